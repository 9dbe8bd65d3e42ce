//! Exact limit evaluation: control vertices against the closed-form limit masks, a regular grid
//! against the uniform bicubic B-spline, continuity across patch borders and towards
//! extraordinary vertices.

mod common;

use common::{
    crease_b_spline, creased_torus, cube, distance_to_crease, genus_two, octahedron, torus_grid,
    torus_point, torus_triangles,
};
use delamesh_core::oracle::Oracle;
use delamesh_formats::PolygonMesh;
use delamesh_subdivision::{Scheme, SubdivisionError, SubdivisionOptions, SubdivisionOracle};
use glam::{DVec2, DVec3};
use std::f64::consts::TAU;

fn oracle(m: &PolygonMesh) -> SubdivisionOracle {
    SubdivisionOracle::new(m, &SubdivisionOptions::default(), &[]).expect("valid control mesh")
}

/// Neighbours of every vertex (by edges), and the corners diagonally opposite in its quads.
fn stars(m: &PolygonMesh) -> Vec<(Vec<DVec3>, Vec<DVec3>)> {
    let mut out = vec![(Vec::new(), Vec::new()); m.positions.len()];
    for f in &m.faces {
        let n = f.len();
        for k in 0..n {
            let v = f[k] as usize;
            out[v].0.push(m.positions[f[(k + 1) % n] as usize]);
            if n == 4 {
                out[v].1.push(m.positions[f[(k + 2) % 4] as usize]);
            }
        }
    }
    out
}

#[test]
fn catmull_clark_control_vertices_reach_the_limit_mask() {
    for m in [cube(), torus_grid(6, 5), genus_two()] {
        let o = oracle(&m);
        let stars = stars(&m);
        let mut slot = 0;
        for f in &m.faces {
            for &v in f {
                let (edges, diagonals) = &stars[v as usize];
                let n = edges.len() as f64;
                let sum = |p: &[DVec3]| p.iter().copied().sum::<DVec3>();
                let mask = (n * n * m.positions[v as usize] + 4.0 * sum(edges) + sum(diagonals))
                    / (n * (n + 5.0));
                let (p, normal) = o.evaluate(slot, 0.0, 0.0).expect("patch");
                assert!(p.distance(mask) < 1e-12, "vertex {v}: {p} against {mask}");
                assert!(
                    (normal.length() - 1.0).abs() < 1e-9,
                    "{} vertices, vertex {v}: normal {normal}",
                    m.positions.len()
                );
                slot += 1;
            }
        }
    }
}

#[test]
fn loop_control_vertices_reach_the_limit_mask() {
    for m in [octahedron(), torus_triangles(8, 6)] {
        let o = oracle(&m);
        assert_eq!(o.scheme(), Scheme::Loop);
        let stars = stars(&m);
        for (f, face) in m.faces.iter().enumerate() {
            for (k, corner) in [DVec2::ZERO, DVec2::X, DVec2::Y].iter().enumerate() {
                let v = face[k] as usize;
                let n = stars[v].0.len() as f64;
                let c = 3.0 / 8.0 + (TAU / n).cos() / 4.0;
                let beta = (5.0 / 8.0 - c * c) / n;
                let chi = 1.0 / (3.0 / (8.0 * beta) + n);
                let mask =
                    (1.0 - n * chi) * m.positions[v] + chi * stars[v].0.iter().sum::<DVec3>();
                let (p, _) = o.evaluate(f, corner.x, corner.y).expect("patch");
                assert!(
                    p.distance(mask) < 1e-12,
                    "face {f} corner {k}: {p} against {mask}"
                );
            }
        }
    }
}

/// The uniform periodic bicubic B-spline of the torus grid at `(u, v)` (control face
/// `(floor u, floor v)`).
fn b_spline(n: usize, m: usize, u: f64, v: f64) -> DVec3 {
    let basis = |s: f64| {
        [
            (1.0 - s).powi(3) / 6.0,
            (3.0 * s.powi(3) - 6.0 * s * s + 4.0) / 6.0,
            (-3.0 * s.powi(3) + 3.0 * s * s + 3.0 * s + 1.0) / 6.0,
            s.powi(3) / 6.0,
        ]
    };
    let (i, j) = (u.floor() as usize, v.floor() as usize);
    let (bu, bv) = (basis(u - i as f64), basis(v - j as f64));
    let mut p = DVec3::ZERO;
    for (a, wa) in bu.iter().enumerate() {
        for (b, wb) in bv.iter().enumerate() {
            p += wa * wb * torus_point(n, m, i + n + a - 1, j + m + b - 1);
        }
    }
    p
}

#[test]
fn a_regular_quad_grid_is_the_uniform_bicubic_b_spline() {
    let (n, m) = (7, 5);
    let o = oracle(&torus_grid(n, m));
    let corners = [DVec2::ZERO, DVec2::X, DVec2::ONE, DVec2::Y];
    for j in 0..m {
        for i in 0..n {
            for k in 0..4 {
                let patch = 4 * (i + n * j) + k;
                let (c, next, prev) = (corners[k], corners[(k + 1) % 4], corners[(k + 3) % 4]);
                for (s, t) in [(0.0, 0.0), (0.3, 0.7), (0.9, 0.1), (1.0, 1.0), (0.5, 0.25)] {
                    let face = c + 0.5 * s * (next - c) + 0.5 * t * (prev - c);
                    let expected = b_spline(n, m, i as f64 + face.x, j as f64 + face.y);
                    let (p, _) = o.evaluate(patch, s, t).expect("patch");
                    assert!(p.distance(expected) < 1e-12, "patch {patch} at ({s}, {t})");
                }
            }
        }
    }
}

/// Points of patch `a` and `b` along a border both patches have: equal positions and normals.
#[test]
fn neighbouring_patches_meet_with_one_tangent_plane() {
    // Catmull–Clark: children 0 and 1 of a control face share the segment from the middle of
    // its first edge to the face centre: (1, s) in child 0, (s, 1) in child 1.
    for m in [cube(), genus_two()] {
        let o = oracle(&m);
        for s in [0.0, 0.25, 0.6, 1.0] {
            let (p0, n0) = o.evaluate(0, 1.0, s).expect("patch");
            let (p1, n1) = o.evaluate(1, s, 1.0).expect("patch");
            assert!(p0.distance(p1) < 1e-12, "{p0} {p1}");
            assert!(n0.distance(n1) < 1e-9, "{n0} {n1}");
        }
    }
}

#[test]
fn evaluation_converges_at_an_extraordinary_vertex() {
    let o = oracle(&cube());
    let (corner, normal) = o.evaluate(0, 0.0, 0.0).expect("patch");
    let mut last = f64::INFINITY;
    for k in [4, 8, 16, 24, 32] {
        let e = 2f64.powi(-k);
        let (p, nk) = o.evaluate(0, e, e).expect("patch");
        let d = p.distance(corner);
        assert!(d < last && d < 4.0 * e, "2^-{k}: {d}");
        assert!(nk.dot(normal) > 0.99, "{nk} {normal}");
        last = d;
    }
}

/// A point off a crease loop by 1e-6 of the diagonal, along a normal of the exact crease (a
/// cubic B-spline, evaluated here on its own), is projected to the foot of that normal, and
/// the polyline's own points stay where they are: both schemes, both loops.
#[test]
fn points_near_a_crease_go_to_the_nearest_point_of_the_exact_crease() {
    for triangles in [false, true] {
        let (control, loops) = creased_torus(8, 6, triangles);
        let o = oracle(&control);
        let diagonal = o.bounding_box().diagonal();
        let curves = o.feature_curves();
        assert_eq!(curves.len(), 2, "two crease loops");
        let mut worst = 0.0f64;
        for l in &loops {
            let curve = curves
                .iter()
                .find(|c| distance_to_crease(l, c.points[0]) < 1e-9 * diagonal)
                .expect("a curve along the loop");
            assert!(curve.closed);
            for &q in &curve.points {
                let r = o.project_to_curve(curve.id, q);
                worst = worst.max(r.distance(q));
            }
            for k in 0..16 * l.len() {
                let [q, tangent] = crease_b_spline(l, k as f64 / 16.0);
                let normal = (tangent.cross(DVec3::Z).normalize() + 0.5 * DVec3::Z).normalize();
                let p = q + 1e-6 * diagonal * normal;
                let r = o.project_to_curve(curve.id, p);
                worst = worst.max(r.distance(q));
            }
        }
        assert!(
            worst <= 1e-12 * diagonal,
            "a projection is {:.2e} × the diagonal from the nearest point",
            worst / diagonal
        );
    }
}

/// Open creases, ending at darts (half a ring of the torus given as a feature polyline) or at
/// crease corners (the cube with every edge sharp): the projection keeps the sampled points,
/// takes a chord's middle to a point it keeps (a point of the curve), and a point past an end
/// along the last chord to that end.
#[test]
fn projections_onto_open_creases_keep_their_points_and_stop_at_their_ends() {
    let (n, m) = (8, 6);
    let half_ring = delamesh_piecewise_smooth::Polyline {
        line: 1,
        points: (0..=n / 2).map(|i| torus_point(n, m, i, 0)).collect(),
    };
    let darts = SubdivisionOracle::new(
        &torus_grid(n, m),
        &SubdivisionOptions::default(),
        &[half_ring],
    )
    .expect("valid");
    let sharp_cube = SubdivisionOracle::new(
        &cube(),
        &SubdivisionOptions {
            crease_angle_deg: Some(60.0),
            ..SubdivisionOptions::default()
        },
        &[],
    )
    .expect("valid");
    for (o, count) in [(darts, 1), (sharp_cube, 12)] {
        let diagonal = o.bounding_box().diagonal();
        let curves = o.feature_curves();
        assert_eq!(curves.len(), count);
        for c in &curves {
            assert!(!c.closed);
            let project = |p: DVec3| o.project_to_curve(c.id, p);
            for w in c.points.windows(2) {
                let (a, b) = (w[0], w[1]);
                assert!(project(a).distance(a) <= 1e-12 * diagonal, "{a} moved");
                let mid = 0.5 * (a + b);
                let r = project(mid);
                assert!(r.distance(mid) <= 1e-6 * diagonal, "{mid} went to {r}");
                assert!(
                    project(r).distance(r) <= 1e-12 * diagonal,
                    "{r} is off the curve"
                );
            }
            let k = c.points.len();
            for (end, before) in [
                (c.points[0], c.points[1]),
                (c.points[k - 1], c.points[k - 2]),
            ] {
                let past = end + 1e-3 * diagonal * (end - before).normalize();
                assert!(
                    project(past).distance(end) <= 1e-12 * diagonal,
                    "past {end}"
                );
            }
        }
    }
}

#[test]
fn hits_lie_on_their_segment_and_the_inside_is_inside() {
    for m in [cube(), octahedron(), torus_grid(6, 5), genus_two()] {
        let o = oracle(&m);
        let b = o.bounding_box();
        let c = b.center();
        let mut hits = Vec::new();
        for k in 0..20 {
            let a = c + 0.01 * DVec3::new(k as f64, 1.0, 0.5);
            let dir = DVec3::new(
                (k as f64).sin(),
                (1.7 * k as f64).cos(),
                0.3 * k as f64 - 2.0,
            );
            let far = a + 2.0 * b.diagonal() * dir.normalize();
            hits.clear();
            o.segment_hits(a, far, &mut hits);
            for h in &hits {
                let on = a + h.t * (far - a);
                assert!(on.distance(h.point) < 1e-9 * b.diagonal());
            }
            // Parity along this segment agrees with the inside test at its start.
            let inside = o.subdomain(a).0 != 0;
            assert_eq!(hits.len() % 2 == 1, inside, "segment {k}");
            assert!(hits.windows(2).all(|w| w[0].t <= w[1].t));
        }
    }
}

#[test]
fn bad_control_meshes_are_refused_by_name() {
    let mut open = cube();
    open.faces.pop();
    open.groups.pop();
    let options = SubdivisionOptions::default();
    let err = |m: &PolygonMesh| SubdivisionOracle::new(m, &options, &[]).err();
    assert!(matches!(err(&open), Some(SubdivisionError::Open { .. })));
    let mut flipped = cube();
    flipped.faces[0].reverse();
    assert!(matches!(
        err(&flipped),
        Some(SubdivisionError::Orientation { .. })
    ));
    let mut degenerate = cube();
    degenerate.faces[0] = vec![0, 2, 2, 1];
    assert!(matches!(
        err(&degenerate),
        Some(SubdivisionError::Degenerate { .. })
    ));
    let empty = common::mesh(Vec::new(), Vec::new());
    assert!(matches!(err(&empty), Some(SubdivisionError::Empty)));
    // Two cubes sharing one vertex: two fans around it.
    let mut pinched = cube();
    let shift = DVec3::splat(2.0);
    let n = pinched.positions.len() as u32;
    pinched
        .positions
        .extend(cube().positions.iter().map(|&p| p + shift).skip(1));
    let remap = |v: u32| if v == 0 { 7 } else { v + n - 1 };
    let more: Vec<Vec<u32>> = cube()
        .faces
        .iter()
        .map(|f| f.iter().map(|&v| remap(v)).collect())
        .collect();
    // The second cube's vertex 0 lands on the first cube's vertex 7 (both at (1, 1, 1)).
    pinched
        .groups
        .extend(more.iter().map(|_| delamesh_core::mesh::PatchId(0)));
    pinched.faces.extend(more);
    assert!(matches!(
        err(&pinched),
        Some(SubdivisionError::NonManifoldVertex { .. })
    ));
    let loop_quads = SubdivisionOptions {
        scheme: Some(Scheme::Loop),
        ..SubdivisionOptions::default()
    };
    assert!(matches!(
        SubdivisionOracle::new(&cube(), &loop_quads, &[]).err(),
        Some(SubdivisionError::LoopNeedsTriangles { .. })
    ));
}

#[test]
fn crossing_counts_agree_in_every_direction() {
    // Parity of the crossings of rays from one point does not depend on the direction: a
    // missed or doubled crossing (near-tangent rays, patch borders) would break it.
    for m in [torus_grid(8, 6), genus_two(), octahedron()] {
        let o = oracle(&m);
        let b = o.bounding_box();
        let dirs = [
            DVec3::new(0.3, 0.5, 0.8),
            DVec3::new(-0.7, 0.2, 0.1),
            DVec3::new(0.1, -0.9, 0.4),
            DVec3::Z,
        ];
        let mut hits = Vec::new();
        for k in 0..400 {
            let f = |s: f64| (s * 12.9898 + k as f64 * 78.233).sin() * 0.5 + 0.5;
            let p = b.min + (b.max - b.min) * DVec3::new(f(1.0), f(2.0), f(3.0));
            let parity: Vec<bool> = dirs
                .iter()
                .map(|&d| {
                    hits.clear();
                    o.segment_hits(p, p + 3.0 * b.diagonal() * d.normalize(), &mut hits);
                    hits.len() % 2 == 1
                })
                .collect();
            assert!(parity.iter().all(|&x| x == parity[0]), "{p}: {parity:?}");
        }
    }
}
