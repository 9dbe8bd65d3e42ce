#!/usr/bin/env bash
# Side-by-side sweep of the sharp-feature path against CGAL Mesh_3: every closed model of a folder
# (e.g. CGAL's data/meshes) and SEED's random CSG parts, each through the shared sweep (same
# criteria on both sides, CGAL without optimisers). Prints each sweep's SUMMARY line.
#
# usage: benches/feature_sweep.sh SWEEP_PY DELAMESH MODELS_DIR WORK_DIR [SEED] [COUNT]
#   SWEEP_PY   the shared sweep script (../shared/bench/sweep.py from the repository's parent)
#   DELAMESH   the binary to measure (target/release/delamesh)
set -euo pipefail
[ $# -ge 4 ] || { sed -n 2,9p "$0"; exit 2; }
sweep=$1 delamesh=$2 models=$3 work=$4 seed=${5:-2} count=${6:-40}
here=$(cd "$(dirname "$0")" && pwd)
mkdir -p "$work"
python3 "$here/csg_parts.py" "$work/csg-$seed" --count "$count" --seed "$seed" >/dev/null
for dir in "$models" "$work/csg-$seed"; do
    name=$(basename "$dir")
    python3 "$sweep" "$delamesh" "$dir" "$work/out-$name" --cgal --timeout 60 | tee "$work/$name.log" | grep '^SUMMARY' | sed "s/^/$name /"
done
