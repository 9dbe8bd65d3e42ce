#!/usr/bin/env python3
"""Volume per label of the partition the image oracle meshes (CGAL's labellized trilinear
interpolation, with delamesh's tie bias): the yardstick for mesh volumes, which
`label_volumes.py` compares. `partition_volumes.py IMAGE.inr[.gz] [K]` (8-bit INR): cubes of
eight equal voxels count whole, the others by a K³ midpoint rule (default 6)."""
import gzip, re, sys
import numpy as np
path = sys.argv[1]; k = int(sys.argv[2]) if len(sys.argv) > 2 else 6
d = gzip.open(path).read() if path.endswith('.gz') else open(path, 'rb').read()
h = d[:256].decode('latin1')
g = lambda key: re.search(key + r'=(\S+)', h).group(1)
X, Y, Z = int(g('XDIM')), int(g('YDIM')), int(g('ZDIM'))
vx, vy, vz = float(g('VX')), float(g('VY')), float(g('VZ'))
a = np.frombuffer(d[256:256 + X * Y * Z], np.uint8).reshape(Z, Y, X)
labels = np.unique(a); n = len(labels)
rank = {int(l): r for r, l in enumerate(labels)}
c = [a[i:Z-1+i, j:Y-1+j, l:X-1+l] for i in (0, 1) for j in (0, 1) for l in (0, 1)]
mn = np.minimum.reduce(c); mx = np.maximum.reduce(c)
uni = mn == mx
vol = {}
cell = vx * vy * vz
for l in labels:
    vol[int(l)] = float(((mn == l) & uni).sum()) * cell
idx = np.argwhere(~uni)
t = (np.arange(k) + 0.5) / k
tz, ty, tx = np.meshgrid(t, t, t, indexing='ij'); tz, ty, tx = tz.ravel(), ty.ravel(), tx.ravel()
for s in range(0, len(idx), 20000):
    b = idx[s:s+20000]
    corners = np.stack([a[b[:, 0]+i, b[:, 1]+j, b[:, 2]+l] for i in (0, 1) for j in (0, 1) for l in (0, 1)], 1)  # (m,8) order z,y,x
    best = np.full((len(b), len(tx)), -1.0); lab = np.zeros((len(b), len(tx)), np.int32)
    for l in labels:
        w = np.zeros((len(b), len(tx)))
        any_ = False
        for m, (i, j, q) in enumerate([(i, j, q) for i in (0, 1) for j in (0, 1) for q in (0, 1)]):
            sel = corners[:, m] == l
            if sel.any():
                any_ = True
                wz = tz if i else 1 - tz; wy = ty if j else 1 - ty; wx = tx if q else 1 - tx
                w += sel[:, None] * (wz * wy * wx)[None, :]
        if not any_:
            continue
        w += 0.04 * rank[int(l)] / n
        w[(corners == l).sum(1) == 0] = -2
        mm = w > best; best[mm] = w[mm]; lab[mm] = l
    for l in labels:
        vol[int(l)] += float((lab == l).sum()) * cell / len(tx)
print({l: round(v, 1) for l, v in vol.items() if l != 0})
