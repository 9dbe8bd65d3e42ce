//! Bulk construction of `Delaunay3`: uniform random points (seed 42) and a regular grid; of
//! `Regular3`: uniform random points with random weights up to half the squared spacing.
//! Sample counts are kept at criterion's minimum so the whole bench runs in a few minutes.
//! The CGAL comparison (same N, construction time only) is `examples/dt3_points.rs`.

// `criterion_group!` defines a public function it gives no documentation.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use delamesh_core::kernel::Point3;
use delamesh_core::triangulation::{Delaunay3, Regular3, Triangulation};
use rand::rngs::StdRng;
use rand::{Rng, SeedableRng};
use std::hint::black_box;
use std::time::Duration;

fn uniform(n: usize) -> Vec<Point3> {
    let mut rng = StdRng::seed_from_u64(42);
    (0..n)
        .map(|_| Point3::new(rng.random(), rng.random(), rng.random()))
        .collect()
}

fn grid(side: usize) -> Vec<Point3> {
    let mut pts = Vec::with_capacity(side * side * side);
    for x in 0..side {
        for y in 0..side {
            for z in 0..side {
                pts.push(Point3::new(x as f64, y as f64, z as f64));
            }
        }
    }
    pts
}

fn build(points: &[Point3]) -> usize {
    let dt = Delaunay3::from_points(points).expect("finite benchmark points");
    dt.num_finite_cells()
}

fn bench_uniform(c: &mut Criterion) {
    let mut group = c.benchmark_group("delaunay3_uniform");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500));
    for n in [10_000usize, 100_000, 1_000_000] {
        let points = uniform(n);
        group.measurement_time(Duration::from_secs(if n >= 1_000_000 { 40 } else { 5 }));
        group.bench_with_input(BenchmarkId::from_parameter(n), &points, |b, pts| {
            b.iter(|| black_box(build(pts)))
        });
    }
    group.finish();
}

fn bench_grid(c: &mut Criterion) {
    let mut group = c.benchmark_group("delaunay3_grid");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(40));
    let points = grid(100);
    group.bench_function("100^3", |b| b.iter(|| black_box(build(&points))));
    group.finish();
}

fn bench_regular(c: &mut Criterion) {
    let n = 100_000;
    let spacing = (n as f64).powf(-1.0 / 3.0);
    let mut rng = StdRng::seed_from_u64(43);
    let points: Vec<(Point3, f64)> = uniform(n)
        .into_iter()
        .map(|p| (p, rng.random::<f64>() * 0.5 * spacing * spacing))
        .collect();
    let mut group = c.benchmark_group("regular3");
    group
        .sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(10));
    group.bench_function("1e5 weighted points", |b| {
        b.iter(|| {
            let (rt, _) = Regular3::from_weighted_points(&points).expect("valid benchmark points");
            black_box(rt.num_finite_cells())
        })
    });
    group.finish();
}

criterion_group!(benches, bench_uniform, bench_grid, bench_regular);
criterion_main!(benches);
