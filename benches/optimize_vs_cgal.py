#!/usr/bin/env python3
"""Optimisation side by side with CGAL Mesh_3 (issue 15's table).

usage: optimize_vs_cgal.py DELAMESH CGAL_MESH_POLYHEDRAL MODELS_DIR WORKDIR [MODEL ...] [-- extra delamesh args]

Criteria on both sides: edge size 0.02·d, facet angle 25°, facet size 0.04·d, facet distance
0.004·d, radius-edge 3, cell size 0.04·d (d = bounding-box diagonal), features detected. CGAL runs
with its default optimisers (perturbation + exudation), delamesh with its defaults. Runs alternate
per model so both see the same machine load. One line per model: wall times, their ratio, smallest
dihedral angle and share of tets below 10° on each side, measured by the same code on both outputs.
Needs `pip install meshio numpy`.
"""
import json
import pathlib
import subprocess
import sys
import time

import meshio
import numpy as np

DEFAULT_MODELS = ["fandisk", "elephant", "anchor", "joint", "spool", "part", "sphere"]


def diagonal(path):
    lines = [l for l in path.read_text().split("\n") if l.strip() and not l.startswith("#")]
    n = int(lines[1].split()[0])
    pts = np.array([[float(v) for v in l.split()[:3]] for l in lines[2 : 2 + n]])
    return float(np.linalg.norm(pts.max(0) - pts.min(0)))


def dihedrals(path):
    m = meshio.read(path)
    tets = np.concatenate([c.data for c in m.cells if c.type == "tetra"])
    p = m.points[tets]
    pairs = [(0, 1, 2, 3), (0, 2, 1, 3), (0, 3, 1, 2), (1, 2, 0, 3), (1, 3, 0, 2), (2, 3, 0, 1)]
    angles = []
    for a, b, c, d in pairs:
        e = p[:, b] - p[:, a]
        n1 = np.cross(e, p[:, c] - p[:, a])
        n2 = np.cross(e, p[:, d] - p[:, a])
        cos = (n1 * n2).sum(1) / (np.linalg.norm(n1, axis=1) * np.linalg.norm(n2, axis=1))
        angles.append(np.degrees(np.arccos(np.clip(cos, -1, 1))))
    per_tet = np.min(np.stack(angles, 1), 1)
    return len(m.points), float(per_tet.min()), float((per_tet < 10).mean() * 100)


def timed(cmd):
    t = time.perf_counter()
    r = subprocess.run(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    if r.returncode != 0:
        raise SystemExit(f"{cmd[0]} failed: {r.stderr.strip()}")
    return time.perf_counter() - t


def main():
    args = sys.argv[1:]
    extra = []
    if "--" in args:
        extra = args[args.index("--") + 1 :]
        args = args[: args.index("--")]
    if len(args) < 4:
        raise SystemExit(__doc__)
    delamesh, cgal, models_dir, work = args[:4]
    models = args[4:] or DEFAULT_MODELS
    work = pathlib.Path(work)
    work.mkdir(parents=True, exist_ok=True)
    for name in models:
        src = pathlib.Path(models_dir) / f"{name}.off"
        d = diagonal(src)
        crit = [0.02 * d, 25, 0.04 * d, 0.004 * d, 3, 0.04 * d]
        ours, theirs = work / f"{name}.vtu", work / f"{name}.mesh"
        t_cgal = timed([cgal, str(src), str(theirs), "1"] + [str(c) for c in crit] + ["1"])
        t_ours = timed(
            [delamesh, "mesh", str(src), "-o", str(ours), "-q",
             "--edge-size", str(crit[0]), "--facet-angle", "25", "--facet-size", str(crit[2]),
             "--facet-distance", str(crit[3]), "--cell-radius-edge-ratio", "3",
             "--cell-size", str(crit[5])] + extra
        )
        nv, amin, below = dihedrals(ours)
        cv, cmin, cbelow = dihedrals(theirs)
        print(json.dumps({
            "model": name, "time": round(t_ours, 3), "cgal_time": round(t_cgal, 3),
            "time_ratio": round(t_ours / t_cgal, 2), "vertices": nv, "cgal_vertices": cv,
            "min_dihedral": round(amin, 2), "cgal_min_dihedral": round(cmin, 2),
            "below_10_pct": round(below, 3), "cgal_below_10_pct": round(cbelow, 3),
        }), flush=True)


if __name__ == "__main__":
    main()
