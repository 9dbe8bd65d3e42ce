mod common;
use delamesh::core::oracle::Oracle;
use delamesh::core::refine::criteria::MeshCriteria;
use delamesh::core::refine::{Limits, MeshOptions, mesh_domain};
use delamesh::polyhedral::PolyhedralOracle;
use glam::DVec3;

#[test]
fn smoke() {
    let s = common::sphere(DVec3::ZERO, 1.0, 3);
    let oracle = PolyhedralOracle::new(&s.points, &s.triangles, None).unwrap();
    let criteria = MeshCriteria::default_for(&oracle.bounding_box());
    let opts = MeshOptions { criteria, limits: Limits::default(), keep_partial: false };
    let t = std::time::Instant::now();
    let out = mesh_domain(&oracle, &opts, &mut |_| {}).unwrap();
    eprintln!("{:?} {} verts {} tets {} facets {:?}", t.elapsed(), out.complex.num_vertices(), out.complex.tets.len(), out.complex.facets.len(), out.stats);
    let q = delamesh::core::quality::tet_quality((0..out.complex.tets.len()).map(|t| out.complex.tet_points(t)));
    eprintln!("{q:?}");
    let topo = delamesh::core::quality::surface_topology(&out.complex.facets);
    eprintln!("{topo:?}");
}
