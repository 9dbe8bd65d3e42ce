//! Points and robust geometric predicates.
//!
//! Every predicate returns the exact sign of its determinant for double-precision input (Shewchuk's
//! adaptive arithmetic through the `robust` crate, or an exact big-integer fallback for the power
//! test). The `perturbation` module resolves exact degeneracies symbolically so that a Delaunay
//! triangulation is unique whatever the insertion order.

mod double_double;
mod exact;
pub mod perturbation;
pub mod power;
pub mod predicates;
pub mod predicates2d;

pub use exact::exact_oracle;
pub use glam::DVec2 as Point2;
pub use glam::DVec3 as Point3;
pub use power::{WeightedPoint3, coplanar_power_test, power_test};
pub use predicates::{Sign, StaticFilter, incircle, insphere, orient2d, orient3d};

/// Centre of the sphere through four affinely independent points (floating point, not exact).
///
/// Computed relative to `a` so that large common offsets do not swallow the significant digits.
pub fn circumcenter3(a: Point3, b: Point3, c: Point3, d: Point3) -> Point3 {
    let (ba, ca, da) = (b - a, c - a, d - a);
    let (lb, lc, ld) = (
        ba.length_squared(),
        ca.length_squared(),
        da.length_squared(),
    );
    let cd = ca.cross(da);
    let db = da.cross(ba);
    let bc = ba.cross(ca);
    let denom = 2.0 * ba.dot(cd);
    a + (lb * cd + lc * db + ld * bc) / denom
}
