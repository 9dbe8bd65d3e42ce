//! The piecewise-smooth oracle: patches of hits, features through the `Oracle` trait, subdomains.

use delamesh_core::mesh::SurfaceMesh;
use delamesh_core::oracle::{OUTSIDE, Oracle, SurfaceHit};
use delamesh_piecewise_smooth::models::{cylinder, two_boxes};
use delamesh_piecewise_smooth::{FeatureOptions, PiecewiseSmoothOracle};
use delamesh_polyhedral::PolyhedralOracle;
use glam::DVec3;

fn oracle(s: &SurfaceMesh) -> PiecewiseSmoothOracle {
    PiecewiseSmoothOracle::from_surface(s, &FeatureOptions::default(), &[]).expect("valid")
}

/// The surface hits along the segment from `a` to `b`.
fn segment_hits(o: &impl Oracle, a: DVec3, b: DVec3) -> Vec<SurfaceHit> {
    let mut hits = Vec::new();
    o.segment_hits(a, b, &mut hits);
    hits
}

#[test]
fn each_face_of_a_cube_is_hit_with_its_own_patch() {
    let o = oracle(&SurfaceMesh::cuboid(DVec3::ZERO, DVec3::ONE));
    let c = DVec3::splat(0.5);
    let mut patches = Vec::new();
    let mut hits = Vec::new();
    for d in [
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ] {
        hits.clear();
        o.segment_hits(c, c + 0.31 * d + DVec3::new(0.013, 0.021, 0.017), &mut hits);
        assert!(hits.is_empty(), "short segment stays inside");
        o.segment_hits(c, c + d + DVec3::new(0.013, 0.021, 0.017), &mut hits);
        assert_eq!(hits.len(), 1);
        patches.push(hits[0].patch.0);
    }
    patches.sort_unstable();
    assert_eq!(patches, vec![1, 2, 3, 4, 5, 6]);
    // Initial points carry the same patch ids.
    assert!(
        o.initial_points()
            .iter()
            .all(|p| (1..=6).contains(&p.patch.0))
    );
    // Features through the trait: ids 1..=12, corners exactly the cube's vertices.
    let curves = o.feature_curves();
    assert_eq!(
        curves.iter().map(|c| c.id.0).collect::<Vec<_>>(),
        (1..=12).collect::<Vec<_>>()
    );
    let mut corners: Vec<[u64; 3]> = o
        .corners()
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect();
    corners.sort_unstable();
    corners.dedup();
    assert_eq!(corners.len(), 8);
    assert!(
        o.corners()
            .iter()
            .all(|p| p.to_array().iter().all(|&x| x == 0.0 || x == 1.0))
    );
}

#[test]
fn smooth_queries_match_the_polyhedral_oracle() {
    let s = cylinder(1.0, 2.0, 40);
    let o = oracle(&s);
    let plain = PolyhedralOracle::new(&s.positions, &s.triangles, None).unwrap();
    assert_eq!(o.bounding_box(), plain.bounding_box());
    let (mut a, mut b) = (Vec::new(), Vec::new());
    for k in 0..50 {
        let t = k as f64 * 0.37;
        let p = DVec3::new(1.3 * t.cos(), 1.1 * t.sin(), (t * 0.7).fract() * 2.6 - 0.3);
        let q = DVec3::new(-1.2 * (t * 1.3).sin(), 0.9 * t.cos(), 1.0);
        assert_eq!(o.subdomain(p), plain.subdomain(p));
        a.clear();
        b.clear();
        o.segment_hits(p, q, &mut a);
        plain.segment_hits(p, q, &mut b);
        assert_eq!(
            a.iter().map(|h| (h.point, h.t)).collect::<Vec<_>>(),
            b.iter().map(|h| (h.point, h.t)).collect::<Vec<_>>()
        );
    }
}

#[test]
fn two_boxes_are_two_subdomains_across_one_interface_hit() {
    let o = oracle(&two_boxes());
    let left = o.subdomain(DVec3::new(0.3, 0.6, 0.4));
    let right = o.subdomain(DVec3::new(1.7, 0.2, 0.55));
    assert!(left != OUTSIDE && right != OUTSIDE && left != right);
    assert_eq!(o.subdomain(DVec3::new(2.2, 0.5, 0.5)), OUTSIDE);
    assert_eq!(o.polyhedral().num_subdomains(), 2);
    assert!((o.polyhedral().domain_volume() - 2.0).abs() < 1e-12);
    let f = o.features();
    let interface = f.triangle_patches[f.shared_faces[0][0] as usize];
    let mut hits = segment_hits(&o, DVec3::new(0.5, 0.4, 0.3), DVec3::new(1.5, 0.45, 0.35));
    assert_eq!(hits.len(), 1);
    assert_eq!(hits[0].patch, interface);
    assert_eq!(hits[0].point.x, 1.0);
    // Through both boxes: in, interface, out, with three different patches.
    hits = segment_hits(&o, DVec3::new(-0.5, 0.4, 0.3), DVec3::new(2.5, 0.45, 0.35));
    assert_eq!(hits.len(), 3);
    assert_eq!(hits[1].patch, interface);
    assert!(hits[0].patch != hits[2].patch && hits[0].patch != interface);

    // The same boxes welded into one vertex set are read the same way.
    let mut welded = two_boxes();
    delamesh_core::mesh::weld_exact(&mut welded.positions, &mut welded.triangles);
    assert!(welded.positions.len() < 16);
    let w = oracle(&welded);
    assert_eq!(w.subdomain(DVec3::new(0.3, 0.6, 0.4)), left);
    assert_eq!(w.subdomain(DVec3::new(1.7, 0.2, 0.55)), right);
}
