"""Side-by-side times of `delamesh.mesh(path)`, the command line, and (optionally) pygalmesh's
`generate_volume_mesh_from_surface_mesh` at equal criteria, one run each, alternating per model.

    python3 python/benches/compare.py CLI MODEL... [--pygalmesh PYTHON]

CLI is the `delamesh` binary (a release build), PYTHON an interpreter where pygalmesh imports
(Debian's python3-pygalmesh lives in the system python). The criteria are delamesh's defaults made
explicit (bounding-box diagonal d: facet and cell size d/20, facet distance d/400, edge size d/20,
facet angle 25°, radius-edge ratio 3), no optimisation on either side (`perturb=False,
exude=False`: delamesh optimises by default), and no sharp features on either side
(`no_features=True`: pygalmesh's `generate_volume_mesh_from_surface_mesh` protects none).
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import delamesh

PYGALMESH = """
import sys, time, pygalmesh
kw = eval(sys.argv[2])
t = time.perf_counter()
m = pygalmesh.generate_volume_mesh_from_surface_mesh(sys.argv[1], verbose=False, **kw)
print(time.perf_counter() - t, len(m.points), len(m.cells_dict.get("tetra", [])))
"""


def diagonal(path: Path) -> float:
    points = delamesh.read(path).points
    return float(np.linalg.norm(points.max(0) - points.min(0)))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("cli", type=Path)
    ap.add_argument("models", type=Path, nargs="+")
    ap.add_argument("--pygalmesh", help="a python interpreter where pygalmesh imports")
    ap.add_argument(
        "--finer",
        type=float,
        default=1.0,
        help="divide the sizes and distance of the pygalmesh comparison by this",
    )
    args = ap.parse_args()
    print(
        "model  cli_s  py_mesh_s  py_mesh+write_s  ratio(py/cli)  ratio(py+write/cli)  pyvertices"
        + ("  pygalmesh_s  pygalmesh_vertices  delamesh/pygalmesh" if args.pygalmesh else "")
    )
    with tempfile.TemporaryDirectory() as tmp:
        for model in args.models:
            out = Path(tmp) / "cli.vtu"
            t = time.perf_counter()
            subprocess.run([str(args.cli), "mesh", str(model), "-o", str(out), "-q"], check=True)
            cli_s = time.perf_counter() - t
            t = time.perf_counter()
            m = delamesh.mesh(model)
            py_s = time.perf_counter() - t
            t = time.perf_counter()
            delamesh.write(Path(tmp) / "py.vtu", m)
            write_s = time.perf_counter() - t
            row = (
                f"{model.stem}  {cli_s:.2f}  {py_s:.2f}  {py_s + write_s:.2f}  {py_s / cli_s:.3f}  "
                f"{(py_s + write_s) / cli_s:.3f}  {len(m.points)}"
            )
            if args.pygalmesh:
                d = diagonal(model) / args.finer
                same = {
                    "facet_angle": 25.0,
                    "facet_size": d / 20,
                    "facet_distance": d / 400,
                    "cell_radius_edge_ratio": 3.0,
                    "cell_size": d / 20,
                    "edge_size": d / 20,
                    "perturb": False,
                    "exude": False,
                    # pygalmesh's surface-mesh entry builds CGAL's Polyhedral_mesh_domain_3,
                    # which protects no sharp feature.
                    "no_features": True,
                }
                kw = {
                    "min_facet_angle": 25.0,
                    "max_radius_surface_delaunay_ball": d / 20,
                    "max_facet_distance": d / 400,
                    "max_circumradius_edge_ratio": 3.0,
                    "max_cell_circumradius": d / 20,
                    "max_edge_size_at_feature_edges": d / 20,
                    "perturb": False,
                    "exude": False,
                }
                done = subprocess.run(
                    [args.pygalmesh, "-c", PYGALMESH, str(model), repr(kw)],
                    check=True,
                    capture_output=True,
                    text=True,
                )
                pg_s, pg_v, _ = done.stdout.split()
                t = time.perf_counter()
                m2 = delamesh.mesh(model, **same)
                eq_s = time.perf_counter() - t
                pg = float(pg_s)
                row += f"  {pg:.2f}  {pg_v}  {eq_s:.2f}/{pg:.2f}={eq_s / pg:.3f} ({len(m2.points)} v)"
            print(row, flush=True)


if __name__ == "__main__":
    sys.exit(main())
