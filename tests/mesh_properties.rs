//! Properties of the meshes of generated surfaces (thesis ch. 3: restricted Delaunay facets,
//! restricted tetrahedra, and the approximation guarantees).

mod common;

use common::{criteria, cuboid, mesh, sphere, torus};
use delamesh::core::complex::{MeshComplex, VertexDimension, signed_volume};
use delamesh::core::oracle::{OUTSIDE, Oracle};
use delamesh::core::quality::{self, radius_edge_ratio, surface_topology, tet_circumcenter};
use delamesh::polyhedral::{PolyhedralOracle, TriangleTree};
use glam::DVec3;

/// Every tet is positively oriented (exact sign), has its circumcentre in its own subdomain, and
/// meets the radius-edge bound.
fn assert_restricted_tets(oracle: &PolyhedralOracle, c: &MeshComplex, ratio: f64) {
    assert!(!c.tets.is_empty());
    for t in 0..c.tets.len() {
        let p = c.tet_points(t);
        assert!(
            signed_volume(&p) > 0.0,
            "tet {t} is not positively oriented"
        );
        let centre = tet_circumcenter(&p).expect("non-flat tet");
        assert_eq!(
            oracle.subdomain(centre),
            c.tet_subdomain[t],
            "tet {t}: circumcentre outside its subdomain"
        );
        assert!(
            radius_edge_ratio(&p) <= ratio * (1.0 + 1e-9),
            "tet {t} has radius-edge {}",
            radius_edge_ratio(&p)
        );
    }
}

/// Every boundary facet is restricted (has a surface ball) and has its three vertices on the surface.
fn assert_restricted_facets(c: &MeshComplex) {
    for (f, tri) in c.facets.iter().enumerate() {
        assert_ne!(
            c.facet_patch[f].0, 0,
            "boundary facet {f} is not a restricted facet"
        );
        for &v in tri {
            assert_eq!(
                c.vertex_dimension[v as usize],
                VertexDimension::Surface,
                "facet {f} has a volume vertex"
            );
        }
    }
}

/// Largest sampled distance from the mesh boundary to the input and back.
fn hausdorff(oracle: &PolyhedralOracle, c: &MeshComplex, spacing: f64) -> f64 {
    let boundary: Vec<[DVec3; 3]> = (0..c.facets.len()).map(|f| c.facet_points(f)).collect();
    let there = quality::one_sided_distance(
        &quality::sample_triangles(boundary.iter().copied(), spacing),
        |p| oracle.distance_to_surface(p),
    );
    let tree = TriangleTree::new(&boundary);
    let back = quality::one_sided_distance(
        &quality::sample_triangles(oracle.triangles().iter().copied(), spacing),
        |p| tree.distance(p, &boundary),
    );
    there.max(back)
}

fn mesh_volume(c: &MeshComplex) -> f64 {
    (0..c.tets.len())
        .map(|t| quality::tet_volume(&c.tet_points(t)))
        .sum()
}

#[test]
fn sphere_mesh_is_a_restricted_delaunay_mesh() {
    let s = sphere(DVec3::new(0.1, -0.2, 0.3), 1.0, 4);
    let (distance, ratio) = (0.01, 2.5);
    let (oracle, c) = mesh(&s, criteria(25.0, 0.25, distance, ratio, 0.3));
    assert_restricted_tets(&oracle, &c, ratio);
    assert_restricted_facets(&c);
    let topology = surface_topology(&c.facets);
    assert!(topology.is_closed_manifold(), "{topology:?}");
    assert_eq!(topology.euler_characteristic, 2);
    assert_eq!(topology.components, 1);
    // The boundary stays within a few facet distances of the input surface...
    let h = hausdorff(&oracle, &c, 0.02);
    assert!(h <= 3.0 * distance, "Hausdorff distance {h}");
    // ...so the volumes differ by at most the area times that distance.
    let area = 4.0 * std::f64::consts::PI;
    let dv = (mesh_volume(&c) - oracle.domain_volume()).abs();
    assert!(dv <= area * 3.0 * distance, "volume differs by {dv}");
    // Boundary facets are oriented outwards: they enclose the mesh volume.
    let enclosed = quality::enclosed_volume(&c.points, &c.facets);
    assert!((enclosed - mesh_volume(&c)).abs() < 1e-9 * mesh_volume(&c).abs().max(1.0));
}

#[test]
fn torus_boundary_has_genus_one() {
    let s = torus(1.0, 0.4, 48, 24);
    let (oracle, c) = mesh(&s, criteria(25.0, 0.15, 0.01, 3.0, 0.2));
    assert_restricted_tets(&oracle, &c, 3.0);
    assert_restricted_facets(&c);
    let topology = surface_topology(&c.facets);
    assert!(topology.is_closed_manifold(), "{topology:?}");
    assert_eq!(topology.euler_characteristic, 0);
}

#[test]
fn nested_spheres_give_two_subdomains_and_an_interface() {
    let s = sphere(DVec3::ZERO, 1.0, 3).merge(sphere(DVec3::ZERO, 0.5, 3));
    let (oracle, c) = mesh(&s, criteria(25.0, 0.2, 0.01, 3.0, 0.3));
    assert_restricted_tets(&oracle, &c, 3.0);
    assert_restricted_facets(&c);
    let mut labels = c.tet_subdomain.clone();
    labels.sort_unstable();
    labels.dedup();
    assert_eq!(labels.len(), 2);
    assert!(!labels.contains(&OUTSIDE));
    // The interface separates the two subdomains and is itself a closed sphere.
    let interface: Vec<[u32; 3]> = (0..c.facets.len())
        .filter(|&f| c.facet_subdomains[f][1] != OUTSIDE)
        .map(|f| c.facets[f])
        .collect();
    let outer: Vec<[u32; 3]> = (0..c.facets.len())
        .filter(|&f| c.facet_subdomains[f][1] == OUTSIDE)
        .map(|f| c.facets[f])
        .collect();
    for part in [&interface, &outer] {
        let t = surface_topology(part);
        assert!(
            t.is_closed_manifold() && t.euler_characteristic == 2,
            "{t:?}"
        );
    }
    let radius = |tris: &[[u32; 3]]| {
        let n = tris.len() as f64 * 3.0;
        tris.iter()
            .flatten()
            .map(|&v| c.points[v as usize].length())
            .sum::<f64>()
            / n
    };
    assert!((radius(&interface) - 0.5).abs() < 0.02 && (radius(&outer) - 1.0).abs() < 0.02);
}

#[test]
fn cube_without_features_terminates_and_approximates_its_edges() {
    let s = cuboid(DVec3::ZERO, DVec3::ONE);
    let (oracle, c) = mesh(&s, criteria(25.0, 0.1, 0.01, 3.0, 0.15));
    assert_restricted_tets(&oracle, &c, 3.0);
    let topology = surface_topology(&c.facets);
    assert!(
        topology.is_closed_manifold() && topology.euler_characteristic == 2,
        "{topology:?}"
    );
    // Edges and corners are rounded, by at most a few facet sizes.
    assert!(hausdorff(&oracle, &c, 0.02) < 0.1);
    assert!((mesh_volume(&c) - 1.0).abs() < 0.1);
}

#[test]
fn thin_plate_terminates() {
    let s = cuboid(DVec3::ZERO, DVec3::new(1.0, 1.0, 0.04));
    let (oracle, c) = mesh(&s, criteria(25.0, 0.1, 0.005, 3.0, 0.1));
    assert_restricted_tets(&oracle, &c, 3.0);
    assert!(mesh_volume(&c) > 0.0);
}

#[test]
fn meshing_is_deterministic() {
    let s = torus(1.0, 0.4, 32, 16);
    let run = || mesh(&s, criteria(25.0, 0.2, 0.02, 3.0, 0.3)).1;
    assert_eq!(run(), run());
}

/// A raised cancel flag stops the pipeline at the engine's next guard check: raised from the
/// progress callback (as the Python binding does on Ctrl-C), refinement ends before the next call.
#[test]
fn a_raised_cancel_flag_stops_the_pipeline() {
    use delamesh::{Cancel, Error, MeshSettings, Mesher, RefineError, SurfaceMesh};
    let cancel = Cancel::new();
    let flag = cancel.clone();
    let settings = MeshSettings::builder()
        .facet_size(0.02)
        .cell_size(0.02)
        .build()
        .expect("valid settings");
    let mut calls = 0;
    let result = Mesher::new(settings)
        .cancel_on(cancel)
        .on_progress(|_| {
            calls += 1;
            flag.cancel();
        })
        .mesh_surface("sphere", SurfaceMesh::icosphere(DVec3::ZERO, 1.0, 3));
    assert!(
        matches!(
            result,
            Err(Error::Stopped {
                source: RefineError::Cancelled,
                ..
            })
        ),
        "a cancelled run is an error, not a mesh"
    );
    assert_eq!(calls, 1, "checks come at least as often as progress calls");
}
