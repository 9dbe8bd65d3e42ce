#!/usr/bin/env bash
# The project's whole test suite: Rust tests of every crate, then the real clients (VTK, meshio,
# pymeshlab) reading what delamesh writes.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --locked
if [[ -f tests/clients/check_outputs.py ]]; then
  python3 tests/clients/check_outputs.py
fi
