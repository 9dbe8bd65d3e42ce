#!/usr/bin/env bash
# The whole test suite: the Rust tests of every crate, then the real clients (VTK's readers, meshio,
# pymeshlab) reading back what delamesh writes. Installs the Python clients if they are missing.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! python3 -c "import numpy, meshio, vtk, pymeshlab" 2>/dev/null; then
  echo "installing the Python clients of tests/clients (VTK, meshio, pymeshlab)" >&2
  python3 -m pip install --quiet --disable-pip-version-check -r tests/clients/requirements.txt
fi
# No incremental cache: a one-off build does not reuse it, and it doubles the size of target/.
CARGO_INCREMENTAL=0 cargo test --workspace --locked
python3 tests/clients/check_outputs.py
