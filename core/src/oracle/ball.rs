//! The unit ball, answered exactly by solving quadratics: the analytic domain (no plugin, no
//! file) that tests and benches across the workspace share.

use super::{
    Aabb, CurveId, FeatureCurve, OUTSIDE, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use crate::kernel::Point3;

/// The open unit ball at the origin: subdomain 1 inside, its sphere patch 1.
#[derive(Clone, Copy, Debug, Default)]
pub struct UnitBall;

/// How many initial points [`UnitBall`] spreads on its sphere.
const INITIAL_POINTS: usize = 20;

impl UnitBall {
    /// Parameters where `o + t d` crosses the unit sphere.
    fn crossings(o: Point3, d: Point3) -> impl Iterator<Item = f64> {
        let (a, b, c) = (d.dot(d), 2.0 * o.dot(d), o.dot(o) - 1.0);
        let disc = b * b - 4.0 * a * c;
        let roots = if a == 0.0 || disc < 0.0 {
            [f64::NAN; 2]
        } else {
            let s = disc.sqrt();
            [(-b - s) / (2.0 * a), (-b + s) / (2.0 * a)]
        };
        roots.into_iter().filter(|t| t.is_finite())
    }

    /// The crossings of `o + t d` with `t` in `range`, in increasing `t`.
    fn hits(o: Point3, d: Point3, range: impl Fn(f64) -> bool, out: &mut Vec<SurfaceHit>) {
        out.extend(
            Self::crossings(o, d)
                .filter(|&t| range(t))
                .map(|t| SurfaceHit {
                    point: o + d * t,
                    t,
                    patch: PatchId(1),
                }),
        );
    }
}

impl Oracle for UnitBall {
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
        Self::hits(a, b - a, |t| (0.0..=1.0).contains(&t), out);
    }

    fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
        Self::hits(origin, dir, |t| t >= 0.0, out);
    }

    /// A Fibonacci spiral.
    fn initial_points(&self) -> Vec<SurfacePoint> {
        let n = INITIAL_POINTS as f64;
        (0..INITIAL_POINTS)
            .map(|i| {
                let z = 1.0 - (2.0 * i as f64 + 1.0) / n;
                let phi = i as f64 * 2.399_963_229_728_653;
                let r = (1.0 - z * z).sqrt();
                SurfacePoint {
                    point: Point3::new(r * phi.cos(), r * phi.sin(), z),
                    patch: PatchId(1),
                }
            })
            .collect()
    }
}

/// [`UnitBall`] with its equator as a feature curve (id 1, a polyline of 64 points), which it
/// projects onto exactly: the analytic domain of the
/// protected mesher's tests.
#[derive(Clone, Copy, Debug, Default)]
pub struct UnitBallWithEquator;

/// Points of the polyline [`UnitBallWithEquator`] gives for its equator.
const EQUATOR_POINTS: usize = 64;

impl Oracle for UnitBallWithEquator {
    fn bounding_box(&self) -> Aabb {
        UnitBall.bounding_box()
    }

    fn subdomain(&self, p: Point3) -> SubdomainId {
        UnitBall.subdomain(p)
    }

    fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
        UnitBall.segment_hits(a, b, out);
    }

    fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
        UnitBall.ray_hits(origin, dir, out);
    }

    fn initial_points(&self) -> Vec<SurfacePoint> {
        UnitBall.initial_points()
    }

    fn feature_curves(&self) -> Vec<FeatureCurve> {
        let points = (0..EQUATOR_POINTS)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / EQUATOR_POINTS as f64;
                Point3::new(t.cos(), t.sin(), 0.0)
            })
            .collect();
        vec![FeatureCurve {
            id: CurveId(1),
            points,
            closed: true,
        }]
    }

    fn project_to_curve(&self, _: CurveId, p: Point3) -> Point3 {
        let q = Point3::new(p.x, p.y, 0.0);
        if q.length_squared() > 0.0 {
            q.normalize()
        } else {
            Point3::X
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_diameter_crosses_the_sphere_twice_and_a_ray_from_inside_once() {
        let ball = UnitBall;
        let mut hits = Vec::new();
        ball.segment_hits(
            Point3::new(-2.0, 0.0, 0.0),
            Point3::new(2.0, 0.0, 0.0),
            &mut hits,
        );
        let xs: Vec<f64> = hits.iter().map(|h| h.point.x).collect();
        assert_eq!(xs, [-1.0, 1.0]);
        hits.clear();
        ball.ray_hits(Point3::ZERO, Point3::Z, &mut hits);
        assert_eq!(hits.len(), 1);
        assert_eq!(hits[0].point, Point3::Z);
        for p in ball.initial_points() {
            assert!((p.point.length() - 1.0).abs() < 1e-12);
        }
    }
}
