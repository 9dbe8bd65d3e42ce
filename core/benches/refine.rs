//! The mesher on an analytic sphere (no plugin, no file): refinement throughput of the engine,
//! the surface level and the cell level.

// `criterion_group!` defines a public function it gives no documentation.
#![allow(missing_docs)]

use criterion::{Criterion, criterion_group, criterion_main};
use delamesh_core::kernel::Point3;
use delamesh_core::oracle::{
    Aabb, OUTSIDE, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use delamesh_core::refine::criteria::{CellCriteria, FacetCriteria, MeshCriteria, Sizing};
use delamesh_core::refine::{Limits, MeshOptions, mesh_domain};
use std::hint::black_box;

/// The unit ball, answered exactly by solving quadratics.
struct Ball;

impl Ball {
    /// Parameters where `o + t d` crosses the unit sphere.
    fn crossings(o: Point3, d: Point3) -> impl Iterator<Item = f64> {
        let (a, b, c) = (d.length_squared(), 2.0 * o.dot(d), o.length_squared() - 1.0);
        let disc = b * b - 4.0 * a * c;
        let roots = if a > 0.0 && disc >= 0.0 {
            let s = disc.sqrt();
            [(-b - s) / (2.0 * a), (-b + s) / (2.0 * a)]
        } else {
            [f64::NAN; 2]
        };
        roots.into_iter().filter(|t| t.is_finite())
    }
}

impl Oracle for Ball {
    fn bounding_box(&self) -> Aabb {
        Aabb {
            min: Point3::splat(-1.0),
            max: Point3::splat(1.0),
        }
    }
    fn subdomain(&self, p: Point3) -> SubdomainId {
        if p.length_squared() < 1.0 {
            SubdomainId(1)
        } else {
            OUTSIDE
        }
    }
    fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
        let d = b - a;
        out.extend(
            Self::crossings(a, d)
                .filter(|t| (0.0..=1.0).contains(t))
                .map(|t| SurfaceHit {
                    point: a + t * d,
                    t,
                    patch: PatchId(1),
                }),
        );
    }
    fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
        out.extend(
            Self::crossings(origin, dir)
                .filter(|&t| t >= 0.0)
                .map(|t| SurfaceHit {
                    point: origin + t * dir,
                    t,
                    patch: PatchId(1),
                }),
        );
    }
    fn initial_points(&self) -> Vec<SurfacePoint> {
        let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
        (0..20)
            .map(|i| {
                let z = 1.0 - 2.0 * (i as f64 + 0.5) / 20.0;
                let r = (1.0 - z * z).sqrt();
                let phi = golden * i as f64;
                SurfacePoint {
                    point: Point3::new(r * phi.cos(), r * phi.sin(), z),
                    patch: PatchId(1),
                }
            })
            .collect()
    }
}

fn sphere(c: &mut Criterion) {
    let options = MeshOptions {
        criteria: MeshCriteria {
            edge_size: Sizing::Constant(0.1),
            edge_min_size: 0.0,
            facet: FacetCriteria {
                angle_deg: 25.0,
                size: Sizing::Constant(0.1),
                distance: Sizing::Constant(0.005),
            },
            cell: CellCriteria {
                radius_edge_ratio: 3.0,
                size: Sizing::Constant(0.1),
            },
        },
        limits: Limits::default(),
        keep_partial: false,
        validity: Default::default(),
        optimize: delamesh_core::optimize::OptimizeOptions::none(),
    };
    let mut group = c.benchmark_group("refine");
    group.sample_size(10);
    group.bench_function("analytic unit ball, size 0.1", |b| {
        b.iter(|| {
            mesh_domain(black_box(&Ball), &options, &mut |_| {}).map(|o| o.complex.tets.len())
        })
    });
    group.finish();
}

criterion_group!(benches, sphere);
criterion_main!(benches);
