//! The exact power test for regular (weighted Delaunay) triangulations.
//!
//! A weighted point `(p, w)` lifts to `|p|² − w`; the power test is the sign of the 5×5 lifted
//! determinant, i.e. whether a fifth weighted point has a negative power distance to the sphere
//! orthogonal to four others. With all weights zero it is the in-sphere test, with the same sign
//! convention. A semi-static floating-point filter decides almost every call; a double-double
//! stage (shared with the in-sphere test) nearly all of the rest, slivers' tests above all; the
//! remaining near-degeneracies are evaluated exactly on the doubles' exact dyadic values with big
//! integers.

use super::exact::{det, dyadic, scaled, sign_of};
use super::predicates::lifted_sign_double_double;
use super::{Point2, Point3, Sign, orient2d, orient3d};
use num_bigint::BigInt;

/// A point with a weight (a squared radius): the vertex type of a regular triangulation.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WeightedPoint3 {
    /// The point.
    pub point: Point3,
    /// Its weight: the square of the radius of its sphere.
    pub weight: f64,
}

impl WeightedPoint3 {
    /// A point with a weight.
    pub fn new(point: Point3, weight: f64) -> Self {
        WeightedPoint3 { point, weight }
    }
}

/// Positive when `e` has a negative power distance to the sphere orthogonal to `a, b, c, d`
/// (`e` conflicts with the cell), given `orient3d(a, b, c, d)` positive; the sign is reversed for
/// a negatively oriented tetrahedron. Zero exactly when `e` is orthogonal to that sphere.
pub fn power_test(
    a: WeightedPoint3,
    b: WeightedPoint3,
    c: WeightedPoint3,
    d: WeightedPoint3,
    e: WeightedPoint3,
) -> Sign {
    let rows = [a, b, c, d].map(|q| {
        let t = q.point - e.point;
        (t, t.length_squared() - (q.weight - e.weight))
    });
    let [(ae, la), (be, lb), (ce, lc), (de, ld)] = rows;
    let ab = ae.x * be.y - be.x * ae.y;
    let bc = be.x * ce.y - ce.x * be.y;
    let cd = ce.x * de.y - de.x * ce.y;
    let da = de.x * ae.y - ae.x * de.y;
    let ac = ae.x * ce.y - ce.x * ae.y;
    let bd = be.x * de.y - de.x * be.y;
    let abc = ae.z * bc - be.z * ac + ce.z * ab;
    let bcd = be.z * cd - ce.z * bd + de.z * bc;
    let cda = ce.z * da + de.z * ac + ae.z * cd;
    let dab = de.z * ab + ae.z * bd + be.z * da;
    let det = (ld * abc - lc * dab) + (lb * cda - la * bcd);
    let m = ae.abs().max(be.abs()).max(ce.abs()).max(de.abs());
    let lift_bound = [a, b, c, d]
        .iter()
        .zip(rows)
        .map(|(q, (t, _))| t.length_squared() + q.weight.abs() + e.weight.abs())
        .fold(0.0, f64::max);
    // Same reasoning as the in-sphere filter, with the lift magnitude bounded by |t|² + |w| + |w_e|.
    let bound = 1e-12 * m.x * m.y * m.z * lift_bound;
    if det.is_finite() && bound.is_finite() && det.abs() > bound && m.min_element() > 1e-55 {
        return Sign::of(det);
    }
    power_test_exact([a, b, c, d, e])
}

/// Centre of the sphere orthogonal to four affinely independent weighted points (the point with
/// equal power distance `|x − p|² − w` to all four; floating point, not exact). With zero weights
/// it is the circumcentre.
pub fn orthocenter3(
    a: WeightedPoint3,
    b: WeightedPoint3,
    c: WeightedPoint3,
    d: WeightedPoint3,
) -> Point3 {
    // Relative to `a`: 2 (q − a)·x = |q − a|² − (w_q − w_a) for q = b, c, d.
    let (ba, ca, da) = (b.point - a.point, c.point - a.point, d.point - a.point);
    let lb = ba.length_squared() - (b.weight - a.weight);
    let lc = ca.length_squared() - (c.weight - a.weight);
    let ld = da.length_squared() - (d.weight - a.weight);
    let cd = ca.cross(da);
    let db = da.cross(ba);
    let bc = ba.cross(ca);
    let denom = 2.0 * ba.dot(cd);
    a.point + (lb * cd + lc * db + ld * bc) / denom
}

/// For weighted points `a, b, c, e` with coplanar positions (`a, b, c` not collinear): positive
/// when `e` has a negative power distance to the circle orthogonal to `a, b, c` in their plane —
/// the conflict test of a hull facet with a point on its plane in a regular triangulation.
/// Orientation-free: the result does not depend on the order of `a, b, c`.
pub fn coplanar_power_test(
    a: WeightedPoint3,
    b: WeightedPoint3,
    c: WeightedPoint3,
    e: WeightedPoint3,
) -> Sign {
    let (q, plane_sign) = off_plane_point([a.point, b.point, c.point]);
    // A sphere orthogonal to a, b, c and any fourth weighted point cuts their plane along the
    // circle orthogonal to a, b, c, and power distances in the plane are preserved up to a
    // constant, so the 3D power test answers the planar one.
    let s = power_test(a, b, c, WeightedPoint3::new(q, 0.0), e);
    if plane_sign == Sign::Negative {
        s.flip()
    } else {
        s
    }
}

/// A point exactly off the plane of the non-collinear triangle `tri`, with `orient3d(tri, q)`.
pub(crate) fn off_plane_point(tri: [Point3; 3]) -> (Point3, Sign) {
    let [a, b, c] = tri;
    let proj = |p: Point3, i: usize, j: usize| Point2::new(p[i], p[j]);
    for (axis, (i, j)) in [(1, 2), (2, 0), (0, 1)].into_iter().enumerate() {
        // The normal's component along `axis` is the orientation of the projection on (i, j).
        if orient2d(proj(a, i, j), proj(b, i, j), proj(c, i, j)) != Sign::Zero {
            let mut q = a;
            q[axis] += 1.0 + q[axis].abs();
            let s = orient3d(a, b, c, q);
            if s != Sign::Zero {
                return (q, s);
            }
        }
    }
    unreachable!("a non-collinear triangle has a non-zero normal component")
}

/// The exact sign of the lifted 5×5 determinant, rows `[x y z |p|²−w 1]`.
#[cold]
fn power_test_exact(p: [WeightedPoint3; 5]) -> Sign {
    lifted_sign_double_double([p[0], p[1], p[2], p[3]], p[4]).unwrap_or_else(|| power_test_big(p))
}

/// [`power_test_exact`] with big integers alone.
fn power_test_big(p: [WeightedPoint3; 5]) -> Sign {
    // Smallest exponents of the coordinates and of the weights: scaling a column by a power of
    // two keeps the determinant's sign, so every entry becomes an integer.
    let exp = |x: f64| if x == 0.0 { i32::MAX } else { dyadic(x).1 };
    let ec = p
        .iter()
        .flat_map(|q| [q.point.x, q.point.y, q.point.z])
        .map(exp)
        .min()
        .unwrap_or(0)
        .min(0);
    let ew = p.iter().map(|q| exp(q.weight)).min().unwrap_or(0);
    let lift_unit = (2 * ec).min(ew);
    let rows: Vec<[BigInt; 4]> = p
        .iter()
        .map(|q| {
            let xyz = [q.point.x, q.point.y, q.point.z].map(|x| scaled(x, ec));
            let square: BigInt = xyz.iter().map(|v| v * v).sum();
            let lift = (square << ((2 * ec - lift_unit) as usize)) - scaled(q.weight, lift_unit);
            let [x, y, z] = xyz;
            [x, y, z, lift]
        })
        .collect();
    // Subtract the last row (the column of ones), leaving a 4×4 determinant.
    let m: Vec<[BigInt; 4]> = rows[..4]
        .iter()
        .map(|r| std::array::from_fn(|j| &r[j] - &rows[4][j]))
        .collect();
    let refs: Vec<Vec<&BigInt>> = m.iter().map(|r| r.iter().collect()).collect();
    // det[rows - e] is the 5×5 determinant up to the sign (-1)^(4) of expanding along the ones.
    sign_of(&det(&refs))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::insphere;
    use crate::random::XorShift;

    fn w(x: f64, y: f64, z: f64, weight: f64) -> WeightedPoint3 {
        WeightedPoint3::new(Point3::new(x, y, z), weight)
    }

    #[test]
    fn unweighted_power_test_is_the_in_sphere_test() {
        let mut rng = XorShift::new(0x9e37_79b9_7f4a_7c15);
        let mut next = || rng.next_f64();
        for k in 0..2000 {
            let scale = if k % 2 == 0 { 1.0 } else { 3.0 };
            let p: [Point3; 5] = std::array::from_fn(|_| {
                // Coarse coordinates make many exact ties.
                Point3::new((next() * 4.0).floor(), (next() * 4.0).floor(), next()) * scale
            });
            let wp = p.map(|q| WeightedPoint3::new(q, 0.0));
            let expected = insphere(p[0], p[1], p[2], p[3], p[4]);
            assert_eq!(power_test(wp[0], wp[1], wp[2], wp[3], wp[4]), expected);
            assert_eq!(power_test_exact(wp), expected);
        }
    }

    #[test]
    fn weights_move_the_orthogonal_sphere() {
        // Unit tetrahedron corner: circumsphere centre (0.5,0.5,0.5), radius² 0.75.
        let [a, b, c, d] = [
            w(1.0, 0.0, 0.0, 0.0),
            w(0.0, 1.0, 0.0, 0.0),
            w(0.0, 0.0, 1.0, 0.0),
            w(0.0, 0.0, 0.0, 0.0),
        ];
        let queries = [
            // On the sphere.
            (w(1.0, 1.0, 1.0, 0.0), Sign::Zero),
            // A positive weight on the query makes it reach into the sphere: conflict.
            (w(1.0, 1.0, 1.0, 0.25), Sign::Positive),
            // A weight cancelling the power distance |q - centre|² - 0.75 = 2.25 - 0.75 = 1.5:
            // orthogonal, hence zero.
            (w(2.0, 0.5, 0.5, 1.5), Sign::Zero),
        ];
        for (q, expected) in queries {
            assert_eq!(power_test(a, b, c, d, q), expected, "{q:?}");
            assert_eq!(power_test_exact([a, b, c, d, q]), expected, "{q:?}");
        }
    }

    #[test]
    fn exact_fallback_handles_tiny_and_huge_magnitudes() {
        let t = 1e-200;
        let [a, b, c, d] = [
            w(t, 0.0, 0.0, 0.0),
            w(0.0, t, 0.0, 0.0),
            w(0.0, 0.0, t, 0.0),
            w(0.0, 0.0, 0.0, 0.0),
        ];
        let quarter = t / 4.0;
        for (q, expected) in [
            (w(t, t, t, 0.0), Sign::Zero),
            (w(quarter, quarter, quarter, 0.0), Sign::Positive),
        ] {
            assert_eq!(power_test(a, b, c, d, q), expected, "{q:?}");
        }
        let big = [
            w(1e40, 0.0, 0.0, 1e70),
            w(0.0, 1e40, 0.0, 0.0),
            w(0.0, 0.0, 1e40, 0.0),
            w(0.0, 0.0, 0.0, 0.0),
        ];
        let q = w(1e40, 1e40, 1e40, 0.0);
        let s = power_test(big[0], big[1], big[2], big[3], q);
        assert_eq!(s, power_test_exact([big[0], big[1], big[2], big[3], q]));
    }

    /// Fifth points orthogonal, up to a rounding, to the sphere of four random weighted points
    /// (the tests of slivers look like this): the double-double stage decides nearly all and
    /// agrees with the big integers on every one it decides; exactly orthogonal ones it leaves.
    #[test]
    fn double_double_stage_agrees_with_big_integers_near_orthogonality() {
        let mut rng = XorShift::new(0x5EED_F5C1_E5EE);
        let mut unit = move || rng.next_f64() * 2.0 - 1.0;
        let (mut decided, runs) = (0, 6_000);
        for k in 0..runs {
            let scale = [1.0, 1e-20, 1e15][k % 3];
            let mut q = [(); 4].map(|()| {
                let p = Point3::new(unit(), unit(), unit()) * scale;
                WeightedPoint3::new(p, 0.1 * unit().abs() * scale * scale)
            });
            if orient3d(q[0].point, q[1].point, q[2].point, q[3].point) == Sign::Negative {
                q.swap(0, 1);
            }
            let centre = orthocenter3(q[0], q[1], q[2], q[3]);
            let power = q[0].point.distance_squared(centre) - q[0].weight;
            // A point on the orthogonal sphere, its weight making it orthogonal up to rounding.
            let p = centre + Point3::new(unit(), unit(), unit()) * scale;
            let e = WeightedPoint3::new(p, p.distance_squared(centre) - power);
            let big = power_test_big([q[0], q[1], q[2], q[3], e]);
            if let Some(sign) = lifted_sign_double_double(q, e) {
                assert_eq!(sign, big, "{q:?} {e:?}");
                decided += 1;
            }
            assert_eq!(power_test(q[0], q[1], q[2], q[3], e), big);
        }
        assert!(
            decided * 10 > runs * 9,
            "double-double decided {decided} of {runs}"
        );
        // Exactly orthogonal: integer points and weights, the stage must not decide.
        let q = [
            (0.0, 0.0, 0.0),
            (4.0, 0.0, 0.0),
            (0.0, 4.0, 0.0),
            (0.0, 0.0, 4.0),
        ]
        .map(|(x, y, z)| w(x, y, z, 1.0));
        let e = w(4.0, 4.0, 0.0, 1.0);
        assert_eq!(lifted_sign_double_double(q, e), None);
        assert_eq!(power_test_big([q[0], q[1], q[2], q[3], e]), Sign::Zero);
    }

    #[test]
    fn coplanar_power_test_matches_the_planar_geometry() {
        let (a, b, c) = (
            w(0.0, 0.0, 2.0, 0.0),
            w(2.0, 0.0, 2.0, 0.0),
            w(0.0, 2.0, 2.0, 0.0),
        );
        // Circumcircle centre (1,1), radius² 2; weight 6 on the far point: power distance
        // 8 - 2 - 6 = 0.
        let cases = [
            ([a, b, c], w(1.0, 1.0, 2.0, 0.0), Sign::Positive),
            ([b, a, c], w(1.0, 1.0, 2.0, 0.0), Sign::Positive),
            ([a, b, c], w(2.0, 2.0, 2.0, 0.0), Sign::Zero),
            ([a, b, c], w(3.0, 3.0, 2.0, 0.0), Sign::Negative),
            ([a, b, c], w(3.0, 3.0, 2.0, 6.0), Sign::Zero),
        ];
        for ([p, q, r], s, expected) in cases {
            assert_eq!(coplanar_power_test(p, q, r, s), expected, "{s:?}");
        }
    }
}
