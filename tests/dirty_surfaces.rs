//! Surfaces users actually have: inconsistently oriented, open, overlapping, self-intersecting,
//! non-manifold. Each is repaired or read by its winding number and meshed; `strict` refuses it.

mod common;

use common::{Surface, criteria, cuboid, flipped, sphere};
use delamesh::core::complex::MeshComplex;
use delamesh::core::oracle::{OUTSIDE, Oracle};
use delamesh::core::quality::{self, surface_topology};
use delamesh::core::refine::{Limits, MeshOptions, mesh_domain};
use delamesh::polyhedral::{PolyhedralError, PolyhedralOptions, PolyhedralOracle, diagnose};
use glam::DVec3;

fn oracle(s: &Surface) -> PolyhedralOracle {
    PolyhedralOracle::new(&s.points, &s.triangles, None).expect("repairable surface")
}

fn strict(s: &Surface) -> Result<PolyhedralOracle, PolyhedralError> {
    PolyhedralOracle::with_options(
        &s.points,
        &s.triangles,
        None,
        &PolyhedralOptions { strict: true },
    )
}

fn mesh_of(oracle: &PolyhedralOracle, size: f64) -> MeshComplex {
    let options = MeshOptions {
        criteria: criteria(25.0, size, size / 10.0, 3.0, size),
        limits: Limits {
            max_vertices: 100_000,
            ..Limits::default()
        },
        keep_partial: false,
        validity: Default::default(),
        optimize: delamesh_core::optimize::OptimizeOptions::none(),
    };
    mesh_domain(oracle, &options, &mut |_| {})
        .expect("refinement terminates")
        .complex
}

fn mesh_volume(c: &MeshComplex) -> f64 {
    (0..c.tets.len())
        .map(|t| quality::tet_volume(&c.tet_points(t)))
        .sum()
}

/// The boundary is a closed 2-manifold with Euler characteristic `chi`, and the tets are
/// positive.
fn assert_valid(c: &MeshComplex, chi: i64) {
    assert!(!c.tets.is_empty());
    assert!((0..c.tets.len()).all(|t| quality::tet_volume(&c.tet_points(t)) > 0.0));
    let topology = surface_topology(&c.facets);
    assert_eq!(topology.border_edges, 0, "boundary is closed");
    assert_eq!(topology.non_manifold_edges, 0, "boundary is edge-manifold");
    assert_eq!(
        topology.non_manifold_vertices, 0,
        "boundary is vertex-manifold"
    );
    assert_eq!(topology.euler_characteristic, chi);
}

/// Reverses every `k`-th triangle, starting with the `first`.
fn shuffle(mut s: Surface, first: usize, k: usize) -> Surface {
    for t in s.triangles.iter_mut().skip(first).step_by(k) {
        t.swap(1, 2);
    }
    s
}

#[test]
fn shuffled_orientations_give_the_same_mesh_as_the_clean_input() {
    let clean = sphere(DVec3::ZERO, 1.0, 2);
    let shuffled = shuffle(clean.clone(), 1, 3);
    let repaired = oracle(&shuffled);
    assert!(repaired.repairs().flipped > 0);
    assert!(!repaired.repairs().needs_winding_domain());
    let (a, b) = (mesh_of(&oracle(&clean), 0.4), mesh_of(&repaired, 0.4));
    assert_eq!(a.points, b.points);
    assert_eq!(a.tets, b.tets);
    // All reversed (a deliberate inward surface is kept), and half reversed, fixed outwards.
    let half = shuffle(clean.clone(), 0, 2);
    assert!(oracle(&half).subdomain(DVec3::ZERO) != OUTSIDE);
    assert!(oracle(&half).repairs().flipped > 0);
}

#[test]
fn two_overlapping_boxes_give_one_solid_of_the_union_volume() {
    let boxes = cuboid(DVec3::ZERO, DVec3::ONE).merge(cuboid(
        DVec3::new(0.5, 0.25, 0.3),
        DVec3::new(1.5, 1.25, 1.3),
    ));
    let union = 2.0 - 0.5 * 0.75 * 0.7;
    let o = oracle(&boxes);
    assert!(o.repairs().crossing_triangles > 0);
    assert_eq!(o.num_subdomains(), 1);
    assert!((o.domain_volume() - union).abs() < 0.01 * union);
    // The buried faces are no surface: a segment across the overlap meets nothing, one leaving
    // the union meets it once.
    let (inside, overlap, out) = (
        DVec3::new(0.25, 0.5, 0.5),
        DVec3::new(0.75, 0.6, 0.6),
        DVec3::new(1.25, 0.6, 0.6),
    );
    let mut hits = Vec::new();
    o.segment_hits(inside, out, &mut hits);
    assert!(hits.is_empty(), "{hits:?}");
    assert!(o.subdomain(overlap) != OUTSIDE);
    o.segment_hits(overlap, DVec3::new(0.75, 0.6, 2.0), &mut hits);
    assert_eq!(hits.len(), 1);
    assert!((hits[0].point.z - 1.3).abs() < 1e-12);

    let c = mesh_of(&o, 0.2);
    assert_valid(&c, 2);
    assert!((mesh_volume(&c) - union).abs() < 0.02 * union);
}

/// Two copies of a box shifted along x: their faces y = 0, 1 and z = 0, 1 overlap in their
/// planes, where the winding number goes from two to zero. Both copies bound the union there.
#[test]
fn boxes_overlapping_in_their_face_planes_give_the_union() {
    let boxes = cuboid(DVec3::ZERO, DVec3::ONE)
        .merge(cuboid(DVec3::new(0.3, 0.0, 0.0), DVec3::new(1.3, 1.0, 1.0)));
    let o = oracle(&boxes);
    assert!((o.domain_volume() - 1.3).abs() < 0.01);
    // Up from inside both, through the shared top face: one hit, on it.
    let mut hits = Vec::new();
    o.segment_hits(
        DVec3::new(0.6, 0.4, 0.5),
        DVec3::new(0.6, 0.4, 2.0),
        &mut hits,
    );
    assert_eq!(hits.len(), 1, "{hits:?}");
    assert!((hits[0].point.z - 1.0).abs() < 1e-12);

    let c = mesh_of(&o, 0.2);
    assert_valid(&c, 2);
    assert!(
        (mesh_volume(&c) - 1.3).abs() < 0.02 * 1.3,
        "{}",
        mesh_volume(&c)
    );
}

#[test]
fn a_cube_with_a_missing_face_gives_the_cube() {
    let mut open = cuboid(DVec3::ZERO, DVec3::ONE);
    // Without the two triangles of the face z = 1.
    let points = open.points.clone();
    open.triangles
        .retain(|t| !t.iter().all(|&v| points[v as usize].z == 1.0));
    assert_eq!(open.triangles.len(), 10);
    let o = oracle(&open);
    assert_eq!(o.repairs().border_edges, 4);
    assert!((o.domain_volume() - 1.0).abs() < 1e-9);
    let mut hits = Vec::new();
    o.segment_hits(DVec3::splat(0.5), DVec3::new(0.5, 0.5, 1.5), &mut hits);
    assert_eq!(hits.len(), 1);
    assert!((hits[0].point.z - 1.0).abs() < 1e-12);
    let c = mesh_of(&o, 0.25);
    assert_valid(&c, 2);
    assert!((mesh_volume(&c) - 1.0).abs() < 0.05);
}

#[test]
fn self_intersecting_spheres_mesh_to_a_manifold_of_the_winding_volume() {
    let s = sphere(DVec3::ZERO, 1.0, 3).merge(sphere(DVec3::new(0.9, 0.2, 0.1), 0.8, 3));
    let o = oracle(&s);
    assert!(o.repairs().crossing_triangles > 0);
    let c = mesh_of(&o, 0.15);
    assert_valid(&c, 2);
    let v = mesh_volume(&c);
    assert!(
        (v - o.domain_volume()).abs() < 0.02 * o.domain_volume(),
        "mesh volume {v}, winding-number volume {}",
        o.domain_volume()
    );
}

#[test]
fn non_manifold_edge_of_two_boxes_is_one_domain() {
    // Two boxes sharing the edge x = 1, y = 1 (welded): four triangles around it.
    let a = cuboid(DVec3::ZERO, DVec3::ONE);
    let b = cuboid(DVec3::new(1.0, 1.0, 0.0), DVec3::new(2.0, 2.0, 1.0));
    let mut s = a.merge(b);
    weld(&mut s);
    let o = oracle(&s);
    assert!(o.repairs().non_manifold_edges > 0);
    assert!((o.domain_volume() - 2.0).abs() < 0.02);
    assert!(o.subdomain(DVec3::splat(0.5)) != OUTSIDE);
    assert!(o.subdomain(DVec3::new(1.5, 1.5, 0.5)) != OUTSIDE);
    assert_eq!(o.subdomain(DVec3::new(1.5, 0.5, 0.5)), OUTSIDE);
    assert!(matches!(strict(&s), Err(PolyhedralError::NonManifold(_))));
}

/// Merges vertices with equal coordinates.
fn weld(s: &mut Surface) {
    let mut index: Vec<u32> = Vec::with_capacity(s.points.len());
    let mut kept: Vec<DVec3> = Vec::new();
    for p in &s.points {
        let i = kept.iter().position(|q| q == p).unwrap_or_else(|| {
            kept.push(*p);
            kept.len() - 1
        });
        index.push(i as u32);
    }
    s.points = kept;
    for t in &mut s.triangles {
        *t = t.map(|v| index[v as usize]);
    }
}

#[test]
fn strict_refuses_each_class_with_its_diagnosis() {
    let cube = cuboid(DVec3::ZERO, DVec3::ONE);
    let mut open = cube.clone();
    open.triangles.pop();
    assert!(matches!(strict(&open), Err(PolyhedralError::NotClosed(3))));
    let shuffled = shuffle(cube.clone(), 0, 4);
    assert!(matches!(
        strict(&shuffled),
        Err(PolyhedralError::Inconsistent(_))
    ));
    let overlapping = cube
        .clone()
        .merge(cuboid(DVec3::splat(0.5), DVec3::splat(1.5)));
    assert!(matches!(
        strict(&overlapping),
        Err(PolyhedralError::SelfIntersecting(..))
    ));
    let mut degenerate = cube.clone();
    degenerate.triangles.push([0, 0, 1]);
    assert!(matches!(
        strict(&degenerate),
        Err(PolyhedralError::DegenerateTriangles(1))
    ));
    // Without `strict` each of them is meshable, with the repair counted.
    for s in [&open, &shuffled, &overlapping, &degenerate] {
        assert!(!oracle(s).repairs().is_empty());
    }
}

/// The cube `[min, max]` without the two triangles of its face `z = max.z`.
fn open_box(min: DVec3, max: DVec3) -> Surface {
    let mut s = cuboid(min, max);
    let points = s.points.clone();
    s.triangles
        .retain(|t| !t.iter().all(|&v| points[v as usize].z == max.z));
    s
}

#[test]
fn an_open_surface_written_inwards_is_turned_outwards() {
    let inward = flipped(open_box(DVec3::ZERO, DVec3::ONE));
    let o = oracle(&inward);
    assert_eq!(o.repairs().flipped, inward.triangles.len());
    assert!((o.domain_volume() - 1.0).abs() < 1e-9);
    assert!(o.subdomain(DVec3::splat(0.5)) != OUTSIDE);
    // The same file with a closed hollow inside, all written the other way round: the outer
    // surface is turned, and the hollow with it, so it stays a hollow.
    let hollow = flipped(
        open_box(DVec3::ZERO, DVec3::splat(3.0))
            .merge(flipped(cuboid(DVec3::ONE, DVec3::splat(2.0)))),
    );
    let o = oracle(&hollow);
    assert!(
        (o.domain_volume() - 26.0).abs() < 0.26,
        "{}",
        o.domain_volume()
    );
    assert_eq!(o.subdomain(DVec3::splat(1.5)), OUTSIDE);
    assert!(o.subdomain(DVec3::splat(0.5)) != OUTSIDE);
}

#[test]
fn the_topology_to_reach_is_the_capped_surface_or_unknown() {
    let open = oracle(&open_box(DVec3::ZERO, DVec3::ONE));
    assert_eq!(
        open.winding_boundary_euler_characteristics(),
        Some(&[2][..])
    );
    let two_open =
        open_box(DVec3::ZERO, DVec3::ONE).merge(open_box(DVec3::splat(2.0), DVec3::splat(3.0)));
    assert_eq!(
        oracle(&two_open).winding_boundary_euler_characteristics(),
        Some(&[2, 2][..])
    );
    // Crossing triangles: the union's topology is only known by meshing it.
    let boxes = cuboid(DVec3::ZERO, DVec3::ONE).merge(cuboid(DVec3::splat(0.5), DVec3::splat(1.5)));
    assert_eq!(
        oracle(&boxes).winding_boundary_euler_characteristics(),
        None
    );
    // A surface that bounds a volume as given is its own boundary.
    let clean = oracle(&cuboid(DVec3::ZERO, DVec3::ONE));
    assert_eq!(clean.winding_boundary_euler_characteristics(), None);
}

#[test]
fn diagnosis_counts_what_meshing_repairs() {
    let cube = cuboid(DVec3::ZERO, DVec3::ONE);
    let surfaces = [
        shuffle(cube.clone(), 0, 4),
        open_box(DVec3::ZERO, DVec3::ONE),
        flipped(open_box(DVec3::ZERO, DVec3::ONE)),
        cube.clone()
            .merge(cuboid(DVec3::splat(0.5), DVec3::splat(1.5))),
    ];
    for s in &surfaces {
        let d = diagnose(&s.points, &s.triangles);
        assert!(!d.is_empty());
        assert_eq!(&d, oracle(s).repairs());
    }
}

/// A closed prism over a regular `n`-gon, each cap a fan of long thin triangles from one corner
/// (as CAD exporters write polygons).
fn fan_capped_prism(n: usize) -> Surface {
    let mut points = Vec::new();
    for z in [0.0, 1.0] {
        for i in 0..n {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            points.push(DVec3::new(a.cos(), a.sin(), z));
        }
    }
    let n32 = n as u32;
    let mut triangles = Vec::new();
    for i in 0..n32 {
        let j = (i + 1) % n32;
        triangles.push([i, j, n32 + j]);
        triangles.push([i, n32 + j, n32 + i]);
    }
    for i in 1..n32 - 1 {
        triangles.push([0, i + 1, i]);
        triangles.push([n32, n32 + i, n32 + i + 1]);
    }
    Surface { points, triangles }
}

#[test]
fn fans_of_coplanar_slivers_do_not_cross() {
    let prism = fan_capped_prism(400);
    let o = strict(&prism).expect("a closed prism bounds a volume");
    assert!(o.repairs().is_empty());
    let area = 0.5 * 400.0 * (std::f64::consts::TAU / 400.0).sin();
    assert!((o.domain_volume() - area).abs() < 1e-9 * area);
    assert!(diagnose(&prism.points, &prism.triangles).is_empty());
    // A corner of the top cap pushed below the bottom one: its fan crosses the bottom's.
    let mut folded = prism.clone();
    folded.points[400].z = -0.5;
    assert!(matches!(
        strict(&folded),
        Err(PolyhedralError::SelfIntersecting(..))
    ));
}

#[test]
fn a_surface_in_an_axis_plane_encloses_nothing() {
    let mut flat = open_box(DVec3::ZERO, DVec3::ONE);
    for p in &mut flat.points {
        p.z = 0.0;
    }
    let r = PolyhedralOracle::new(&flat.points, &flat.triangles, None);
    assert!(matches!(r, Err(PolyhedralError::NoVolume)));
}
