#!/usr/bin/env python3
"""delamesh vs Gmsh (HXT, one thread) with the same background-mesh size field.

    python3 benches/sizing_vs_gmsh.py PART.off OUT_DIR [--hmin 0.02] [--slope 0.3] [--delamesh BIN]

The field is h(x) = hmin + slope * |x - c|, c the part's bounding-box minimum corner (a size
concentrated near one corner), sampled at the nodes of a Kuhn grid over the padded box: written
as OUT_DIR/background.vtu (point field `h`) for delamesh and given to Gmsh as a list-based view
(a PostView background field; boundary, point and curvature sizes off). Both outputs get the same
check: per tet, circumradius / h(circumcentre) (delamesh's criterion bounds it by 1) and per edge,
length / h(midpoint) (Gmsh's size is an edge length). Gmsh is run a second time with its field
scaled so that its vertex count matches delamesh's. Prints one line per run and the time ratio.
"""
import argparse, os, subprocess, sys, time
import numpy as np, meshio, trimesh

def kuhn_grid(lo, hi, n):
    axes = [np.linspace(lo[k], hi[k], n + 1) for k in range(3)]
    z, y, x = np.meshgrid(axes[2], axes[1], axes[0], indexing='ij')
    pts = np.stack([x.ravel(), y.ravel(), z.ravel()], 1)
    node = lambda i, j, k: i + (n + 1) * (j + (n + 1) * k)
    I, J, K = [a.ravel() for a in np.meshgrid(np.arange(n), np.arange(n), np.arange(n), indexing='ij')]
    c = lambda b: node(I + (b & 1), J + ((b >> 1) & 1), K + (b >> 2))
    tets = np.concatenate([np.stack([c(0), c(p), c(q), c(7)], 1)
                           for p, q in [(1, 3), (1, 5), (2, 3), (2, 6), (4, 5), (4, 6)]])
    return pts, tets

def check(path, h):
    m = meshio.read(path)
    tets = np.concatenate([c.data for c in m.cells if c.type == 'tetra'])
    p = m.points[tets]
    a, b, c, d = p[:, 0], p[:, 1], p[:, 2], p[:, 3]
    u, v, w = b - a, c - a, d - a
    det = 2 * np.einsum('ij,ij->i', u, np.cross(v, w))
    num = (np.einsum('ij,ij->i', u, u)[:, None] * np.cross(v, w)
           + np.einsum('ij,ij->i', v, v)[:, None] * np.cross(w, u)
           + np.einsum('ij,ij->i', w, w)[:, None] * np.cross(u, v))
    ok = np.abs(det) > 1e-300
    cc = a[ok] + num[ok] / det[ok, None]
    radius = np.linalg.norm(cc - a[ok], axis=1)
    rr = radius / h(cc)
    edges = np.unique(np.sort(np.concatenate([tets[:, [i, j]] for i, j in
                      [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]]), axis=1), axis=0)
    e0, e1 = m.points[edges[:, 0]], m.points[edges[:, 1]]
    er = np.linalg.norm(e1 - e0, axis=1) / h(0.5 * (e0 + e1))
    return dict(vertices=len(m.points), tets=len(tets), r_over_h_max=rr.max(),
                r_over_h_p99=np.percentile(rr, 99), frac_r_gt_h=(rr > 1.0 + 1e-9).mean(),
                edge_over_h_median=np.median(er), edge_p90_over_p10=np.percentile(er, 90) / np.percentile(er, 10))

GMSH = r'''
import sys, math, time, numpy as np, gmsh
stl, bg, scale, out = sys.argv[1], sys.argv[2], float(sys.argv[3]), sys.argv[4]
d = np.load(bg)
pts, tets, h = d['pts'], d['tets'], d['h'] * scale
t0 = time.perf_counter()
gmsh.initialize()
gmsh.option.setNumber('General.Terminal', 0)
gmsh.option.setNumber('General.NumThreads', 1)
gmsh.merge(stl)
gmsh.model.mesh.classifySurfaces(40 * math.pi / 180, True, True, math.pi)
gmsh.model.mesh.createGeometry()
s = gmsh.model.getEntities(2)
loop = gmsh.model.geo.addSurfaceLoop([e[1] for e in s])
gmsh.model.geo.addVolume([loop])
gmsh.model.geo.synchronize()
view = gmsh.view.add('h')
data = np.concatenate([pts[tets].transpose(0, 2, 1).reshape(-1, 12), h[tets]], 1)
gmsh.view.addListData(view, 'SS', len(tets), data.ravel().tolist())
f = gmsh.model.mesh.field.add('PostView')
gmsh.model.mesh.field.setNumber(f, 'ViewTag', view)
gmsh.model.mesh.field.setAsBackgroundMesh(f)
for o in ['Mesh.MeshSizeExtendFromBoundary', 'Mesh.MeshSizeFromPoints', 'Mesh.MeshSizeFromCurvature']:
    gmsh.option.setNumber(o, 0)
gmsh.option.setNumber('Mesh.Algorithm3D', 10)
gmsh.model.mesh.generate(3)
gmsh.write(out)
gmsh.finalize()
print(time.perf_counter() - t0)
'''

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument('part'); ap.add_argument('out')
    ap.add_argument('--hmin', type=float, default=0.02)
    ap.add_argument('--slope', type=float, default=0.3)
    ap.add_argument('--grid', type=int, default=24)
    ap.add_argument('--delamesh', default='target/release/delamesh')
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    surf = trimesh.load(a.part, force='mesh')
    lo, hi = surf.bounds
    pad = 0.05 * np.linalg.norm(hi - lo)
    corner = lo.copy()
    h = lambda x: a.hmin + a.slope * np.linalg.norm(np.atleast_2d(x) - corner, axis=1)
    pts, tets = kuhn_grid(lo - pad, hi + pad, a.grid)
    bg = os.path.join(a.out, 'background.vtu')
    meshio.write(bg, meshio.Mesh(pts, [('tetra', tets)], point_data={'h': h(pts)}))
    np.savez(os.path.join(a.out, 'background.npz'), pts=pts, tets=tets, h=h(pts))
    stl = os.path.join(a.out, 'part.stl')
    surf.export(stl)
    script = os.path.join(a.out, 'gmsh_run.py')
    open(script, 'w').write(GMSH)
    ours = os.path.join(a.out, 'delamesh.vtu')
    t0 = time.perf_counter()
    subprocess.run([a.delamesh, 'mesh', a.part, '-o', ours, '--sizing', bg, '-q'], check=True)
    t_ours = time.perf_counter() - t0
    r_ours = check(ours, h)
    print(f'delamesh  {t_ours:7.2f} s  {r_ours}')
    scale, n_target = 1.0, r_ours['vertices']
    for run in range(2):
        out = os.path.join(a.out, f'gmsh_{run}.msh')
        t0 = time.perf_counter()
        subprocess.run([sys.executable, script, stl, os.path.join(a.out, 'background.npz'), str(scale), out],
                       check=True, capture_output=True)
        t_gmsh = time.perf_counter() - t0
        r = check(out, lambda x: h(x) * scale)
        print(f'gmsh x{scale:.3f} {t_gmsh:7.2f} s  {r}   time delamesh / gmsh = {t_ours / t_gmsh:.2f}')
        scale *= (r['vertices'] / n_target) ** (1 / 3)

main()
