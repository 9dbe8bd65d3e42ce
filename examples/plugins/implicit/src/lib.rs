//! A third-party delamesh plugin written in Rust: the domain `{p : f(p) < 0}` of an implicit
//! function `f`, chosen by the configuration string.
//!
//! Configuration: space-separated `key=value` pairs.
//! - `shape=sphere` (default) with `radius=1`;
//! - `shape=torus` with `major=1 minor=0.35` (axis z);
//! - `shape=tanglecube` (`x⁴ − 5x² + y⁴ − 5y² + z⁴ − 5z² + 11.8`, genus 5);
//! - `center=x,y,z` (default `0,0,0`) moves any shape;
//! - `samples=64`: sign samples per segment query (crossings closer than one sample are missed).
//!
//! Build with `cargo build -p delamesh-implicit-example --release`, then
//! `delamesh mesh --plugin target/release/libdelamesh_implicit.so --plugin-config 'shape=torus'`.

use delamesh_core::kernel::Point3;
use delamesh_core::oracle::{
    Aabb, OUTSIDE, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use delamesh_core::plugin::PluginOracle;

/// The shapes this example knows, in their own local frame (centred at the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Shape {
    /// A sphere.
    Sphere {
        /// Its radius.
        radius: f64,
    },
    /// A torus around the z axis.
    Torus {
        /// The radius of the circle the tube follows.
        major: f64,
        /// The radius of the tube.
        minor: f64,
    },
    /// The tanglecube, a closed surface of genus 5.
    Tanglecube,
}

impl Shape {
    /// Negative inside, positive outside.
    fn value(self, p: Point3) -> f64 {
        match self {
            Shape::Sphere { radius } => p.length() - radius,
            Shape::Torus { major, minor } => {
                let ring = (p.x * p.x + p.y * p.y).sqrt() - major;
                ring * ring + p.z * p.z - minor * minor
            }
            Shape::Tanglecube => {
                let q = |x: f64| x * x * x * x - 5.0 * x * x;
                q(p.x) + q(p.y) + q(p.z) + 11.8
            }
        }
    }

    /// Half-extent of a box around the zero set.
    fn half_extent(self) -> Point3 {
        match self {
            Shape::Sphere { radius } => Point3::splat(radius),
            Shape::Torus { major, minor } => Point3::new(major + minor, major + minor, minor),
            // |x| < 2.27 on the zero set: x⁴ − 5x² < 2·6.25 − 11.8.
            Shape::Tanglecube => Point3::splat(2.3),
        }
    }
}

/// An implicit domain: `shape` translated to `center`.
#[derive(Clone, Debug)]
pub struct ImplicitOracle {
    shape: Shape,
    center: Point3,
    samples: usize,
    bbox: Aabb,
}

/// Bisection steps: 60 halvings take any segment below f64 resolution of its length.
const BISECTIONS: usize = 60;
/// Grid resolution along each axis for the search of initial points.
const SEED_GRID: usize = 24;
/// At most this many initial points are returned (evenly thinned), enough for the mesher's P0.
const MAX_INITIAL_POINTS: usize = 64;

impl ImplicitOracle {
    /// The oracle of `shape` moved to `center`, with `samples` sign samples per segment;
    /// an error for non-positive sizes or no samples.
    pub fn new(shape: Shape, center: Point3, samples: usize) -> Result<Self, String> {
        let valid = match shape {
            Shape::Sphere { radius } => radius.is_finite() && radius > 0.0,
            Shape::Torus { major, minor } => {
                major.is_finite() && minor.is_finite() && 0.0 < minor && minor < major
            }
            Shape::Tanglecube => true,
        };
        if !valid {
            return Err(format!(
                "invalid shape parameters {shape:?} (sizes must be positive, torus minor < major)"
            ));
        }
        if !center.is_finite() {
            return Err("center must be finite".into());
        }
        if samples < 2 {
            return Err("samples must be at least 2".into());
        }
        // 2% margin: the box must contain the surface strictly, and bisection stays inside it.
        let half = shape.half_extent() * 1.02;
        Ok(ImplicitOracle {
            shape,
            center,
            samples,
            bbox: Aabb {
                min: center - half,
                max: center + half,
            },
        })
    }

    fn value(&self, p: Point3) -> f64 {
        self.shape.value(p - self.center)
    }

    fn inside(&self, p: Point3) -> bool {
        self.value(p) < 0.0
    }

    /// The crossing between `a + t0 (b - a)` and `a + t1 (b - a)`, whose insides differ.
    fn bisect(&self, a: Point3, b: Point3, mut t0: f64, mut t1: f64) -> f64 {
        let inside0 = self.inside(a.lerp(b, t0));
        for _ in 0..BISECTIONS {
            let mid = 0.5 * (t0 + t1);
            if self.inside(a.lerp(b, mid)) == inside0 {
                t0 = mid;
            } else {
                t1 = mid;
            }
        }
        0.5 * (t0 + t1)
    }

    fn push_hit(&self, a: Point3, b: Point3, t: f64, scale: f64, out: &mut Vec<SurfaceHit>) {
        out.push(SurfaceHit {
            point: a.lerp(b, t),
            t: t * scale,
            patch: PatchId(1),
        });
    }
}

impl Oracle for ImplicitOracle {
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    fn subdomain(&self, p: Point3) -> SubdomainId {
        if self.inside(p) {
            SubdomainId(1)
        } else {
            OUTSIDE
        }
    }

    fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
        let steps = self.samples;
        let mut previous = self.inside(a);
        for i in 1..=steps {
            let t = i as f64 / steps as f64;
            let current = self.inside(a.lerp(b, t));
            if current != previous {
                let crossing = self.bisect(a, b, (i - 1) as f64 / steps as f64, t);
                self.push_hit(a, b, crossing, 1.0, out);
            }
            previous = current;
        }
    }

    fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
        // The surface lies in the box: clip the ray to where it leaves the box (slab method).
        let exit = (0..3)
            .filter(|&k| dir[k] != 0.0)
            .map(|k| {
                ((self.bbox.min[k] - origin[k]) / dir[k])
                    .max((self.bbox.max[k] - origin[k]) / dir[k])
            })
            .fold(f64::INFINITY, f64::min);
        if exit.is_finite() && exit > 0.0 {
            let end = origin + exit * dir;
            let start = out.len();
            self.segment_hits(origin, end, out);
            for hit in &mut out[start..] {
                hit.t *= exit;
            }
        }
    }

    fn initial_points(&self) -> Vec<SurfacePoint> {
        // Every grid edge along x whose ends differ in side holds a surface point: with a grid finer
        // than the smallest component, every component gets some.
        let Aabb { min, max } = self.bbox;
        let cell = (max - min) / SEED_GRID as f64;
        let mut points = Vec::new();
        for k in 0..=SEED_GRID {
            for j in 0..=SEED_GRID {
                let row = |i: usize| min + Point3::new(i as f64, j as f64, k as f64) * cell;
                for i in 0..SEED_GRID {
                    let (a, b) = (row(i), row(i + 1));
                    if self.inside(a) != self.inside(b) {
                        points.push(SurfacePoint {
                            point: a.lerp(b, self.bisect(a, b, 0.0, 1.0)),
                            patch: PatchId(1),
                        });
                    }
                }
            }
        }
        let stride = points.len().div_ceil(MAX_INITIAL_POINTS).max(1);
        points.into_iter().step_by(stride).collect()
    }
}

impl PluginOracle for ImplicitOracle {
    fn from_config(config: &str) -> Result<Self, String> {
        let mut shape_name = "sphere";
        let (mut radius, mut major, mut minor) = (1.0, 1.0, 0.35);
        let mut center = Point3::ZERO;
        let mut samples = 64;
        let number = |key: &str, value: &str| -> Result<f64, String> {
            value
                .parse::<f64>()
                .map_err(|_| format!("`{key}={value}`: not a number"))
        };
        for pair in config.split_whitespace() {
            let (key, value) = pair
                .split_once('=')
                .ok_or_else(|| format!("`{pair}`: expected key=value"))?;
            match key {
                "shape" => shape_name = value,
                "radius" => radius = number(key, value)?,
                "major" => major = number(key, value)?,
                "minor" => minor = number(key, value)?,
                "samples" => {
                    samples = value
                        .parse()
                        .map_err(|_| format!("`{pair}`: not a count"))?
                }
                "center" => {
                    let coords: Vec<f64> = value
                        .split(',')
                        .map(|c| number(key, c))
                        .collect::<Result<_, _>>()?;
                    let [x, y, z] = coords[..] else {
                        return Err(format!("`{pair}`: expected x,y,z"));
                    };
                    center = Point3::new(x, y, z);
                }
                _ => {
                    return Err(format!(
                        "unknown key `{key}` (known: shape, radius, major, minor, center, samples)"
                    ));
                }
            }
        }
        let shape = match shape_name {
            "sphere" => Shape::Sphere { radius },
            "torus" => Shape::Torus { major, minor },
            "tanglecube" => Shape::Tanglecube,
            other => {
                return Err(format!(
                    "unknown shape `{other}` (known: sphere, torus, tanglecube)"
                ));
            }
        };
        ImplicitOracle::new(shape, center, samples)
    }
}

delamesh_core::export_oracle_plugin!(ImplicitOracle, name = "implicit", kind = "implicit");

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_segment_through_center_crosses_twice_at_radius() {
        let oracle = ImplicitOracle::from_config("shape=sphere radius=2 center=1,0,0")
            .expect("valid config");
        let mut hits = Vec::new();
        oracle.segment_hits(
            Point3::new(-5.0, 0.0, 0.0),
            Point3::new(5.0, 0.0, 0.0),
            &mut hits,
        );
        assert_eq!(hits.len(), 2);
        assert!((hits[0].point.x + 1.0).abs() < 1e-12 && (hits[1].point.x - 3.0).abs() < 1e-12);
        assert!(hits[0].t < hits[1].t);
    }

    #[test]
    fn rays_cross_at_the_analytic_distances() {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-9;
        let mut hits = Vec::new();
        let sphere = ImplicitOracle::from_config("shape=sphere radius=0.8").expect("valid config");
        sphere.ray_hits(Point3::ZERO, Point3::new(0.0, 2.0, 0.0), &mut hits);
        assert_eq!(hits.len(), 1);
        assert!(close(hits[0].t, 0.4) && close(hits[0].point.y, 0.8));
        hits.clear();
        let torus =
            ImplicitOracle::from_config("shape=torus major=1 minor=0.25").expect("valid config");
        torus.ray_hits(Point3::ZERO, Point3::X, &mut hits);
        let ts: Vec<f64> = hits.iter().map(|h| h.t).collect();
        assert_eq!(ts.len(), 2, "{ts:?}");
        assert!(close(ts[0], 0.75) && close(ts[1], 1.25), "{ts:?}");
    }

    #[test]
    fn initial_points_lie_on_the_surface_of_every_shape() {
        for config in [
            "shape=sphere radius=0.5",
            "shape=torus major=2 minor=0.5",
            "shape=tanglecube",
        ] {
            let oracle = ImplicitOracle::from_config(config).expect("valid config");
            let points = oracle.initial_points();
            assert!(
                !points.is_empty() && points.len() <= MAX_INITIAL_POINTS,
                "{config}"
            );
            assert!(
                points
                    .iter()
                    .all(|p| oracle.value(p.point).abs() < 1e-9 && oracle.bbox.contains(p.point)),
                "{config}"
            );
        }
    }

    #[test]
    fn bad_configs_are_rejected_with_the_key() {
        for (config, word) in [
            ("shape=cube", "cube"),
            ("radius=abc", "radius"),
            ("center=1,2", "center"),
            ("colour=red", "colour"),
        ] {
            let error = ImplicitOracle::from_config(config).expect_err(config);
            assert!(error.contains(word), "{config}: {error}");
        }
        assert!(ImplicitOracle::from_config("shape=torus major=1 minor=2").is_err());
    }
}
