#!/usr/bin/env python3
"""delamesh vs fTetWild (pytetwild) side by side on surfaces that need repair.

usage: dirty_vs_ftetwild.py DELAMESH_BINARY MODELS_DIR WORK_DIR NAME... [-- DELAMESH_MESH_ARGS]...

For each NAME.off in MODELS_DIR: wall time of each mesher (delamesh's CLI, fTetWild's
tetrahedralize call with its defaults), tet volume, the sampled one-sided Hausdorff distance from
each output's boundary to the input triangles, as a fraction of the input's bounding-box diagonal,
and the Euler characteristic of each output's boundary. The two meshers alternate per model.
Arguments after `--` are passed to `delamesh mesh`, `diag/N` standing for the input's
bounding-box diagonal divided by N; each further `--` starts another delamesh configuration, all
compared with the same fTetWild run (one row per configuration).
"""
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import meshio
import numpy as np
import pytetwild
import trimesh


def tet_volume(points, tets):
    a, b, c, d = (points[tets[:, k]] for k in range(4))
    return float(np.abs(np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))).sum() / 6.0)


def boundary(tets):
    faces = np.sort(np.concatenate([tets[:, [0, 1, 2]], tets[:, [0, 1, 3]],
                                    tets[:, [0, 2, 3]], tets[:, [1, 2, 3]]]), axis=1)
    uniq, count = np.unique(faces, axis=0, return_counts=True)
    return uniq[count == 1]


def hausdorff_to_input(points, tets, surface, diagonal, samples=20000):
    shell = trimesh.Trimesh(points, boundary(tets), process=False)
    sample, _ = trimesh.sample.sample_surface_even(shell, samples, seed=1)
    _, dist, _ = trimesh.proximity.closest_point(surface, sample)
    return float(dist.max()) / diagonal


def euler(tets):
    faces = boundary(tets)
    edges = np.unique(np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [0, 2]]]),
                              axis=1), axis=0)
    return len(np.unique(faces)) - len(edges) + len(faces)


def main():
    args, configs = sys.argv[1:], []
    while "--" in args:
        cut = len(args) - 1 - args[::-1].index("--")
        configs.insert(0, args[cut + 1:])
        args = args[:cut]
    configs = configs or [[]]
    binary, models, work = args[0], Path(args[1]), Path(args[2])
    work.mkdir(parents=True, exist_ok=True)
    print("model | delamesh s | fTetWild s | time ratio | delamesh vol | fTetWild vol | vol diff"
          " | delamesh H/diag | fTetWild H/diag | delamesh χ | fTetWild χ")
    for name in args[3:]:
        path = models / f"{name}.off"
        surface = trimesh.load(path, process=False, force="mesh")
        points, tris = np.asarray(surface.vertices, float), np.asarray(surface.faces)
        diagonal = float(np.linalg.norm(surface.bounds[1] - surface.bounds[0]))

        def ours(config):
            out = work / f"{name}.vtu"
            extra = [str(diagonal / float(x[5:])) if x.startswith("diag/") else x for x in config]
            t0 = time.perf_counter()
            subprocess.run([binary, "mesh", str(path), "-o", str(out), "-q"] + extra, check=True,
                           stderr=subprocess.DEVNULL)
            elapsed = time.perf_counter() - t0
            mesh = meshio.read(out)
            return elapsed, mesh.points, np.concatenate([c.data for c in mesh.cells if c.type == "tetra"])

        # The first configuration runs before fTetWild, the others after it.
        runs = [ours(configs[0])]
        # fTetWild writes `__tracked_surface.stl` into the working directory: run it in a scratch one.
        cwd = os.getcwd()
        with tempfile.TemporaryDirectory() as scratch:
            os.chdir(scratch)
            try:
                t0 = time.perf_counter()
                v, t = pytetwild.tetrahedralize(points, tris.astype(np.int32))
                t_peer = time.perf_counter() - t0
            finally:
                os.chdir(cwd)
        v, t = np.asarray(v), np.asarray(t)
        runs += [ours(c) for c in configs[1:]]

        vol_peer, h_peer = tet_volume(v, t), hausdorff_to_input(v, t, surface, diagonal)
        for config, (t_ours, p, tets) in zip(configs, runs):
            vol_ours, h_ours = tet_volume(p, tets), hausdorff_to_input(p, tets, surface, diagonal)
            label = " ".join([name] + config)
            print(f"{label} | {t_ours:.2f} | {t_peer:.2f} | {t_ours / t_peer:.3f} | {vol_ours:.6g} | "
                  f"{vol_peer:.6g} | {100 * (vol_ours / vol_peer - 1):+.2f}% | {h_ours:.5f} | "
                  f"{h_peer:.5f} | {euler(tets)} | {euler(t)}", flush=True)

if __name__ == "__main__":
    main()
