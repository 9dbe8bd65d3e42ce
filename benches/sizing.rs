//! The cost of a sizing field: the same mesh of the unit ball (features off) with a constant
//! size, and with the same size given as an expression, a background mesh and a size image
//! (each field constant, so every run inserts the same vertices and the difference is the
//! field's evaluation). Run: `cargo bench --bench sizing`.

// `criterion_group!` defines a public function it gives no documentation.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use delamesh::core::refine::sizing::{BackgroundMesh, SizeGrid};
use delamesh::{FeatureSettings, MeshSettings, Mesher, Point3, SizeSource, SurfaceMesh};
use glam::{DAffine3, DMat3};
use std::sync::Arc;

const SIZE: f64 = 0.06;

/// Kuhn-subdivided cubes (`n`³ over [-l, l]³) with `SIZE` at every node.
fn background(n: usize, l: f64) -> BackgroundMesh {
    let node = |i: usize, j: usize, k: usize| (i + (n + 1) * (j + (n + 1) * k)) as u32;
    let t = |a: usize| -l + 2.0 * l * a as f64 / n as f64;
    let mut points = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                points.push(Point3::new(t(i), t(j), t(k)));
            }
        }
    }
    let mut tets = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = |b: usize| node(i + (b & 1), j + ((b >> 1) & 1), k + (b >> 2));
                for [p, q] in [[1, 3], [1, 5], [2, 3], [2, 6], [4, 5], [4, 6]] {
                    tets.push([c(0), c(p), c(q), c(7)]);
                }
            }
        }
    }
    let values = vec![SIZE; points.len()];
    BackgroundMesh::new(points, tets, values).expect("a valid background mesh")
}

fn image(n: usize, l: f64) -> SizeGrid {
    let step = 2.0 * l / (n - 1) as f64;
    let map = DAffine3::from_mat3_translation(
        DMat3::from_diagonal(Point3::splat(step)),
        Point3::splat(-l),
    );
    SizeGrid::new([n; 3], map, vec![SIZE; n * n * n]).expect("a valid grid")
}

fn settings(field: Option<SizeSource>) -> MeshSettings {
    let base = MeshSettings {
        features: FeatureSettings {
            enabled: false,
            ..FeatureSettings::default()
        },
        ..MeshSettings::default()
    };
    match field {
        None => MeshSettings {
            facet_size: Some(SIZE),
            cell_size: Some(SIZE),
            ..base
        },
        Some(f) => MeshSettings {
            sizing: delamesh::SizingSettings {
                field: Some(f),
                ..Default::default()
            },
            ..base
        },
    }
}

fn sizing(c: &mut Criterion) {
    let ball = SurfaceMesh::icosphere(Point3::ZERO, 1.0, 3);
    let cases = [
        ("constant size", None),
        (
            "expression",
            Some(SizeSource::Expression(format!("{SIZE} + 0 * x"))),
        ),
        (
            "background mesh 20^3 x 6 tets",
            Some(SizeSource::Field(Arc::new(background(20, 1.2)))),
        ),
        (
            "size image 32^3",
            Some(SizeSource::Field(Arc::new(image(32, 1.2)))),
        ),
    ];
    let mut group = c.benchmark_group("sizing field, unit ball");
    group.sample_size(10);
    for (name, field) in cases {
        let s = settings(field);
        group.bench_function(name, |b| {
            b.iter(|| {
                Mesher::new(s.clone())
                    .mesh_surface("ball", ball.clone())
                    .map(|m| m.complex.points.len())
            })
        });
    }
    group.finish();
}

criterion_group!(benches, sizing);
criterion_main!(benches);
