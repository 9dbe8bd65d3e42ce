//! The mesher on an analytic sphere (no plugin, no file): refinement throughput of the engine,
//! the surface level and the cell level.

// `criterion_group!` defines a public function it gives no documentation.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use delamesh_core::optimize::OptimizeOptions;
use delamesh_core::oracle::UnitBall;
use delamesh_core::refine::criteria::MeshCriteria;
use delamesh_core::refine::{MeshOptions, mesh_domain};
use std::hint::black_box;

fn sphere(c: &mut Criterion) {
    let options = MeshOptions {
        optimize: OptimizeOptions::none(),
        ..MeshOptions::new(MeshCriteria::uniform(0.1, 0.005))
    };
    let mut group = c.benchmark_group("refine");
    group.sample_size(10);
    group.bench_function("analytic unit ball, size 0.1", |b| {
        b.iter(|| {
            mesh_domain(black_box(&UnitBall), &options, &mut |_| {}).map(|o| o.complex.tets.len())
        })
    });
    group.finish();
}

criterion_group!(benches, sphere);
criterion_main!(benches);
