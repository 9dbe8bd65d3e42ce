//! Triangle quality measures used to judge 2D meshes.

use glam::DVec2;

/// Smallest interior angle of the triangle, in degrees.
pub fn min_angle_deg(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let angle = |p: DVec2, q: DVec2, r: DVec2| (q - p).angle_to(r - p).abs();
    angle(a, b, c)
        .min(angle(b, c, a))
        .min(angle(c, a, b))
        .to_degrees()
}

/// Pébay's shape measure D = α h / r (h longest edge, r inradius, α = √3/6): 1 for the equilateral
/// triangle, growing without bound as the triangle degenerates.
pub fn shape_measure(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    let (la, lb, lc) = ((b - c).length(), (c - a).length(), (a - b).length());
    let area = 0.5 * (b - a).perp_dot(c - a).abs();
    let inradius = 2.0 * area / (la + lb + lc);
    (3f64.sqrt() / 6.0) * la.max(lb).max(lc) / inradius
}

/// Signed area of `(a, b, c)`: positive when counter-clockwise.
pub fn signed_area(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    0.5 * (b - a).perp_dot(c - a)
}
