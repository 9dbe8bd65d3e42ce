#!/usr/bin/env python3
"""Seeded random CAD-like parts: unions and differences of boxes, cylinders and spheres, written as
closed, manifold, consistently oriented OFF surfaces. Inputs nobody tuned the mesher to.

usage: csg_parts.py OUT_DIR [--count N] [--seed S] [--segments K]

Part i is drawn from the generator seeded with S + i, so `--seed 7 --count 1` writes the same part
as the eighth of `--seed 0 --count 8`. Each part: a base box, 2 to 6 further primitives, each added
(union) or cut away (difference), randomly placed, sized and rotated; parts that come out empty,
split into several pieces or of genus above 6 are redrawn. Needs `pip install manifold3d numpy`.
"""
import argparse
import os
import random

import numpy as np
from manifold3d import Manifold


def primitive(rng, segments):
    kind = rng.choice(["box", "box", "cylinder", "sphere"])
    if kind == "box":
        size = [rng.uniform(0.2, 0.9) for _ in range(3)]
        m = Manifold.cube(size, center=True)
    elif kind == "cylinder":
        r, h = rng.uniform(0.08, 0.35), rng.uniform(0.3, 1.4)
        m = Manifold.cylinder(h, r, r, segments, center=True)
    else:
        m = Manifold.sphere(rng.uniform(0.12, 0.4), segments)
    if rng.random() < 0.5:  # axis-aligned half the time, as most CAD features are
        m = m.rotate([rng.choice([0, 90]), rng.choice([0, 90]), rng.choice([0, 90])])
    else:
        m = m.rotate([rng.uniform(0, 180) for _ in range(3)])
    return m.translate([rng.uniform(-0.5, 0.5) for _ in range(3)])


def part(seed, segments):
    rng = random.Random(seed)
    for _ in range(100):
        m = Manifold.cube([rng.uniform(0.8, 1.4), rng.uniform(0.6, 1.2), rng.uniform(0.3, 1.0)], center=True)
        for _ in range(rng.randint(2, 6)):
            p = primitive(rng, segments)
            m = m - p if rng.random() < 0.5 else m + p
        if m.is_empty() or len(m.decompose()) != 1 or m.genus() > 6 or m.volume() < 0.05:
            continue
        return m
    raise RuntimeError(f"seed {seed}: no valid part in 100 draws")


def write_off(path, m):
    mesh = m.to_mesh()
    v = np.asarray(mesh.vert_properties)[:, :3]
    t = np.asarray(mesh.tri_verts)
    with open(path, "w") as f:
        f.write(f"OFF\n{len(v)} {len(t)} 0\n")
        f.writelines(f"{x:.17g} {y:.17g} {z:.17g}\n" for x, y, z in v)
        f.writelines(f"3 {a} {b} {c}\n" for a, b, c in t)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out")
    ap.add_argument("--count", type=int, default=40)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--segments", type=int, default=32, help="facets around a cylinder or sphere")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    for i in range(a.count):
        s = a.seed + i
        write_off(os.path.join(a.out, f"csg_{s:04d}.off"), part(s, a.segments))


if __name__ == "__main__":
    main()
