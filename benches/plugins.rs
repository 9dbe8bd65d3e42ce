//! Cost of the C ABI: the same implicit oracle called statically (Rust trait object) and through
//! the plugin library loaded with libloading (`DynOracle`).
//!
//! Run: `cargo bench --bench plugins` (builds the example plugin in the release profile first).
//! The requirement is on `mesh_torus`: dynamic / static ≤ 1.10.

// `criterion_group!` defines a public function it gives no documentation.
#![allow(missing_docs)]

#[path = "../tests/plugins_support/mod.rs"]
mod common;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use delamesh::core::kernel::Point3;
use delamesh::core::oracle::{OUTSIDE, Oracle};
use delamesh::core::plugin::{PluginLibrary, PluginOracle};
use delamesh::core::refine::criteria::MeshCriteria;
use delamesh::core::refine::{MeshOptions, mesh_domain};
use delamesh_implicit::ImplicitOracle;
use std::hint::black_box;

const CONFIG: &str = "shape=torus major=1 minor=0.35";

/// Points on a regular lattice over the box, deterministic.
fn lattice(min: Point3, max: Point3, per_axis: usize) -> Vec<Point3> {
    let step = (max - min) / (per_axis - 1) as f64;
    (0..per_axis * per_axis * per_axis)
        .map(|i| {
            min + step
                * Point3::new(
                    (i % per_axis) as f64,
                    ((i / per_axis) % per_axis) as f64,
                    (i / per_axis / per_axis) as f64,
                )
        })
        .collect()
}

fn oracle_calls(c: &mut Criterion) {
    let library =
        PluginLibrary::open(&common::implicit_plugin()).expect("the example plugin loads");
    let dynamic = library.create(CONFIG).expect("valid config");
    let direct = ImplicitOracle::from_config(CONFIG).expect("valid config");
    let oracles: [(&str, &dyn Oracle); 2] = [("static", &direct), ("dynamic", &dynamic)];
    let bbox = direct.bounding_box();
    let points = lattice(bbox.min, bbox.max, 16);

    let mut group = c.benchmark_group("segment_hits");
    for (name, oracle) in oracles {
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            let mut hits = Vec::new();
            b.iter(|| {
                let mut count = 0;
                for pair in points.windows(2).step_by(7) {
                    hits.clear();
                    oracle.segment_hits(pair[0], -pair[1], &mut hits);
                    count += hits.len();
                }
                black_box(count)
            })
        });
    }
    group.finish();

    let mut group = c.benchmark_group("subdomain");
    for (name, oracle) in oracles {
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                points
                    .iter()
                    .filter(|&&p| oracle.subdomain(p) != OUTSIDE)
                    .count()
            })
        });
    }
    group.bench_function(BenchmarkId::from_parameter("dynamic-batch"), |b| {
        let mut labels = vec![OUTSIDE; points.len()];
        b.iter(|| {
            dynamic
                .try_subdomains(&points, &mut labels)
                .expect("no fault");
            labels.iter().filter(|&&l| l != OUTSIDE).count()
        })
    });
    group.finish();
    assert!(dynamic.fault().is_none(), "{:?}", dynamic.fault());
}

/// The figure that matters: a whole refinement run, where oracle calls are one cost among many.
fn meshing(c: &mut Criterion) {
    let library =
        PluginLibrary::open(&common::implicit_plugin()).expect("the example plugin loads");
    let dynamic = library.create(CONFIG).expect("valid config");
    let direct = ImplicitOracle::from_config(CONFIG).expect("valid config");
    let options = MeshOptions {
        criteria: MeshCriteria::default_for(&direct.bounding_box()),
        limits: Default::default(),
        keep_partial: false,
        validity: Default::default(),
        optimize: delamesh_core::optimize::OptimizeOptions::none(),
    };
    let mut group = c.benchmark_group("mesh_torus");
    group.sample_size(10);
    for (name, oracle) in [("static", &direct as &dyn Oracle), ("dynamic", &dynamic)] {
        group.bench_function(BenchmarkId::from_parameter(name), |b| {
            b.iter(|| {
                mesh_domain(oracle, &options, &mut |_| {})
                    .expect("the torus meshes")
                    .complex
                    .tets
                    .len()
            })
        });
    }
    group.finish();
    assert!(dynamic.fault().is_none(), "{:?}", dynamic.fault());
}

criterion_group!(benches, oracle_calls, meshing);
criterion_main!(benches);
