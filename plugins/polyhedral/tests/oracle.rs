//! Properties of the polyhedral oracle on simple closed surfaces.

use delamesh_core::oracle::{OUTSIDE, Oracle};
use delamesh_polyhedral::{PolyhedralError, PolyhedralOracle};
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
    let mut hits = Vec::new();
    o.segment_hits(
        DVec3::new(-1.0, 0.3, 0.4),
        DVec3::new(2.0, 0.3, 0.4),
        &mut hits,
    );
    assert_eq!(hits.len(), 2);
    assert!((hits[0].point.x - 0.0).abs() < 1e-12 && (hits[1].point.x - 1.0).abs() < 1e-12);
    assert!(hits[0].t < hits[1].t);
    assert!(hits.iter().all(|h| h.patch == 1));
    // Through an edge shared by two triangles (the face diagonal): reported once.
    hits.clear();
    o.segment_hits(
        DVec3::new(0.5, 0.5, -1.0),
        DVec3::new(0.5, 0.5, 0.5),
        &mut hits,
    );
    assert_eq!(hits.len(), 1);
    hits.clear();
    o.ray_hits(DVec3::splat(0.5), DVec3::new(0.0, 0.0, 2.0), &mut hits);
    assert_eq!(hits.len(), 1);
    assert!((hits[0].point.z - 1.0).abs() < 1e-12 && (hits[0].t - 0.25).abs() < 1e-12);
}

#[test]
fn initial_points_lie_on_every_component() {
    let (p, t) = merge(
        cube(DVec3::ZERO, 3.0, false),
        cube(DVec3::splat(1.0), 1.0, false),
    );
    let o = PolyhedralOracle::new(&p, &t, None).expect("nested cubes");
    let pts = o.initial_points();
    assert!(pts.iter().any(|s| s.patch == 1) && pts.iter().any(|s| s.patch == 2));
    for s in &pts {
        assert!(o.distance_to_surface(s.point) < 1e-9);
    }
}

#[test]
fn rejects_surfaces_that_bound_no_volume() {
    let (p, t) = cube(DVec3::ZERO, 1.0, false);
    assert!(matches!(
        PolyhedralOracle::new(&p, &t[1..], None),
        Err(PolyhedralError::NotClosed(_))
    ));
    let mut flipped = t.clone();
    flipped[0] = [t[0][0], t[0][2], t[0][1]];
    assert!(matches!(
        PolyhedralOracle::new(&p, &flipped, None),
        Err(PolyhedralError::Inconsistent(_))
    ));
    let (p2, t2) = merge(
        cube(DVec3::ZERO, 1.0, false),
        cube(DVec3::splat(0.5), 1.0, false),
    );
    assert!(matches!(
        PolyhedralOracle::new(&p2, &t2, None),
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
    let mut hits = Vec::new();
    o.segment_hits(
        DVec3::new(0.5, 0.3, 0.4),
        DVec3::new(1.5, 0.3, 0.4),
        &mut hits,
    );
    assert_eq!(hits.len(), 1);
    assert_eq!(hits[0].point.x, 1.0);

    // A box poking into the other one still crosses it.
    let (p, t) = merge(
        cube(DVec3::ZERO, 1.0, false),
        cube(DVec3::new(0.5, 0.25, 0.25), 1.0, false),
    );
    assert!(matches!(
        PolyhedralOracle::new(&p, &t, None),
        Err(PolyhedralError::SelfIntersecting(..))
    ));
}
