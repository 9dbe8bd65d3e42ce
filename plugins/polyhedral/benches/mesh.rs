//! The whole mesher over a polyhedral surface: the icosphere of CGAL's `sphere.off` (162
//! vertices, 320 triangles, radius 0.5), with the criteria of the side-by-side comparison
//! with CGAL Mesh_3 (facet angle 25°, facet size 0.05, facet distance 0.002, radius-edge 3,
//! cell size 0.05). Its planar faces make many nearly flat cells, the hard case for the
//! surface level. Run: `cargo bench -p delamesh-polyhedral --bench mesh`.

// `criterion_group!` defines a public function it gives no documentation.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use delamesh_core::mesh::SurfaceMesh;
use delamesh_core::optimize::OptimizeOptions;
use delamesh_core::refine::criteria::{MeshCriteria, Sizing};
use delamesh_core::refine::{MeshOptions, mesh_domain};
use delamesh_polyhedral::PolyhedralOracle;
use glam::DVec3;
use std::hint::black_box;

fn sphere_off(c: &mut Criterion) {
    let SurfaceMesh {
        positions: points,
        triangles,
        ..
    } = SurfaceMesh::icosphere(DVec3::ZERO, 0.5, 2);
    assert_eq!((points.len(), triangles.len()), (162, 320));
    let oracle = PolyhedralOracle::new(&points, &triangles, None).expect("a closed icosphere");
    let criteria = MeshCriteria {
        // No sharp features on a sphere: nothing to protect.
        edge_size: Sizing::Unbounded,
        ..MeshCriteria::uniform(0.05, 0.002)
    };
    let options = MeshOptions {
        optimize: OptimizeOptions::none(),
        ..MeshOptions::new(criteria)
    };
    let mut group = c.benchmark_group("mesh");
    group.sample_size(10);
    group.bench_function("icosphere 162 (CGAL sphere.off), CGAL criteria", |b| {
        b.iter(|| {
            mesh_domain(black_box(&oracle), &options, &mut |_| {}).map(|o| o.complex.tets.len())
        })
    });
    group.finish();
}

criterion_group!(benches, sphere_off);
criterion_main!(benches);
