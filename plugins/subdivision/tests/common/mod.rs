//! Small closed control meshes for the tests (also used by the workspace's end-to-end tests).
#![allow(dead_code)]

use delamesh_core::mesh::PatchId;
use delamesh_formats::PolygonMesh;
use glam::DVec3;
use std::collections::HashMap;
use std::f64::consts::TAU;

pub fn mesh(points: Vec<DVec3>, faces: Vec<Vec<u32>>) -> PolygonMesh {
    PolygonMesh {
        positions: points,
        groups: vec![PatchId(0); faces.len()],
        faces,
        group_names: vec!["surface".into()],
    }
}

/// The cube [-1, 1]³, outward quads.
pub fn cube() -> PolygonMesh {
    let p = (0..8)
        .map(|i| {
            let c = |b: u32| if i >> b & 1 == 1 { 1.0 } else { -1.0 };
            DVec3::new(c(0), c(1), c(2))
        })
        .collect();
    let f = vec![
        vec![0, 2, 3, 1],
        vec![4, 5, 7, 6],
        vec![0, 1, 5, 4],
        vec![2, 6, 7, 3],
        vec![0, 4, 6, 2],
        vec![1, 3, 7, 5],
    ];
    mesh(p, f)
}

/// The octahedron with vertices at ±1 on the axes, outward triangles.
pub fn octahedron() -> PolygonMesh {
    let p = vec![
        DVec3::X,
        DVec3::NEG_X,
        DVec3::Y,
        DVec3::NEG_Y,
        DVec3::Z,
        DVec3::NEG_Z,
    ];
    let f = vec![
        vec![0, 2, 4],
        vec![2, 1, 4],
        vec![1, 3, 4],
        vec![3, 0, 4],
        vec![2, 0, 5],
        vec![1, 2, 5],
        vec![3, 1, 5],
        vec![0, 3, 5],
    ];
    mesh(p, f)
}

/// Control point `(i, j)` of the `n × m` torus grid (radii 2 and 0.7).
pub fn torus_point(n: usize, m: usize, i: usize, j: usize) -> DVec3 {
    let (theta, phi) = (
        TAU * (i % n) as f64 / n as f64,
        TAU * (j % m) as f64 / m as f64,
    );
    let r = 2.0 + 0.7 * phi.cos();
    DVec3::new(r * theta.cos(), r * theta.sin(), 0.7 * phi.sin())
}

/// The regular `n × m` quad grid on a torus: every vertex of valence 4, face `i + n j` is
/// `(i, j), (i+1, j), (i+1, j+1), (i, j+1)`.
pub fn torus_grid(n: usize, m: usize) -> PolygonMesh {
    let id = |i: usize, j: usize| ((i % n) + n * (j % m)) as u32;
    let points = (0..m)
        .flat_map(|j| (0..n).map(move |i| torus_point(n, m, i, j)))
        .collect();
    let faces = (0..m)
        .flat_map(|j| {
            (0..n).map(move |i| vec![id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        })
        .collect();
    mesh(points, faces)
}

/// The same grid, each quad cut along the same diagonal: every vertex of valence 6.
pub fn torus_triangles(n: usize, m: usize) -> PolygonMesh {
    let quads = torus_grid(n, m);
    let faces = quads
        .faces
        .iter()
        .flat_map(|q| [vec![q[0], q[1], q[2]], vec![q[0], q[2], q[3]]])
        .collect();
    mesh(quads.positions, faces)
}

/// The uniform periodic cubic B-spline of the closed polygon `c` at `t` (one unit per
/// control point) and its derivative: the limit of the crease rules (crease vertex
/// `(a + 6v + b)/8`, edge point the midpoint), Loop's and Catmull–Clark's alike.
pub fn crease_b_spline(c: &[DVec3], t: f64) -> [DVec3; 2] {
    let n = c.len();
    let t = t.rem_euclid(n as f64);
    let (i, s) = (t.floor() as usize, t.fract());
    let b = [
        (1.0 - s).powi(3) / 6.0,
        (3.0 * s.powi(3) - 6.0 * s * s + 4.0) / 6.0,
        (-3.0 * s.powi(3) + 3.0 * s * s + 3.0 * s + 1.0) / 6.0,
        s.powi(3) / 6.0,
    ];
    let d = [
        -(1.0 - s).powi(2) / 2.0,
        (3.0 * s * s - 4.0 * s) / 2.0,
        (-3.0 * s * s + 2.0 * s + 1.0) / 2.0,
        s * s / 2.0,
    ];
    let mut out = [DVec3::ZERO; 2];
    for k in 0..4 {
        let p = c[(i + n + k - 1) % n];
        out[0] += b[k] * p;
        out[1] += d[k] * p;
    }
    out
}

/// Distance from `p` to the B-spline of `c`: the nearest of a sample, then damped Newton on
/// the squared distance.
pub fn distance_to_crease(c: &[DVec3], p: DVec3) -> f64 {
    let samples = 64 * c.len();
    let mut t = (0..samples)
        .map(|k| k as f64 / 64.0)
        .min_by(|&a, &b| {
            let da = crease_b_spline(c, a)[0].distance(p);
            da.total_cmp(&crease_b_spline(c, b)[0].distance(p))
        })
        .unwrap_or(0.0);
    let mut d = crease_b_spline(c, t)[0].distance(p);
    for _ in 0..60 {
        let [q, dq] = crease_b_spline(c, t);
        let mut step = (q - p).dot(dq) / dq.length_squared();
        while step.abs() > 1e-18 && crease_b_spline(c, t - step)[0].distance(p) > d {
            step *= 0.5;
        }
        t -= step;
        d = crease_b_spline(c, t)[0].distance(p);
    }
    d
}

/// The torus grid (or its triangles) with the faces of its upper half (`j < m / 2`) in a group
/// of their own: two closed crease loops along the rings `j = 0` and `j = m / 2`, every vertex
/// on them a regular crease vertex. Returns the mesh and the two loops' control polygons.
pub fn creased_torus(n: usize, m: usize, triangles: bool) -> (PolygonMesh, [Vec<DVec3>; 2]) {
    let mut t = if triangles {
        torus_triangles(n, m)
    } else {
        torus_grid(n, m)
    };
    let per_quad = if triangles { 2 } else { 1 };
    t.groups = (0..t.faces.len())
        .map(|f| PatchId(u32::from(f / per_quad / n >= m / 2)))
        .collect();
    t.group_names = vec!["upper".into(), "lower".into()];
    let ring = |j: usize| (0..n).map(|i| torus_point(n, m, i, j)).collect();
    (t, [ring(0), ring(m / 2)])
}

/// A slab of 5 × 3 × 1 unit cubes with two cubes taken out: a genus-2 quad mesh (χ = −2).
pub fn genus_two() -> PolygonMesh {
    let solid = |x: i32, y: i32, z: i32| {
        (0..5).contains(&x) && (0..3).contains(&y) && z == 0 && !(y == 1 && (x == 1 || x == 3))
    };
    let mut index: HashMap<[i32; 3], u32> = HashMap::new();
    let mut points = Vec::new();
    let mut faces = Vec::new();
    let mut vertex = |p: [i32; 3], points: &mut Vec<DVec3>| {
        *index.entry(p).or_insert_with(|| {
            points.push(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64));
            points.len() as u32 - 1
        })
    };
    for x in -1..6 {
        for y in -1..4 {
            for z in -1..2 {
                if !solid(x, y, z) {
                    continue;
                }
                // Each face towards an empty neighbour, counter-clockwise seen from outside.
                for axis in 0..3 {
                    for side in [0, 1] {
                        let mut n = [x, y, z];
                        n[axis] += 2 * side - 1;
                        if solid(n[0], n[1], n[2]) {
                            continue;
                        }
                        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
                        let corner = |du: i32, dv: i32| {
                            let mut p = [x, y, z];
                            p[axis] += side;
                            p[u] += du;
                            p[v] += dv;
                            p
                        };
                        let mut quad = vec![corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)];
                        if side == 0 {
                            quad.reverse();
                        }
                        faces.push(quad.into_iter().map(|p| vertex(p, &mut points)).collect());
                    }
                }
            }
        }
    }
    mesh(points, faces)
}

/// V − E + F of a polygon mesh.
pub fn euler_characteristic(m: &PolygonMesh) -> i64 {
    let mut edges: Vec<(u32, u32)> = m
        .faces
        .iter()
        .flat_map(|f| {
            (0..f.len()).map(move |k| {
                (
                    f[k].min(f[(k + 1) % f.len()]),
                    f[k].max(f[(k + 1) % f.len()]),
                )
            })
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    m.positions.len() as i64 - edges.len() as i64 + m.faces.len() as i64
}
