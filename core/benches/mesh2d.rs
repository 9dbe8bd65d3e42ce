//! Benchmarks of the planar code: `Delaunay2` on uniform random points, the quality mesher on the
//! PSLGs compared with Triangle (see `triangle_compare.py` next to this file for the side-by-side
//! run), and Pébay's Algorithm 3.2.

// `criterion_group!` defines a public function it gives no documentation.
#![allow(missing_docs)]

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use delamesh_core::mesh2d::mesher::{MeshOptions, mesh};
use delamesh_core::mesh2d::{ConformOptions, Point2, Pslg, conform};
use delamesh_core::triangulation::{Delaunay2, Triangulation};
use rand::{Rng, SeedableRng, rngs::StdRng};
use std::f64::consts::PI;

fn uniform(n: usize) -> Vec<Point2> {
    let mut rng = StdRng::seed_from_u64(42);
    (0..n)
        .map(|_| Point2::new(rng.random(), rng.random()))
        .collect()
}

fn polygon(points: Vec<Point2>, holes: Vec<Point2>) -> Pslg {
    let n = points.len() as u32;
    Pslg {
        points,
        segments: (0..n).map(|k| [k, (k + 1) % n]).collect(),
        segment_markers: vec![0; n as usize],
        holes,
        regions: Vec::new(),
    }
}

fn square_with_hole() -> Pslg {
    let mut p = polygon(
        vec![
            Point2::new(0.0, 0.0),
            Point2::new(10.0, 0.0),
            Point2::new(10.0, 10.0),
            Point2::new(0.0, 10.0),
        ],
        vec![Point2::new(5.0, 5.0)],
    );
    p.points.extend([
        Point2::new(4.0, 4.0),
        Point2::new(6.0, 4.0),
        Point2::new(6.0, 6.0),
        Point2::new(4.0, 6.0),
    ]);
    p.segments.extend([[4, 5], [5, 6], [6, 7], [7, 4]]);
    p.segment_markers.extend([0; 4]);
    p
}

/// A star with 10 spikes of 10° tip angle.
fn star() -> Pslg {
    let (n, outer) = (10, 10.0);
    let half = PI / n as f64;
    let tip = 10f64.to_radians() / 2.0;
    let inner = outer * tip.sin() / (tip + half).sin();
    let pts = (0..2 * n)
        .map(|k| {
            let r = if k % 2 == 0 { outer } else { inner };
            Point2::from_angle(half * k as f64) * r
        })
        .collect();
    polygon(pts, Vec::new())
}

/// A star-shaped polygon with equally spaced angles and radii 1 ± h/2 (h the spacing), so that
/// its corners range over about 90° to 270°.
fn random_polygon(n: usize) -> Pslg {
    let mut rng = StdRng::seed_from_u64(42);
    let h = 2.0 * PI / n as f64;
    let pts = (0..n)
        .map(|k| Point2::from_angle(h * k as f64) * (1.0 + rng.random_range(-h / 2.0..h / 2.0)))
        .collect();
    polygon(pts, Vec::new())
}

fn delaunay2(c: &mut Criterion) {
    let mut g = c.benchmark_group("delaunay2");
    g.sample_size(10);
    for n in [10_000, 100_000, 1_000_000] {
        let pts = uniform(n);
        g.bench_with_input(BenchmarkId::from_parameter(n), &pts, |b, pts| {
            b.iter(|| Delaunay2::from_points(pts).map(|(t, _)| t.num_finite_cells()))
        });
    }
    g.finish();
}

fn mesher(c: &mut Criterion) {
    let mut g = c.benchmark_group("mesh2d_q30");
    g.sample_size(10);
    let cases = [
        ("square_hole_a0.001", square_with_hole(), Some(0.001)),
        ("star_10deg", star(), None),
        ("star_10deg_a0.01", star(), Some(0.01)),
        ("random_polygon_1e4", random_polygon(10_000), None),
        ("random_polygon_1e5", random_polygon(100_000), None),
    ];
    for (name, pslg, max_area) in cases {
        let opts = MeshOptions {
            min_angle_deg: 30.0,
            max_area,
            ..MeshOptions::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| mesh(&pslg, &opts).map(|m| m.triangles.len()))
        });
    }
    g.finish();
}

fn pebay(c: &mut Criterion) {
    let mut g = c.benchmark_group("conform2d_alg32");
    g.sample_size(10);
    let pslg = random_polygon(10_000);
    g.bench_function("random_polygon_1e4", |b| {
        b.iter(|| conform(&pslg, &ConformOptions::default()).map(|o| o.points.len()))
    });
    g.finish();
}

criterion_group!(benches, delaunay2, mesher, pebay);
criterion_main!(benches);
