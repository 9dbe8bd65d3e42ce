//! Properties of the polyhedral oracle on simple closed surfaces.

use delamesh_core::oracle::{OUTSIDE, Oracle, SurfaceHit};
use delamesh_polyhedral::{PolyhedralError, PolyhedralOptions, PolyhedralOracle};
use glam::DVec3;

/// A cube [0, 1]^3 as 12 outward triangles, shifted by `offset` and scaled by `scale`.
fn cube(offset: DVec3, scale: f64, inward: bool) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let m = delamesh_core::mesh::SurfaceMesh::cuboid(offset, offset + DVec3::splat(scale));
    let tris = m
        .triangles
        .into_iter()
        .map(|[a, b, c]| if inward { [a, c, b] } else { [a, b, c] })
        .collect();
    (m.positions, tris)
}

/// The surface hits along the segment from `a` to `b`.
fn segment_hits(o: &impl Oracle, a: DVec3, b: DVec3) -> Vec<SurfaceHit> {
    let mut hits = Vec::new();
    o.segment_hits(a, b, &mut hits);
    hits
}

fn merge(
    a: (Vec<DVec3>, Vec<[u32; 3]>),
    b: (Vec<DVec3>, Vec<[u32; 3]>),
) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let (mut p, mut t) = a;
    let off = p.len() as u32;
    p.extend(b.0);
    t.extend(b.1.into_iter().map(|x| x.map(|v| v + off)));
    (p, t)
}

#[test]
fn inside_test_of_a_cube_including_degenerate_rays() {
    let (p, t) = cube(DVec3::ZERO, 1.0, false);
    let o = PolyhedralOracle::new(&p, &t, None).expect("valid cube");
    // Centre and points in the planes of edges and diagonals, where naive rays graze edges.
    for q in [
        DVec3::splat(0.5),
        DVec3::new(0.5, 0.5, 0.25),
        DVec3::new(0.25, 0.25, 0.25),
        DVec3::new(0.9, 0.1, 0.5),
    ] {
        assert_ne!(o.subdomain(q), OUTSIDE, "{q} is inside");
    }
    for q in [
        DVec3::splat(1.5),
        DVec3::new(0.5, 0.5, -0.25),
        DVec3::new(-0.1, 0.5, 0.5),
        DVec3::new(1.0 + 1e-12, 0.5, 0.5),
    ] {
        assert_eq!(o.subdomain(q), OUTSIDE, "{q} is outside");
    }
    assert!((o.domain_volume() - 1.0).abs() < 1e-12);
}

#[test]
fn inverted_cube_is_still_a_domain() {
    let (p, t) = cube(DVec3::ZERO, 1.0, true);
    let o = PolyhedralOracle::new(&p, &t, None).expect("valid cube");
    assert_ne!(o.subdomain(DVec3::splat(0.5)), OUTSIDE);
}

#[test]
fn nested_cubes_give_two_subdomains_or_a_hollow() {
    let outer = cube(DVec3::ZERO, 3.0, false);
    let inner = cube(DVec3::splat(1.0), 1.0, false);
    let (p, t) = merge(outer.clone(), inner);
    let o = PolyhedralOracle::new(&p, &t, None).expect("nested cubes");
    let core = o.subdomain(DVec3::splat(1.5));
    let shell = o.subdomain(DVec3::splat(0.5));
    assert!(core != OUTSIDE && shell != OUTSIDE && core != shell);
    assert_eq!(o.num_subdomains(), 2);
    assert!((o.domain_volume() - 27.0).abs() < 1e-9);

    let hollow = cube(DVec3::splat(1.0), 1.0, true);
    let (p, t) = merge(outer, hollow);
    let o = PolyhedralOracle::new(&p, &t, None).expect("hollow cube");
    assert_eq!(o.subdomain(DVec3::splat(1.5)), OUTSIDE);
    assert_ne!(o.subdomain(DVec3::splat(0.5)), OUTSIDE);
    assert_eq!(o.num_subdomains(), 1);
    assert!((o.domain_volume() - 26.0).abs() < 1e-9);
}

#[test]
fn segment_hits_are_sorted_with_patches() {
    let (p, t) = cube(DVec3::ZERO, 1.0, false);
    let o = PolyhedralOracle::new(&p, &t, None).expect("valid cube");
    let mut hits = segment_hits(&o, DVec3::new(-1.0, 0.3, 0.4), DVec3::new(2.0, 0.3, 0.4));
    assert_eq!(hits.len(), 2);
    assert!((hits[0].point.x - 0.0).abs() < 1e-12 && (hits[1].point.x - 1.0).abs() < 1e-12);
    assert!(hits[0].t < hits[1].t);
    assert!(hits.iter().all(|h| h.patch.0 == 1));
    // Through an edge shared by two triangles (the face diagonal): reported once.
    hits = segment_hits(&o, DVec3::new(0.5, 0.5, -1.0), DVec3::new(0.5, 0.5, 0.5));
    assert_eq!(hits.len(), 1);
    hits.clear();
    o.ray_hits(DVec3::splat(0.5), DVec3::new(0.0, 0.0, 2.0), &mut hits);
    assert_eq!(hits.len(), 1);
    assert!((hits[0].point.z - 1.0).abs() < 1e-12 && (hits[0].t - 0.25).abs() < 1e-12);
}

/// The circumcentre of a nearly flat cell can lie 10¹⁵ away: a segment from there must still
/// report its crossing on the surface, not a point smeared by cancellation.
#[test]
fn crossing_of_a_segment_from_very_far_lies_on_the_surface() {
    let (p, t) = cube(DVec3::ZERO, 1.0, false);
    let o = PolyhedralOracle::new(&p, &t, None).expect("valid cube");
    let near = DVec3::new(0.5, 0.3, 0.4);
    for far in [
        DVec3::new(-4.8e15, 0.3, 0.4),
        DVec3::new(-4.8e15, -1.8e15, 1.5e15),
        DVec3::new(3.0e15, 1.0e15, -2.0e15),
    ] {
        for (a, b) in [(far, near), (near, far)] {
            let mut hits = Vec::new();
            o.segment_hits(a, b, &mut hits);
            assert_eq!(hits.len(), 1, "{a} → {b}");
            let q = hits[0].point;
            let on_a_face = (0..3).any(|k| q[k].abs() < 1e-9 || (q[k] - 1.0).abs() < 1e-9);
            let in_the_cube = (0..3).all(|k| (-1e-9..=1.0 + 1e-9).contains(&q[k]));
            assert!(on_a_face && in_the_cube, "{a} → {b} crosses at {q}");
            // And the crossing lies on the segment.
            let along = (q - near).normalize().dot((far - near).normalize());
            assert!(along > 1.0 - 1e-9, "{q} is off the segment");
        }
    }
}

#[test]
fn initial_points_lie_on_every_component() {
    let (p, t) = merge(
        cube(DVec3::ZERO, 3.0, false),
        cube(DVec3::splat(1.0), 1.0, false),
    );
    let o = PolyhedralOracle::new(&p, &t, None).expect("nested cubes");
    let pts = o.initial_points();
    assert!(pts.iter().any(|s| s.patch.0 == 1) && pts.iter().any(|s| s.patch.0 == 2));
    for s in &pts {
        assert!(o.distance_to_surface(s.point) < 1e-9);
    }
}

/// The oracle of `--strict`, which refuses what it would otherwise repair.
fn strict(p: &[DVec3], t: &[[u32; 3]]) -> Result<PolyhedralOracle, PolyhedralError> {
    PolyhedralOracle::with_options(p, t, None, &PolyhedralOptions { strict: true })
}

#[test]
fn strict_rejects_surfaces_that_bound_no_volume() {
    let (p, t) = cube(DVec3::ZERO, 1.0, false);
    assert!(matches!(
        strict(&p, &t[1..]),
        Err(PolyhedralError::NotClosed(_))
    ));
    let mut flipped = t.clone();
    flipped[0] = [t[0][0], t[0][2], t[0][1]];
    assert!(matches!(
        strict(&p, &flipped),
        Err(PolyhedralError::Inconsistent(_))
    ));
    let (p2, t2) = merge(
        cube(DVec3::ZERO, 1.0, false),
        cube(DVec3::splat(0.5), 1.0, false),
    );
    assert!(matches!(
        strict(&p2, &t2),
        Err(PolyhedralError::SelfIntersecting(..))
    ));
    let bad = vec![[0, 1, 99]];
    assert!(matches!(
        PolyhedralOracle::new(&p, &bad, None),
        Err(PolyhedralError::IndexOutOfRange { .. })
    ));
    assert!(matches!(
        PolyhedralOracle::new(&p, &[], None),
        Err(PolyhedralError::Empty)
    ));
    let mut nan = p.clone();
    nan[3].x = f64::NAN;
    assert!(matches!(
        PolyhedralOracle::new(&nan, &t, None),
        Err(PolyhedralError::NonFinite(3))
    ));
}

/// `with_defects` keeps a clean surface as given and reports nothing; a crossing surface is
/// reported and repaired (its domain is where the winding number is positive), or refused with
/// `strict`.
#[test]
fn with_defects_reports_what_the_surface_had_as_given() {
    let lenient = PolyhedralOptions::default();
    let (p, t) = cube(DVec3::ZERO, 1.0, false);
    let (o, defects) = PolyhedralOracle::with_defects(&p, &t, None, &lenient).expect("cube");
    assert!(defects.is_empty());
    assert_eq!(o.repairs(), &Default::default());
    assert!((o.domain_volume() - 1.0).abs() < 1e-12);
    let (p2, t2) = merge(
        cube(DVec3::ZERO, 1.0, false),
        cube(DVec3::splat(0.5), 1.0, false),
    );
    let (o, defects) = PolyhedralOracle::with_defects(&p2, &t2, None, &lenient).expect("union");
    assert!(defects.first_intersection.is_some());
    assert!(o.repairs().crossing_triangles > 0);
    assert_ne!(o.subdomain(DVec3::splat(1.25)), OUTSIDE);
    assert_eq!(o.subdomain(DVec3::new(1.25, 0.25, 0.25)), OUTSIDE);
    let strict = PolyhedralOptions { strict: true };
    assert!(matches!(
        PolyhedralOracle::with_defects(&p2, &t2, None, &strict),
        Err(PolyhedralError::SelfIntersecting(..))
    ));
}

#[test]
fn boxes_sharing_a_face_are_two_subdomains_not_a_self_intersection() {
    // Each box keeps its own copy of the common face x = 1 (coincident triangles, opposite
    // orientations): a supported multi-domain input, not a crossing.
    let (p, t) = merge(cube(DVec3::ZERO, 1.0, false), cube(DVec3::X, 1.0, false));
    let o = PolyhedralOracle::new(&p, &t, None).expect("touching boxes are valid");
    assert_eq!(o.num_subdomains(), 2);
    let left = o.subdomain(DVec3::new(0.4, 0.6, 0.3));
    let right = o.subdomain(DVec3::new(1.6, 0.3, 0.7));
    assert!(left != OUTSIDE && right != OUTSIDE && left != right);
    assert_eq!(o.subdomain(DVec3::new(2.5, 0.5, 0.5)), OUTSIDE);
    assert!((o.domain_volume() - 2.0).abs() < 1e-12);
    // Crossing the common face meets it once.
    let hits = segment_hits(&o, DVec3::new(0.5, 0.3, 0.4), DVec3::new(1.5, 0.3, 0.4));
    assert_eq!(hits.len(), 1);
    assert_eq!(hits[0].point.x, 1.0);

    // A box poking into the other one still crosses it.
    let (p, t) = merge(
        cube(DVec3::ZERO, 1.0, false),
        cube(DVec3::new(0.5, 0.25, 0.25), 1.0, false),
    );
    assert!(matches!(
        strict(&p, &t),
        Err(PolyhedralError::SelfIntersecting(..))
    ));
}

#[test]
fn subdomains_of_many_points_match_the_geometry_whatever_the_query_order() {
    // Labels are remembered per empty grid cell: asking in two orders must not change them.
    let outer = cube(DVec3::ZERO, 3.0, false);
    let inner = cube(DVec3::splat(1.0), 1.0, false);
    let (p, t) = merge(outer, inner);
    let o = PolyhedralOracle::new(&p, &t, None).expect("nested cubes");
    let (core, shell) = (
        o.subdomain(DVec3::splat(1.5)),
        o.subdomain(DVec3::splat(0.5)),
    );
    let mut state = 0x9e37_79b9_7f4a_7c15_u64;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 11) as f64 / (1u64 << 53) as f64 * 3.2 - 0.1
    };
    let points: Vec<DVec3> = (0..5000)
        .map(|_| DVec3::new(next(), next(), next()))
        .collect();
    let expected = |q: DVec3| {
        if q.cmpgt(DVec3::splat(1.0)).all() && q.cmplt(DVec3::splat(2.0)).all() {
            core
        } else if q.cmpgt(DVec3::ZERO).all() && q.cmplt(DVec3::splat(3.0)).all() {
            shell
        } else {
            OUTSIDE
        }
    };
    for q in points.iter().chain(points.iter().rev()) {
        assert_eq!(o.subdomain(*q), expected(*q), "{q}");
    }
}
