//! Test-only plugin: a unit sphere that breaks the plugin contract in the way its configuration
//! names, so the host's fault containment can be tested. Configuration: `fault=KIND` with KIND one
//! of `none`, `fail-create`, `panic-create`, `panic-subdomain`, `panic-hits`, `nan-hits`,
//! `outside-hits`, `outside-initial-points`, and `panic-after-N` (subdomain panics from its N-th
//! point on: a fault that passes the host's self-check and strikes in the middle of meshing).

use delamesh_core::kernel::Point3;
use delamesh_core::oracle::{
    Aabb, OUTSIDE, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use delamesh_core::plugin::PluginOracle;
use std::sync::atomic::{AtomicUsize, Ordering};

#[derive(Clone, Copy, PartialEq, Eq)]
enum Fault {
    None,
    PanicSubdomain,
    PanicHits,
    NanHits,
    OutsideHits,
    OutsideInitialPoints,
    PanicAfter(usize),
}

struct FaultySphere {
    fault: Fault,
    located: AtomicUsize,
}

impl Oracle for FaultySphere {
    fn bounding_box(&self) -> Aabb {
        Aabb {
            min: Point3::splat(-1.0),
            max: Point3::splat(1.0),
        }
    }

    fn subdomain(&self, p: Point3) -> SubdomainId {
        let located = self.located.fetch_add(1, Ordering::Relaxed);
        match self.fault {
            Fault::PanicSubdomain => panic!("deliberate panic in subdomain"),
            Fault::PanicAfter(n) if located >= n => {
                panic!("deliberate panic in subdomain after {n} points")
            }
            _ => {}
        }
        if p.length() < 1.0 {
            SubdomainId(1)
        } else {
            OUTSIDE
        }
    }

    fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
        // |a + t d|² = 1: t² |d|² + 2 t a·d + |a|² − 1 = 0.
        let d = b - a;
        let (qa, qb, qc) = (d.length_squared(), 2.0 * a.dot(d), a.length_squared() - 1.0);
        let discriminant = qb * qb - 4.0 * qa * qc;
        if qa == 0.0 || discriminant <= 0.0 {
            return;
        }
        for t in [
            (-qb - discriminant.sqrt()) / (2.0 * qa),
            (-qb + discriminant.sqrt()) / (2.0 * qa),
        ] {
            if (0.0..=1.0).contains(&t) {
                let point = match self.fault {
                    Fault::PanicHits => panic!("deliberate panic in segment_hits"),
                    Fault::NanHits => Point3::NAN,
                    Fault::OutsideHits => a + t * d + Point3::splat(10.0),
                    _ => a + t * d,
                };
                out.push(SurfaceHit {
                    point,
                    t,
                    patch: PatchId(1),
                });
            }
        }
    }

    fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
        // The sphere is within distance 2 of any box point: a long enough segment covers the ray.
        let reach = 4.0 / dir.length().max(f64::MIN_POSITIVE);
        let start = out.len();
        self.segment_hits(origin, origin + reach * dir, out);
        for hit in &mut out[start..] {
            hit.t *= reach;
        }
    }

    fn initial_points(&self) -> Vec<SurfacePoint> {
        let offset = if self.fault == Fault::OutsideInitialPoints {
            5.0
        } else {
            1.0
        };
        [Point3::X, Point3::Y, Point3::Z, -Point3::X]
            .iter()
            .map(|&p| SurfacePoint {
                point: p * offset,
                patch: PatchId(1),
            })
            .collect()
    }
}

impl PluginOracle for FaultySphere {
    fn from_config(config: &str) -> Result<Self, String> {
        let fault = match config.trim().strip_prefix("fault=").unwrap_or("none") {
            "none" => Fault::None,
            "fail-create" => return Err("deliberate create failure".into()),
            "panic-create" => panic!("deliberate panic in create"),
            "panic-subdomain" => Fault::PanicSubdomain,
            "panic-hits" => Fault::PanicHits,
            "nan-hits" => Fault::NanHits,
            "outside-hits" => Fault::OutsideHits,
            "outside-initial-points" => Fault::OutsideInitialPoints,
            other => match other.strip_prefix("panic-after-").map(str::parse) {
                Some(Ok(n)) => Fault::PanicAfter(n),
                _ => return Err(format!("unknown fault `{other}`")),
            },
        };
        Ok(FaultySphere {
            fault,
            located: AtomicUsize::new(0),
        })
    }
}

delamesh_core::export_oracle_plugin!(FaultySphere, name = "faulty", kind = "test");
