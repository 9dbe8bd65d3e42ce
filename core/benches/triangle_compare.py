#!/usr/bin/env python3
"""Side-by-side comparison of `delamesh mesh2d`'s mesher with Shewchuk's Triangle (`pip install triangle`).

Usage: triangle_compare.py PATH/TO/mesh2d_poly [WORKDIR]
(`cargo build --release --example mesh2d_poly` builds it in `target/release/examples/`.)

Writes the benchmark PSLGs as .poly files (a square with a square hole, a star with 10-degree
spikes, random star-shaped polygons), meshes each with Triangle (`-pq30`, plus an area bound where
given) and with delamesh's mesher at `--min-angle 30` (same area bound), and prints one line per
case: mesh times, the time ratio, triangle counts and their ratio, and the smallest angle of each
mesh.

The times compare like with like: both sides run in-process, the best of repeated runs on the
same input (at least 5, more until half a second has passed, as `timeit` does: warm code and
allocator on both sides), with file reading and writing excluded. Triangle's time
includes its conversion from and to numpy arrays; delamesh's covers the PSLG check, the Delaunay
triangulation of the input points and the refinement. The machine's load skews small cases most:
compare runs made at the same load.
"""


import math
import os
import re
import subprocess
import sys
import time

import numpy as np
import triangle

# Repetitions: at least MIN_RUNS, more until BUDGET_S has passed (as `examples/mesh2d_poly.rs`).
MIN_RUNS, MAX_RUNS, BUDGET_S = 5, 2000, 0.5


def square_with_hole():
    pts = [(0, 0), (10, 0), (10, 10), (0, 10), (4, 4), (6, 4), (6, 6), (4, 6)]
    segs = [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4)]
    return pts, segs, [(5.0, 5.0)]


def star(n=10, tip_deg=10.0, outer=10.0):
    half = math.pi / n
    tip = math.radians(tip_deg) / 2
    inner = outer * math.sin(tip) / math.sin(tip + half)
    pts = []
    for k in range(2 * n):
        r = outer if k % 2 == 0 else inner
        th = half * k
        pts.append((r * math.cos(th), r * math.sin(th)))
    return pts, [(k, (k + 1) % (2 * n)) for k in range(2 * n)], []


def random_polygon(n, seed=42):
    """Star-shaped polygon: equally spaced angles, radii 1 + U(-h/2, h/2) with h = 2 pi / n the
    spacing (seeded), so corners range over about 90 to 270 degrees."""
    rng = np.random.default_rng(seed)
    h = 2 * math.pi / n
    r = 1.0 + rng.uniform(-h / 2, h / 2, n)
    th = 2 * math.pi * np.arange(n) / n
    pts = list(zip(r * np.cos(th), r * np.sin(th)))
    return pts, [(k, (k + 1) % n) for k in range(n)], []


def write_poly(path, pts, segs, holes):
    with open(path, "w") as f:
        f.write(f"{len(pts)} 2 0 0\n")
        for i, (x, y) in enumerate(pts):
            f.write(f"{i} {float(x)!r} {float(y)!r}\n")
        f.write(f"{len(segs)} 0\n")
        for i, (a, b) in enumerate(segs):
            f.write(f"{i} {a} {b}\n")
        f.write(f"{len(holes)}\n")
        for i, (x, y) in enumerate(holes):
            f.write(f"{i} {float(x)!r} {float(y)!r}\n")


def min_angle(vertices, tris):
    p = vertices[tris]
    worst = 180.0
    for i in range(3):
        a, b, c = p[:, i], p[:, (i + 1) % 3], p[:, (i + 2) % 3]
        u, v = b - a, c - a
        cos = (u * v).sum(1) / np.linalg.norm(u, axis=1) / np.linalg.norm(v, axis=1)
        worst = min(worst, float(np.degrees(np.arccos(np.clip(cos, -1, 1))).min()))
    return worst


def run_triangle(pts, segs, holes, area):
    data = {"vertices": np.array(pts, float), "segments": np.array(segs, int)}
    if holes:
        data["holes"] = np.array(holes, float)
    opts = "pq30" + (f"a{area}" if area else "") + "Q"
    best = math.inf
    start = time.perf_counter()
    runs = 0
    while runs < MAX_RUNS and (runs < MIN_RUNS or time.perf_counter() - start <= BUDGET_S):
        runs += 1
        t0 = time.perf_counter()
        out = triangle.triangulate(data, opts)
        best = min(best, time.perf_counter() - t0)
    return best, len(out["triangles"]), min_angle(out["vertices"], out["triangles"])


def run_delamesh(exe, poly, area):
    cmd = [exe, poly, "30"] + ([str(area)] if area else [])
    line = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    best = float(re.search(r"best_s=([0-9.]+)", line).group(1))
    tris = int(re.search(r"triangles=(\d+)", line).group(1))
    angle = float(re.search(r"smallest_angle=([0-9.]+)", line).group(1))
    return best, tris, angle


def main():
    exe = sys.argv[1]
    workdir = sys.argv[2] if len(sys.argv) > 2 else "."
    cases = [
        ("square-hole", square_with_hole(), None),
        ("square-hole a0.001", square_with_hole(), 0.001),
        ("star-10deg", star(), None),
        ("star-10deg a0.01", star(), 0.01),
        ("random-polygon-1e4", random_polygon(10_000), None),
        ("random-polygon-1e5", random_polygon(100_000), None),
    ]
    print("case | Triangle s | delamesh s | time ratio | Triangle tris | delamesh tris | count ratio"
          " | Triangle min angle | delamesh min angle")
    for name, (pts, segs, holes), area in cases:
        poly = os.path.join(workdir, name.split()[0] + ".poly")
        write_poly(poly, pts, segs, holes)
        tt, tn, ta = run_triangle(pts, segs, holes, area)
        dt, dn, da = run_delamesh(exe, poly, area)
        print(f"{name} | {tt:.6f} | {dt:.6f} | {dt / tt:.2f} | {tn} | {dn} | {dn / tn:.3f}"
              f" | {ta:.2f} | {da:.2f}")


if __name__ == "__main__":
    main()
