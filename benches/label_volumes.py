#!/usr/bin/env python3
"""Vertices, tets and volume per label of tet meshes (.vtu with `subdomain`, or MEDIT .mesh with
references), side by side: `label_volumes.py A.vtu B.mesh`. Relative differences are against the
first mesh."""
import sys

import meshio
import numpy as np


def volumes(path):
    m = meshio.read(path)
    pts = m.points
    tets, labels = [], []
    for k, block in enumerate(m.cells):
        if block.type != "tetra":
            continue
        tets.append(block.data)
        data = None
        for name in ("subdomain", "medit:ref", "gmsh:physical"):
            if name in m.cell_data:
                data = m.cell_data[name][k]
                break
        if data is None:
            data = np.zeros(len(block.data), dtype=int)
        labels.append(np.asarray(data).reshape(-1).astype(int))
    tets, labels = np.concatenate(tets), np.concatenate(labels)
    a, b, c, d = (pts[tets[:, i]] for i in range(4))
    vol = np.abs(np.einsum("ij,ij->i", np.cross(b - a, c - a), d - a)) / 6.0
    used = np.unique(tets)
    return len(used), len(tets), {int(l): float(vol[labels == l].sum()) for l in np.unique(labels)}


def main():
    first = None
    for path in sys.argv[1:]:
        nv, nt, per = volumes(path)
        line = f"{path}: vertices={nv} tets={nt}"
        for l, v in sorted(per.items()):
            line += f" vol[{l}]={v:.1f}"
            if first is not None and l in first[2] and first[2][l] > 0:
                line += f"({100.0 * (v / first[2][l] - 1.0):+.2f}%)"
        if first is not None:
            line += f" vertices({100.0 * (nv / first[0] - 1.0):+.1f}%)"
        print(line)
        first = first or (nv, nt, per)


if __name__ == "__main__":
    main()
