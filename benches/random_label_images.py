#!/usr/bin/env python3
"""Seeded random label images (INR), meshed with delamesh and checked: inputs nobody tuned to.

usage: random_label_images.py DELAMESH OUT_DIR [--count N] [--seed S] [-- DELAMESH_MESH_ARGS]

Image i is drawn from the generator seeded with S + i: 6 to 39 voxels per axis, voxel sizes 0.3 to
2.0 per axis, 1 to 7 shapes (balls, boxes, speckle) of 1 to 5 labels. Each is meshed with
`delamesh mesh IMAGE -o IMAGE.vtu` (and the arguments after `--`), and the output is checked:
flat tets (|6V| <= 1e-12 L^3, L the tet's longest edge), tiny tets (longest edge below 1e-3 of the
mesh's longest edge: clusters of vertices), the smallest dihedral angle, vertices and wall time.
One line per image, then a summary. Needs numpy and meshio.
"""
import argparse
import os
import subprocess
import time

import meshio
import numpy as np


def image(rng):
    dims = rng.integers(6, 40, 3)
    spacing = rng.uniform(0.3, 2.0, 3)
    z, y, x = np.mgrid[0:dims[2], 0:dims[1], 0:dims[0]]
    labels = np.zeros(dims[::-1], np.uint8)
    count = rng.integers(1, 6)
    for _ in range(rng.integers(1, 8)):
        c = rng.uniform(0, 1, 3) * dims
        r = rng.uniform(1, max(2, dims.min() / 2))
        kind = rng.integers(3)
        if kind == 0:
            inside = (x - c[0]) ** 2 + (y - c[1]) ** 2 + (z - c[2]) ** 2 < r * r
        elif kind == 1:
            inside = ((abs(x - c[0]) < r) & (abs(y - c[1]) < r * rng.uniform(0.3, 1))
                      & (abs(z - c[2]) < r * rng.uniform(0.3, 1)))
        else:
            inside = rng.random(labels.shape) < 0.02
        labels[inside] = rng.integers(1, count + 1)
    return dims, spacing, labels


def write_inr(path, dims, spacing, labels):
    header = ("#INRIMAGE-4#{\nXDIM=%d\nYDIM=%d\nZDIM=%d\nVDIM=1\nTYPE=unsigned fixed\n"
              "PIXSIZE=8 bits\nCPU=decm\nVX=%g\nVY=%g\nVZ=%g\n" % (*dims, *spacing))
    header += "\n" * (252 - len(header)) + "##}\n"
    with open(path, "wb") as f:
        f.write(header.encode() + labels.tobytes())


def check(path):
    m = meshio.read(path)
    tets = np.concatenate([c.data for c in m.cells if c.type == "tetra"])
    p = m.points[tets]
    v6 = np.einsum("ij,ij->i", np.cross(p[:, 1] - p[:, 0], p[:, 2] - p[:, 0]), p[:, 3] - p[:, 0])
    longest = np.max([np.linalg.norm(p[:, i] - p[:, j], axis=1)
                      for i in range(4) for j in range(i + 1, 4)], axis=0)
    angles = np.concatenate([np.asarray(d).reshape(-1) for c, d in
                             zip(m.cells, m.cell_data["min_dihedral_deg"]) if c.type == "tetra"])
    return {"flat": int((np.abs(v6) <= 1e-12 * longest ** 3).sum()),
            "tiny": int((longest < 1e-3 * longest.max()).sum()),
            "min_dihedral": round(float(angles.min()), 2), "vertices": len(m.points)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("delamesh")
    ap.add_argument("out")
    ap.add_argument("--count", type=int, default=60)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("extra", nargs="*")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    failed, flat, tiny, sliver = 0, 0, 0, 0
    for i in range(a.count):
        dims, spacing, labels = image(np.random.default_rng(a.seed + i))
        if labels.max() == 0:
            continue
        path = os.path.join(a.out, f"labels_{a.seed + i}.inr")
        write_inr(path, dims, spacing, labels)
        t0 = time.perf_counter()
        run = subprocess.run([a.delamesh, "mesh", path, "-o", path + ".vtu", "-q", *a.extra],
                             capture_output=True, text=True)
        row = {"image": os.path.basename(path), "rc": run.returncode,
               "wall": round(time.perf_counter() - t0, 3)}
        if run.returncode == 0:
            row.update(check(path + ".vtu"))
            flat += row["flat"] > 0
            tiny += row["tiny"] > 0
            sliver += row["min_dihedral"] < 1.0
        else:
            failed += 1
            row["error"] = run.stderr.strip()[-200:]
        print(row, flush=True)
    print(f"SUMMARY images {a.count} failed {failed} with_flat {flat} with_tiny {tiny} "
          f"min_dihedral_below_1deg {sliver}")


if __name__ == "__main__":
    main()
