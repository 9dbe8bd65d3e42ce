#!/usr/bin/env python3
"""Random overlapping solids, written as one self-intersecting surface, against their exact union.

usage: overlap_union.py DELAMESH_BINARY WORK_DIR [--count N] [--seed S] [-- DELAMESH_MESH_ARGS]

Each input is two to four primitives of manifold3d (boxes, spheres, cylinders and cones, randomly
sized, turned and moved) whose triangles are simply listed together: the surfaces cross wherever
the solids overlap. delamesh meshes each (default arguments: `--preserve-surface`); each output is
checked independently of delamesh: no flat or inverted tet (|6V| <= 1e-12 * longest edge^3),
boundary a closed 2-manifold, its Euler characteristic equal to that of manifold3d's boolean union
of the same primitives, and its volume against the union's. One line per input, then a summary.
"""
import argparse
import subprocess
import sys
import time
from pathlib import Path

import manifold3d as m3
import meshio
import numpy as np


def primitive(rng):
    kind = rng.integers(0, 3)
    if kind == 0:
        solid = m3.Manifold.cube(tuple(rng.uniform(0.3, 1.0, 3)), True)
    elif kind == 1:
        solid = m3.Manifold.sphere(rng.uniform(0.2, 0.5), int(rng.integers(12, 40)))
    else:
        solid = m3.Manifold.cylinder(rng.uniform(0.3, 1.0), rng.uniform(0.1, 0.4),
                                     rng.uniform(0.1, 0.4), int(rng.integers(8, 32)), True)
    return solid.rotate(tuple(rng.uniform(0, 360, 3))).translate(tuple(rng.uniform(-0.3, 0.3, 3)))


def euler(faces):
    edges = np.unique(np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [0, 2]]]),
                              axis=1), axis=0)
    return len(np.unique(faces)) - len(edges) + len(faces)


def write_off(path, parts):
    points, triangles, offset = [], [], 0
    for p in parts:
        mesh = p.to_mesh()
        v = np.asarray(mesh.vert_properties)[:, :3].astype(float)
        points.append(v)
        triangles.append(np.asarray(mesh.tri_verts) + offset)
        offset += len(v)
    points, triangles = np.concatenate(points), np.concatenate(triangles)
    with open(path, "w") as f:
        f.write(f"OFF\n{len(points)} {len(triangles)} 0\n")
        f.writelines("%r %r %r\n" % tuple(map(float, p)) for p in points)
        f.writelines(f"3 {t[0]} {t[1]} {t[2]}\n" for t in triangles)


def check(path):
    mesh = meshio.read(path)
    p = mesh.points
    t = np.concatenate([c.data for c in mesh.cells if c.type == "tetra"])
    a, b, c, d = (p[t[:, k]] for k in range(4))
    v6 = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))
    longest = np.max([np.linalg.norm(x - y, axis=1)
                      for x, y in [(a, b), (a, c), (a, d), (b, c), (b, d), (c, d)]], axis=0)
    tol = 1e-12 * longest ** 3
    faces = np.sort(np.concatenate([t[:, [0, 1, 2]], t[:, [0, 1, 3]], t[:, [0, 2, 3]], t[:, [1, 2, 3]]]),
                    axis=1)
    uniq, count = np.unique(faces, axis=0, return_counts=True)
    boundary = uniq[count == 1]
    edges, uses = np.unique(np.sort(np.concatenate([boundary[:, [0, 1]], boundary[:, [1, 2]],
                                                    boundary[:, [0, 2]]]), axis=1),
                            axis=0, return_counts=True)
    return dict(flat=int(np.sum(np.abs(v6) <= tol)), inverted=int(np.sum(v6 < -tol)),
                volume=float(abs(v6.sum()) / 6.0), non_manifold_edges=int(np.sum(uses != 2)),
                euler=euler(boundary))


def main():
    argv = sys.argv[1:]
    extra = ["--preserve-surface"]
    if "--" in argv:
        cut = argv.index("--")
        argv, extra = argv[:cut], argv[cut + 1:]
    parser = argparse.ArgumentParser()
    parser.add_argument("binary")
    parser.add_argument("work", type=Path)
    parser.add_argument("--count", type=int, default=20)
    parser.add_argument("--seed", type=int, default=7100)
    args = parser.parse_args(argv)
    args.work.mkdir(parents=True, exist_ok=True)
    rng = np.random.default_rng(args.seed)
    good, times = 0, []
    for k in range(args.count):
        parts = [primitive(rng) for _ in range(rng.integers(2, 5))]
        union = parts[0]
        for p in parts[1:]:
            union = union + p
        union_mesh = union.to_mesh()
        want_volume, want_euler = union.volume(), euler(np.asarray(union_mesh.tri_verts))
        name = f"overlap_{args.seed}_{k:02d}"
        source, out = args.work / f"{name}.off", args.work / f"{name}.vtu"
        write_off(source, parts)
        t0 = time.perf_counter()
        run = subprocess.run([args.binary, "mesh", str(source), "-o", str(out), "-q"] + extra,
                             capture_output=True, text=True)
        elapsed = time.perf_counter() - t0
        if run.returncode != 0:
            print(f"{name} FAILED rc={run.returncode} {run.stderr.strip().splitlines()[0]}", flush=True)
            continue
        times.append(elapsed)
        r = check(out)
        error = r["volume"] / want_volume - 1
        ok = (r["flat"] == 0 and r["inverted"] == 0 and r["non_manifold_edges"] == 0
              and r["euler"] == want_euler)
        good += ok
        print(f"{name} {'good' if ok else 'BAD '} {elapsed:.2f} s, volume {error:+.2e} of the union's, "
              f"χ {r['euler']} (union {want_euler}), flat {r['flat']}, inverted {r['inverted']}, "
              f"non-manifold edges {r['non_manifold_edges']}", flush=True)
    print(f"SUMMARY good {good} of {args.count}, median time {np.median(times) if times else 0:.2f} s")


if __name__ == "__main__":
    main()
