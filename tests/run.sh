#!/usr/bin/env bash
# The whole test suite: the Rust tests of every crate, then the real clients (VTK's readers, meshio,
# pymeshlab) reading back what delamesh writes, then the Python package (python/) built, installed
# and tested against the command line. Installs the Python clients if they are missing.
set -euo pipefail
cd "$(dirname "$0")/.."
if ! python3 -c "import numpy, meshio, vtk, pymeshlab, pytest, nibabel, pyvista" 2>/dev/null; then
  echo "installing the Python clients of tests/clients (VTK, meshio, pymeshlab, pytest, nibabel, pyvista)" >&2
  python3 -m pip install --quiet --disable-pip-version-check -r tests/clients/requirements.txt
fi
# No incremental cache: a one-off build does not reuse it, and it doubles the size of target/.
CARGO_INCREMENTAL=0 cargo test --workspace --locked
python3 tests/clients/check_outputs.py
# The package in the test profile: the dependencies `cargo test` just built are reused (a release
# build would compile them all again). The wheel pip was handed is not kept.
CARGO_INCREMENTAL=0 MATURIN_PEP517_ARGS="--profile dev" python3 -m pip install --quiet \
  --disable-pip-version-check --force-reinstall --no-deps ./python
rm -rf target/wheels
DELAMESH_CLI=target/debug/delamesh python3 -m pytest -q python/tests
