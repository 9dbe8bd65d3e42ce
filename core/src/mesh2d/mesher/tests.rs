use super::{Mesh, MeshError, MeshOptions, mesh};
use crate::mesh2d::pslg::{Pslg, Region};
use crate::mesh2d::quality::{min_angle_deg, signed_area};
use crate::mesh2d::tests::sub_segment_chain;
use crate::random::XorShift;
use glam::DVec2;

fn v(x: f64, y: f64) -> DVec2 {
    DVec2::new(x, y)
}

/// Closed polygon loops as a PSLG.
fn loops(polys: &[Vec<DVec2>]) -> Pslg {
    let mut p = Pslg::default();
    for poly in polys {
        let base = p.points.len() as u32;
        let n = poly.len() as u32;
        p.points.extend_from_slice(poly);
        p.segments
            .extend((0..n).map(|k| [base + k, base + (k + 1) % n]));
    }
    p.segment_markers = vec![0; p.segments.len()];
    p
}

fn square(lo: f64, hi: f64) -> Vec<DVec2> {
    vec![v(lo, lo), v(hi, lo), v(hi, hi), v(lo, hi)]
}

/// A star with `n` spikes of tip angle about `tip_deg`.
fn star(n: usize, tip_deg: f64) -> Vec<DVec2> {
    let outer = 10.0;
    let half = std::f64::consts::PI / n as f64;
    // Inner radius giving the requested tip angle.
    let tip = tip_deg.to_radians() / 2.0;
    let inner = outer * tip.sin() / (tip + half).sin();
    (0..2 * n)
        .map(|k| {
            let th = half * k as f64;
            let r = if k % 2 == 0 { outer } else { inner };
            v(th.cos(), th.sin()) * r
        })
        .collect()
}

fn area(m: &Mesh) -> f64 {
    m.triangles
        .iter()
        .map(|t| {
            signed_area(
                m.points[t[0] as usize],
                m.points[t[1] as usize],
                m.points[t[2] as usize],
            )
        })
        .sum()
}

fn has_edge(m: &Mesh, a: u32, b: u32) -> bool {
    m.triangles.iter().any(|t| t.contains(&a) && t.contains(&b))
}

/// Every input segment is a chain of output sub-segments, each an edge of a domain triangle.
fn assert_segments_conform(input: &Pslg, m: &Mesh) {
    for (s, &[a, b]) in input.segments.iter().enumerate() {
        let chain = sub_segment_chain(&m.segments, &m.segment_origins, s, a);
        assert_eq!(chain.last(), Some(&b));
        for w in chain.windows(2) {
            let (x, y) = (w[0], w[1]);
            assert!(has_edge(m, x, y), "sub-segment {x}-{y} is not a mesh edge");
        }
    }
}

fn assert_triangles_valid(m: &Mesh) {
    for t in &m.triangles {
        let p = t.map(|i| m.points[i as usize]);
        assert!(signed_area(p[0], p[1], p[2]) > 0.0);
    }
}

/// Meshes `input` with these bounds, checking the triangles and that the segments conform.
fn mesh_checked(input: &Pslg, min_angle_deg: f64, max_area: Option<f64>) -> Mesh {
    let opts = MeshOptions {
        min_angle_deg,
        max_area,
        ..MeshOptions::default()
    };
    let m = mesh(input, &opts).expect("meshes");
    assert_triangles_valid(&m);
    assert_segments_conform(input, &m);
    m
}

#[test]
fn square_with_hole_meets_the_angle_bound() {
    let input = Pslg {
        holes: vec![v(5.0, 5.0)],
        ..loops(&[square(0.0, 10.0), square(4.0, 6.0)])
    };
    let m = mesh_checked(&input, 30.0, None);
    for t in &m.triangles {
        let p = t.map(|i| m.points[i as usize]);
        assert!(min_angle_deg(p[0], p[1], p[2]) >= 30.0 - 1e-9, "{p:?}");
        // Hole empty: no triangle has its centroid inside the hole.
        let c = (p[0] + p[1] + p[2]) / 3.0;
        assert!(!(c.x > 4.0 && c.x < 6.0 && c.y > 4.0 && c.y < 6.0));
    }
    assert!((area(&m) - 96.0).abs() < 1e-9);
    assert_eq!(&m.points[..8], &input.points[..]);
    // Deterministic.
    assert_eq!(mesh_checked(&input, 30.0, None), m);
}

#[test]
fn area_bound_and_regions() {
    let mut input = loops(&[square(0.0, 4.0)]);
    // A vertical divider splitting the square into two regions.
    input.points.extend([v(2.0, 0.0), v(2.0, 4.0)]);
    input.segments = vec![[0, 4], [4, 1], [1, 2], [2, 5], [5, 3], [3, 0], [4, 5]];
    input.segment_markers = vec![0; 7];
    input.regions = vec![
        Region {
            point: v(1.0, 1.0),
            attribute: 1.0,
            max_area: Some(0.05),
        },
        Region {
            point: v(3.0, 1.0),
            attribute: 2.0,
            max_area: None,
        },
    ];
    let m = mesh_checked(&input, 25.0, Some(0.5));
    assert!((area(&m) - 16.0).abs() < 1e-9);
    for (t, &attr) in m.triangles.iter().zip(&m.triangle_attributes) {
        let p = t.map(|i| m.points[i as usize]);
        let c = (p[0] + p[1] + p[2]) / 3.0;
        assert_eq!(attr, if c.x < 2.0 { 1.0 } else { 2.0 });
        let bound = if attr == 1.0 { 0.05 } else { 0.5 };
        assert!(signed_area(p[0], p[1], p[2]) <= bound);
    }
}

#[test]
fn star_with_sharp_spikes_terminates_and_is_good_away_from_tips() {
    let input = loops(&[star(5, 10.0)]);
    let m = mesh_checked(&input, 30.0, Some(0.5));
    // The spikes: triangles (inner vertex, tip, inner vertex) around each 10° angle.
    let n = input.points.len();
    let spikes: Vec<[DVec2; 3]> = (0..n)
        .step_by(2)
        .map(|k| {
            [
                input.points[(k + n - 1) % n],
                input.points[k],
                input.points[(k + 1) % n],
            ]
        })
        .collect();
    let in_spike = |q: DVec2| {
        spikes
            .iter()
            .any(|t| (0..3).all(|i| signed_area(t[i], t[(i + 1) % 3], q) >= -1e-9))
    };
    let mut skinny = 0;
    for t in &m.triangles {
        let p = t.map(|i| m.points[i as usize]);
        if min_angle_deg(p[0], p[1], p[2]) < 30.0 - 1e-9 {
            skinny += 1;
            // Only inside a spike, next to its small input angle.
            assert!(
                p.iter().all(|&q| in_spike(q)),
                "skinny triangle {p:?} away from the small angles"
            );
        }
    }
    assert!(
        skinny < m.triangles.len() / 2,
        "{skinny} of {}",
        m.triangles.len()
    );
}

#[test]
fn bad_options_and_input_are_errors() {
    let input = loops(&[square(0.0, 1.0)]);
    let too_sharp = MeshOptions {
        min_angle_deg: 40.0,
        ..MeshOptions::default()
    };
    assert!(matches!(
        mesh(&input, &too_sharp),
        Err(MeshError::Option(_))
    ));
    let crossing = Pslg {
        segments: vec![[0, 2], [1, 3]],
        segment_markers: vec![0, 0],
        ..input
    };
    assert!(matches!(
        mesh(&crossing, &MeshOptions::default()),
        Err(MeshError::Invalid(_))
    ));
}

#[test]
fn vertex_limit_stops_refinement() {
    let input = loops(&[square(0.0, 1.0)]);
    // The area bound allows the 200 triangles the limit could make, but not with good angles.
    let opts = MeshOptions {
        max_area: Some(5e-3),
        max_vertices: 100,
        ..MeshOptions::default()
    };
    assert!(matches!(mesh(&input, &opts), Err(MeshError::Refine(_))));
    // An area bound needing far more triangles than the limit allows is refused before work.
    let impossible = MeshOptions {
        max_area: Some(1e-4),
        ..opts
    };
    assert!(matches!(
        mesh(&input, &impossible),
        Err(MeshError::Option(_))
    ));
    // Fewer allowed vertices than the input has: refused too.
    let none = MeshOptions {
        max_vertices: 0,
        ..MeshOptions::default()
    };
    assert!(matches!(mesh(&input, &none), Err(MeshError::Refine(_))));
}

/// Star-shaped polygons with random radii at random angles (a fixed sequence): concave
/// outlines with notches of every depth and angle. Each one meshes, conforming to every
/// segment, with positive triangles covering its area.
#[test]
fn random_star_shaped_polygons_mesh_and_conform() {
    let mut rng = XorShift::new(0x2545_f491_4f6c_dd1d);
    let mut next = || rng.next_f64();
    for case in 0..60 {
        let n = 5 + (next() * 20.0) as usize;
        // Gaps between consecutive angles below half a turn: the polygon is simple.
        let gaps: Vec<f64> = (0..n).map(|_| 0.5 + next()).collect();
        let total: f64 = gaps.iter().sum();
        let start = next() * std::f64::consts::TAU;
        let angles: Vec<f64> = gaps
            .iter()
            .scan(start, |t, g| {
                *t += g / total * std::f64::consts::TAU;
                Some(*t)
            })
            .collect();
        let poly: Vec<DVec2> = angles
            .iter()
            .map(|&t| v(t.cos(), t.sin()) * (2.0 + 8.0 * next()))
            .collect();
        let input = loops(std::slice::from_ref(&poly));
        let opts = MeshOptions {
            min_angle_deg: 20.0,
            ..MeshOptions::default()
        };
        let m = mesh(&input, &opts).unwrap_or_else(|e| panic!("case {case}: {e}"));
        assert_triangles_valid(&m);
        assert_segments_conform(&input, &m);
        let polygon_area: f64 = (0..poly.len())
            .map(|k| poly[k].perp_dot(poly[(k + 1) % poly.len()]) / 2.0)
            .sum();
        assert!(
            (area(&m) - polygon_area).abs() < 1e-9 * polygon_area,
            "case {case}: area {} instead of {polygon_area}",
            area(&m)
        );
    }
}

/// A notched outline (a slot cut down from the top edge, its pocket outside the domain) with a
/// square hole right beside the slot: both stay empty, and the rest is covered exactly.
#[test]
fn a_notch_with_a_hole_beside_it_meshes() {
    let outline = vec![
        v(0.0, 0.0),
        v(4.0, 0.0),
        v(4.0, 3.0),
        v(2.2, 3.0),
        v(2.2, 1.0),
        v(1.8, 1.0),
        v(1.8, 3.0),
        v(0.0, 3.0),
    ];
    let hole = vec![v(2.4, 1.5), v(3.0, 1.5), v(3.0, 2.1), v(2.4, 2.1)];
    let input = Pslg {
        holes: vec![v(2.7, 1.8)],
        ..loops(&[outline, hole])
    };
    let m = mesh_checked(&input, 25.0, None);
    let expected = 12.0 - 0.4 * 2.0 - 0.6 * 0.6;
    assert!((area(&m) - expected).abs() < 1e-9, "area {}", area(&m));
    for t in &m.triangles {
        let c = t.iter().map(|&i| m.points[i as usize]).sum::<DVec2>() / 3.0;
        let in_slot = c.x > 1.8 && c.x < 2.2 && c.y > 1.0;
        let in_hole = c.x > 2.4 && c.x < 3.0 && c.y > 1.5 && c.y < 2.1;
        assert!(!in_slot && !in_hole, "a triangle at {c:?}");
    }
}
