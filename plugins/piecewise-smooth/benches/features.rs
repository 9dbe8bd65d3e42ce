//! Cost of feature extraction and of building the piecewise-smooth oracle.
//!
//! Run: `cargo bench -p delamesh-piecewise-smooth --bench features`. Set
//! `DELAMESH_BENCH_SURFACE=path/to/surface.off` (e.g. CGAL's `fandisk.off`) to add a real CAD part.

// `criterion_group!` defines a public function it gives no documentation.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use delamesh_core::mesh::SurfaceMesh;
use delamesh_piecewise_smooth::models::{cylinder, voxels};
use delamesh_piecewise_smooth::{FeatureOptions, Features, PiecewiseSmoothOracle};
use std::hint::black_box;

fn surfaces() -> Vec<(String, SurfaceMesh)> {
    // A staircase of voxels: many sharp edges and corners; a fine cylinder: long closed curves.
    let stairs: Vec<[i32; 3]> = (0..40)
        .flat_map(|i| (0..=i).map(move |j| [i, j, 0]))
        .collect();
    let mut out = vec![
        ("stairs".to_string(), voxels(&stairs, 1.0)),
        ("cylinder_500".to_string(), cylinder(1.0, 1.0, 500)),
    ];
    if let Some(path) = std::env::var_os("DELAMESH_BENCH_SURFACE") {
        let path = std::path::PathBuf::from(path);
        match delamesh_formats::read_surface(&path, None) {
            Ok(read) => out.push((path.display().to_string(), read.mesh)),
            Err(e) => eprintln!("skipping {}: {e}", path.display()),
        }
    }
    out
}

fn bench(c: &mut Criterion) {
    let options = FeatureOptions::default();
    for (name, surface) in surfaces() {
        c.bench_function(&format!("extract/{name}"), |b| {
            b.iter(|| Features::extract(black_box(&surface), &options, &[]))
        });
        c.bench_function(&format!("oracle/{name}"), |b| {
            b.iter(|| PiecewiseSmoothOracle::from_surface(black_box(&surface), &options, &[]))
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench
}
criterion_main!(benches);
