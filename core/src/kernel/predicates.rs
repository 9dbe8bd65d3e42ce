//! Exact-sign orientation and in-sphere predicates on double-precision points.
//!
//! Each predicate is a cascade, cheapest first, every stage deciding the sign only when its error
//! bound allows: a static filter (a bound from the bounding box, for the triangulations' hot
//! paths), a semi-static filter (a bound from the coordinate differences), exact evaluation of
//! small integer grids, a double-double stage on the exact differences (in-sphere), and last the
//! `robust` crate's exact adaptive arithmetic (Shewchuk's expansions).

use super::double_double::{dd_add, dd_mul, dd_neg, dd_sub, two_diff};
use super::exact::{expansions_are_exact, insphere_big, orient2d_big, orient3d_big};
use super::{Point2, Point3, WeightedPoint3};
use robust::{Coord, Coord3D};

/// The sign of a determinant. Triangulations branch on signs only, never on magnitudes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Sign {
    /// Below zero.
    Negative,
    /// Exactly zero: degenerate.
    Zero,
    /// Above zero.
    Positive,
}

impl Sign {
    /// Sign of an (exactly signed) determinant value.
    #[inline]
    pub fn of(value: f64) -> Sign {
        if value > 0.0 {
            Sign::Positive
        } else if value < 0.0 {
            Sign::Negative
        } else {
            Sign::Zero
        }
    }

    /// The opposite sign.
    #[inline]
    pub fn flip(self) -> Sign {
        match self {
            Sign::Negative => Sign::Positive,
            Sign::Zero => Sign::Zero,
            Sign::Positive => Sign::Negative,
        }
    }
}

#[inline]
fn c2(p: Point2) -> Coord<f64> {
    Coord { x: p.x, y: p.y }
}

#[inline]
fn c3(p: Point3) -> Coord3D<f64> {
    Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Positive when `a, b, c` turn counter-clockwise.
#[inline]
pub fn orient2d(a: Point2, b: Point2, c: Point2) -> Sign {
    let (ac, bc) = (a - c, b - c);
    let (left, right) = (ac.x * bc.y, ac.y * bc.x);
    let det = left - right;
    let permanent = left.abs() + right.abs();
    // Shewchuk's first bound; above the range guard, underflow cannot have mattered.
    if det.abs() > ORIENT2D_ERROR * permanent && permanent > MIN_FILTER_PERMANENT {
        return Sign::of(det);
    }
    orient2d_exact(a, b, c)
}

#[cold]
#[inline(never)]
fn orient2d_exact(a: Point2, b: Point2, c: Point2) -> Sign {
    if expansions_are_exact(&[a.x, a.y, b.x, b.y, c.x, c.y], 2) {
        Sign::of(robust::orient2d(c2(a), c2(b), c2(c)))
    } else {
        orient2d_big([a, b, c].map(|p| p.to_array()))
    }
}

/// Positive when `d` lies below the plane through `a, b, c`, seen counter-clockwise from above
/// (Shewchuk's convention: the sign of `det[a-d; b-d; c-d]`). A tetrahedron `(a, b, c, d)` is
/// *positively oriented* when this is positive; every finite cell of `Delaunay3` is.
#[inline]
pub fn orient3d(a: Point3, b: Point3, c: Point3, d: Point3) -> Sign {
    orient3d_refined(a, b, c, d, orient3d_det(a, b, c, d))
}

/// The orientation determinant in plain floating point.
#[inline(always)]
fn orient3d_det(a: Point3, b: Point3, c: Point3, d: Point3) -> f64 {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    ad.x * (bd.y * cd.z - bd.z * cd.y) - ad.y * (bd.x * cd.z - bd.z * cd.x)
        + ad.z * (bd.x * cd.y - bd.y * cd.x)
}

/// The sign of `orient3d(a, b, c, d)` given its floating-point determinant `det`.
#[inline]
fn orient3d_refined(a: Point3, b: Point3, c: Point3, d: Point3, det: f64) -> Sign {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let m = ad.abs().max(bd.abs()).max(cd.abs());
    // Semi-static filter: each of the six products of three differences is at most
    // m.x * m.y * m.z and is evaluated with a handful of roundings, so the floating-point error
    // stays below ~5e-15 of that product; 1e-14 leaves a margin. The range guard keeps the bound
    // itself free of underflow; an infinite determinant overflowed and decides nothing.
    let bound = ORIENT3D_ERROR * m.x * m.y * m.z;
    if det.is_finite() && det.abs() > bound && m.min_element() > 1e-90 {
        return Sign::of(det);
    }
    // Integer points with differences up to 2^16: every intermediate is an integer below 2^53,
    // so the evaluation above was exact (this makes degenerate grids fast).
    if m.max_element() <= 65536.0 && all_integral(&[a, b, c, d]) {
        return Sign::of(det);
    }
    orient3d_exact(a, b, c, d)
}

/// Shewchuk's first error bound of the planar orientation, relative to its permanent.
const ORIENT2D_ERROR: f64 = (3.0 + 16.0 * UNIT_ROUNDOFF) * UNIT_ROUNDOFF;
/// Smallest permanent a first-stage filter decides with: above it, what underflow can lose is
/// far below the error bound.
const MIN_FILTER_PERMANENT: f64 = 1e-280;
/// Relative error bound of the orientation determinant (see [`orient3d`]).
const ORIENT3D_ERROR: f64 = 1e-14;
/// Relative error bound of the in-sphere determinant (see [`insphere`]).
const INSPHERE_ERROR: f64 = 1e-12;
/// Below this, a static bound could be swamped by underflow in the determinants: not used.
const MIN_STATIC_BOUND: f64 = 1e-200;
/// Above this box extent a term of the in-sphere determinant (degree five, up to 72 of them)
/// can overflow while the bound stays finite: the static filters are then not used.
const MAX_STATIC_EXTENT: f64 = 1e60;

/// Static filters (fixed error bounds) for points inside a known bounding box.
///
/// The semi-static filters of [`orient3d`] and [`insphere`] bound the error with the largest
/// coordinate differences of the points at hand, which costs a few dozen instructions per call.
/// Differences never exceed the box's extent, so one bound computed from the box decides almost
/// every call of a bulk construction at once; the rest go on to the semi-static filter.
#[derive(Clone, Copy, Debug)]
pub struct StaticFilter {
    lo: Point3,
    hi: Point3,
    orient3d_bound: f64,
    insphere_bound: f64,
}

impl Default for StaticFilter {
    fn default() -> Self {
        StaticFilter {
            lo: Point3::splat(f64::INFINITY),
            hi: Point3::splat(f64::NEG_INFINITY),
            orient3d_bound: f64::INFINITY,
            insphere_bound: f64::INFINITY,
        }
    }
}

impl StaticFilter {
    /// Grows the box to contain the finite point `p`; every point given to the predicates must
    /// have been included.
    #[inline]
    pub fn include(&mut self, p: Point3) {
        if p.cmplt(self.lo).any() || p.cmpgt(self.hi).any() {
            self.grow(p);
        }
    }

    /// Whether the box holds `p`: the bounds then hold for predicates on it.
    #[inline]
    pub fn contains(&self, p: Point3) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all()
    }

    #[cold]
    fn grow(&mut self, p: Point3) {
        self.lo = self.lo.min(p);
        self.hi = self.hi.max(p);
        let e = self.hi - self.lo;
        let m = e.max_element();
        let valid = |b: f64| {
            if b >= MIN_STATIC_BOUND && m <= MAX_STATIC_EXTENT {
                b
            } else {
                f64::INFINITY
            }
        };
        // Rounding the bounds themselves costs a few ulps, far inside the filters' margins.
        self.orient3d_bound = valid(ORIENT3D_ERROR * e.x * e.y * e.z);
        self.insphere_bound = valid(INSPHERE_ERROR * e.x * e.y * e.z * m * m);
    }

    /// [`orient3d`] for points inside the box.
    #[inline]
    pub fn orient3d(&self, a: Point3, b: Point3, c: Point3, d: Point3) -> Sign {
        let det = orient3d_det(a, b, c, d);
        if det.abs() > self.orient3d_bound {
            return Sign::of(det);
        }
        orient3d_cold(a, b, c, d)
    }

    /// [`insphere`] when the static bound alone decides it, `None` otherwise (rarely). Keeps
    /// the caller's hot path free of the refinement code and its register pressure.
    #[inline(always)]
    pub fn insphere_static(
        &self,
        a: Point3,
        b: Point3,
        c: Point3,
        d: Point3,
        e: Point3,
    ) -> Option<Sign> {
        let det = insphere_det(a, b, c, d, e);
        (det.abs() > self.insphere_bound).then(|| Sign::of(det))
    }

    /// [`insphere`] for points inside the box.
    #[inline]
    pub fn insphere(&self, a: Point3, b: Point3, c: Point3, d: Point3, e: Point3) -> Sign {
        let det = insphere_det(a, b, c, d, e);
        if det.abs() > self.insphere_bound {
            return Sign::of(det);
        }
        insphere_refined(a, b, c, d, e, det)
    }
}

/// Whether every coordinate is an integer. With integer inputs, a floating-point difference of at
/// most 2^53 in magnitude is exact (the exact result is representable).
#[inline]
fn all_integral(points: &[Point3]) -> bool {
    // The saturating cast maps |x| ≥ 2^63 to a different value: reported as non-integral, which
    // only sends the caller to the exact path.
    let integral = |x: f64| (x as i64) as f64 == x;
    points
        .iter()
        .all(|p| integral(p.x) && integral(p.y) && integral(p.z))
}

/// [`orient3d`] out of line, for callers whose fast path already failed.
#[cold]
#[inline(never)]
fn orient3d_cold(a: Point3, b: Point3, c: Point3, d: Point3) -> Sign {
    orient3d(a, b, c, d)
}

#[cold]
fn orient3d_exact(a: Point3, b: Point3, c: Point3, d: Point3) -> Sign {
    if expansions_are_exact(&coordinates(&[a, b, c, d]), 3) {
        Sign::of(robust::orient3d(c3(a), c3(b), c3(c), c3(d)))
    } else {
        orient3d_big([a, b, c, d].map(|p| p.to_array()))
    }
}

/// The coordinates of `points`, for [`expansions_are_exact`].
fn coordinates<const N: usize>(points: &[Point3; N]) -> Vec<f64> {
    points.iter().flat_map(|p| p.to_array()).collect()
}

/// Positive when `d` lies inside the circle through `a, b, c`, given `orient2d(a, b, c)` positive
/// (the sign is reversed for a negatively oriented triangle).
#[inline]
pub fn incircle(a: Point2, b: Point2, c: Point2, d: Point2) -> Sign {
    match super::predicates2d::incircle(a, b, c, d) {
        std::cmp::Ordering::Less => Sign::Negative,
        std::cmp::Ordering::Equal => Sign::Zero,
        std::cmp::Ordering::Greater => Sign::Positive,
    }
}

/// Positive when `e` lies inside the sphere through `a, b, c, d`, given `orient3d(a, b, c, d)`
/// positive (the sign is reversed for a negatively oriented tetrahedron).
#[inline]
pub fn insphere(a: Point3, b: Point3, c: Point3, d: Point3, e: Point3) -> Sign {
    insphere_refined(a, b, c, d, e, insphere_det(a, b, c, d, e))
}

/// The in-sphere determinant in plain floating point.
///
/// Written as a scalar expression tree over pairs of rows, in the order that lets the compiler
/// keep both halves in the two lanes of a vector register without shuffling between them.
#[inline(always)]
fn insphere_det(a: Point3, b: Point3, c: Point3, d: Point3, e: Point3) -> f64 {
    // Rows a and c, then b and d, are handled side by side.
    let (aex, aey, aez) = (a.x - e.x, a.y - e.y, a.z - e.z);
    let (cex, cey, cez) = (c.x - e.x, c.y - e.y, c.z - e.z);
    let (bex, bey, bez) = (b.x - e.x, b.y - e.y, b.z - e.z);
    let (dex, dey, dez) = (d.x - e.x, d.y - e.y, d.z - e.z);
    let la = aex * aex + aey * aey + aez * aez;
    let lc = cex * cex + cey * cey + cez * cez;
    let lb = bex * bex + bey * bey + bez * bez;
    let ld = dex * dex + dey * dey + dez * dez;
    // 4×4 determinant [x y z lift] of the translated rows, expanded along 2×2 minors.
    let ab = aex * bey - bex * aey;
    let cd = cex * dey - dex * cey;
    let bc = bex * cey - cex * bey;
    let da = dex * aey - aex * dey;
    let ac = aex * cey - cex * aey;
    let bd = bex * dey - dex * bey;
    let abc = aez * bc - bez * ac + cez * ab;
    let cda = cez * da + dez * ac + aez * cd;
    let bcd = bez * cd - cez * bd + dez * bc;
    let dab = dez * ab + aez * bd + bez * da;
    (ld * abc - lc * dab) + (lb * cda - la * bcd)
}

/// The sign of `insphere(a, b, c, d, e)` given its floating-point determinant `det`.
#[inline]
fn insphere_refined(a: Point3, b: Point3, c: Point3, d: Point3, e: Point3, det: f64) -> Sign {
    let (ae, be, ce, de) = (a - e, b - e, c - e, d - e);
    let m = ae.abs().max(be.abs()).max(ce.abs()).max(de.abs());
    let mm = m.max_element();
    // Semi-static filter: the 24 products x * y * z * lift are each at most m.x * m.y * m.z *
    // 3 mm², computed with about ten roundings: the error stays below ~1e-13 of m.x m.y m.z mm²;
    // 1e-12 leaves a margin. The range guard keeps the bound free of underflow; an infinite
    // determinant overflowed and decides nothing.
    let bound = INSPHERE_ERROR * m.x * m.y * m.z * mm * mm;
    if det.is_finite() && det.abs() > bound && m.min_element() > 1e-55 {
        return Sign::of(det);
    }
    // Integer points with differences up to 2^9: |det| < 72 · 2^45 and every intermediate is an
    // integer below 2^53, so the evaluation above was exact (this makes degenerate grids fast).
    if mm <= 512.0 && all_integral(&[a, b, c, d, e]) {
        return Sign::of(det);
    }
    insphere_exact(a, b, c, d, e)
}

/// u = 2⁻⁵³, the unit roundoff.
const UNIT_ROUNDOFF: f64 = f64::EPSILON / 2.0;
/// Error bound of [`lifted_double_double`] relative to its permanent: nine levels of
/// double-double operations (the eighth subtracts the weights from the lift), each within 7u² of
/// its exact result, stay within (1 + 7u²)⁹ − 1 < 64u²; this is twice that.
const LIFTED_ERROR_DD: f64 = 128.0 * UNIT_ROUNDOFF * UNIT_ROUNDOFF;
/// Non-zero differences outside this range skip the double-double stage: inside it no term of
/// degree five overflows. Weights, of degree two, may span the squared range.
const DD_RANGE: (f64, f64) = (1e-50, 1e50);
/// Smallest permanent the double-double stage decides with: above it, what underflow can lose
/// is far below the error bound.
const MIN_DD_PERMANENT: f64 = 1e-200;

/// The in-sphere sign when the floating-point filters failed: the determinant of the exact
/// differences in double-double arithmetic decides all but near-exact degeneracies (points
/// sampled from a sphere make many), then `robust`'s exact evaluation.
#[cold]
#[inline(never)]
fn insphere_exact(a: Point3, b: Point3, c: Point3, d: Point3, e: Point3) -> Sign {
    let unweighted = [a, b, c, d].map(|p| WeightedPoint3::new(p, 0.0));
    if let Some(sign) = lifted_sign_double_double(unweighted, WeightedPoint3::new(e, 0.0)) {
        return sign;
    }
    if expansions_are_exact(&coordinates(&[a, b, c, d, e]), 5) {
        Sign::of(robust::insphere(c3(a), c3(b), c3(c), c3(d), c3(e)))
    } else {
        insphere_big([a, b, c, d, e].map(|p| p.to_array()))
    }
}

/// The sign of the lifted determinant of the power test (the in-sphere test with zero weights)
/// of `rows` against `e`, from the exact differences in double-double arithmetic; `None` when
/// the error bound cannot decide it (a near-exact degeneracy) or the magnitudes are out of the
/// stage's range. The filters of slivers' tests fail for most of them, and this decides nearly
/// all of those at a fraction of the big-integer evaluation's cost.
pub(crate) fn lifted_sign_double_double(
    rows: [WeightedPoint3; 4],
    e: WeightedPoint3,
) -> Option<Sign> {
    let diffs = rows.map(|q| {
        let p = q.point;
        [
            two_diff(p.x, e.point.x),
            two_diff(p.y, e.point.y),
            two_diff(p.z, e.point.z),
        ]
    });
    let weights = rows.map(|q| two_diff(q.weight, e.weight));
    let within = |x: f64, (lo, hi): (f64, f64)| x == 0.0 || (lo..=hi).contains(&x.abs());
    let squared = (DD_RANGE.0 * DD_RANGE.0, DD_RANGE.1 * DD_RANGE.1);
    let in_range = diffs.iter().flatten().all(|&(hi, _)| within(hi, DD_RANGE))
        && weights.iter().all(|&(hi, _)| within(hi, squared));
    if !in_range {
        return None;
    }
    let (det, permanent) = lifted_double_double(diffs, weights);
    (permanent > MIN_DD_PERMANENT && det.abs() > LIFTED_ERROR_DD * permanent).then(|| Sign::of(det))
}

/// The lifted determinant of the exact differences `(hi, lo)` (rows a, b, c, d relative to e,
/// lifts `|row|² − weight`) in double-double arithmetic, in the same expansion as
/// [`insphere_det`], with its permanent: the same expression in absolute values, which bounds
/// the rounding error.
fn lifted_double_double(d: [[(f64, f64); 3]; 4], w: [(f64, f64); 4]) -> (f64, f64) {
    let [[ax, ay, az], [bx, by, bz], [cx, cy, cz], [dx, dy, dz]] = d;
    let cross = |ux, uy, vx, vy| dd_sub(dd_mul(ux, vy), dd_mul(vx, uy));
    let (ab, cd, bc) = (
        cross(ax, ay, bx, by),
        cross(cx, cy, dx, dy),
        cross(bx, by, cx, cy),
    );
    let (da, ac, bd) = (
        cross(dx, dy, ax, ay),
        cross(ax, ay, cx, cy),
        cross(bx, by, dx, dy),
    );
    let triple =
        |z1, m1, z2, m2, z3, m3| dd_add(dd_add(dd_mul(z1, m1), dd_mul(z2, m2)), dd_mul(z3, m3));
    let abc = triple(az, bc, dd_neg(bz), ac, cz, ab);
    let cda = triple(cz, da, dz, ac, az, cd);
    let bcd = triple(bz, cd, dd_neg(cz), bd, dz, bc);
    let dab = triple(dz, ab, az, bd, bz, da);
    let square = |x, y, z| dd_add(dd_add(dd_mul(x, x), dd_mul(y, y)), dd_mul(z, z));
    let (sa, sb, sc, sd) = (
        square(ax, ay, az),
        square(bx, by, bz),
        square(cx, cy, cz),
        square(dx, dy, dz),
    );
    let (la, lb, lc, ld) = (
        dd_sub(sa, w[0]),
        dd_sub(sb, w[1]),
        dd_sub(sc, w[2]),
        dd_sub(sd, w[3]),
    );
    let det = dd_add(
        dd_sub(dd_mul(ld, abc), dd_mul(lc, dab)),
        dd_sub(dd_mul(lb, cda), dd_mul(la, bcd)),
    );
    // The permanent from the high parts: they differ from the exact differences by a relative
    // u at most, and the factor-2 margin of the bound absorbs that and this sum's roundings.
    let h = |v: (f64, f64)| v.0.abs();
    let p2 = |ux, uy, vx, vy| h(ux) * h(vy) + h(vx) * h(uy);
    let (pab, pcd, pbc) = (p2(ax, ay, bx, by), p2(cx, cy, dx, dy), p2(bx, by, cx, cy));
    let (pda, pac, pbd) = (p2(dx, dy, ax, ay), p2(ax, ay, cx, cy), p2(bx, by, dx, dy));
    let p3 = |z1, m1: f64, z2, m2: f64, z3, m3: f64| h(z1) * m1 + h(z2) * m2 + h(z3) * m3;
    // A lift's rounding is relative to its square and its weight, not to their difference.
    let lift = |s: (f64, f64), w: (f64, f64)| s.0 + w.0.abs();
    let permanent = lift(sd, w[3]) * p3(az, pbc, bz, pac, cz, pab)
        + lift(sc, w[2]) * p3(dz, pab, az, pbd, bz, pda)
        + lift(sb, w[1]) * p3(cz, pda, dz, pac, az, pcd)
        + lift(sa, w[0]) * p3(bz, pcd, cz, pbd, dz, pbc);
    (det.0 + det.1, permanent)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::XorShift;

    /// Points of the unit sphere rounded to doubles: nearly every in-sphere test of five of them
    /// reaches the double-double stage, and some the exact one.
    #[test]
    fn nearly_cospherical_signs_match_the_exact_predicate() {
        let mut rng = XorShift::new(0x9E37_79B9_7F4A_7C15);
        let mut unit = move || rng.next_f64() * 2.0 - 1.0;
        let mut on_sphere = |scale: f64| {
            let p = Point3::new(unit(), unit(), unit());
            p / p.length() * scale
        };
        let exact = |q: [Point3; 5]| {
            Sign::of(robust::insphere(
                c3(q[0]),
                c3(q[1]),
                c3(q[2]),
                c3(q[3]),
                c3(q[4]),
            ))
        };
        let mut decided = 0;
        for k in 0..20_000 {
            let scale = [1.0, 1e-30, 1e20][k % 3];
            let q = [(); 5].map(|()| on_sphere(scale));
            assert_eq!(
                insphere_exact(q[0], q[1], q[2], q[3], q[4]),
                exact(q),
                "{q:?}"
            );
            assert_eq!(insphere(q[0], q[1], q[2], q[3], q[4]), exact(q), "{q:?}");
            let diffs = [q[0], q[1], q[2], q[3]].map(|p| {
                [
                    two_diff(p.x, q[4].x),
                    two_diff(p.y, q[4].y),
                    two_diff(p.z, q[4].z),
                ]
            });
            let (det, permanent) = lifted_double_double(diffs, [(0.0, 0.0); 4]);
            decided += usize::from(det.abs() > LIFTED_ERROR_DD * permanent);
        }
        // The stage is worth having only if it decides most of these.
        assert!(decided > 19_900, "double-double decided {decided} of 20000");
        // Exactly cospherical integer points: the stage must not decide, the answer is zero.
        let q = [
            (3.0, 4.0, 0.0),
            (0.0, 3.0, 4.0),
            (4.0, 0.0, 3.0),
            (-5.0, 0.0, 0.0),
            (0.0, -4.0, 3.0),
        ]
        .map(|(x, y, z)| Point3::new(x, y, z));
        assert_eq!(insphere_exact(q[0], q[1], q[2], q[3], q[4]), Sign::Zero);
    }

    #[test]
    fn orientation_convention_of_the_unit_tetrahedron() {
        let o = Point3::ZERO;
        let (x, y, z) = (Point3::X, Point3::Y, Point3::Z);
        assert_eq!(orient3d(x, y, z, o), Sign::Positive);
        assert_eq!(orient3d(y, x, z, o), Sign::Negative);
        assert_eq!(orient3d(x, y, z, Point3::new(0.25, 0.25, 0.5)), Sign::Zero);
        assert_eq!(insphere(x, y, z, o, Point3::splat(0.25)), Sign::Positive);
        assert_eq!(insphere(x, y, z, o, Point3::splat(2.0)), Sign::Negative);
        assert_eq!(insphere(x, y, z, o, Point3::ONE), Sign::Zero);
    }

    #[test]
    fn orientation_is_exact_one_ulp_off_a_plane() {
        // d is exactly on the plane x + y + z = 1; one ulp up or down must be seen on either side,
        // which a plain floating-point evaluation of the determinant does not guarantee.
        let a = Point3::new(1.0, 0.0, 0.0);
        let b = Point3::new(0.0, 1.0, 0.0);
        let c = Point3::new(0.0, 0.0, 1.0);
        let z = 0.375f64;
        let d = Point3::new(0.3125, 0.3125, z);
        let up = Point3::new(d.x, d.y, f64::from_bits(z.to_bits() + 1));
        let down = Point3::new(d.x, d.y, f64::from_bits(z.to_bits() - 1));
        assert_eq!(orient3d(a, b, c, d), Sign::Zero);
        let s_up = orient3d(a, b, c, up);
        assert_ne!(s_up, Sign::Zero);
        assert_eq!(orient3d(a, b, c, down), s_up.flip());
        // Permutations flip or keep the sign consistently.
        assert_eq!(orient3d(b, a, c, up), s_up.flip());
        assert_eq!(orient3d(b, c, a, up), s_up);
    }

    #[test]
    fn filtered_predicates_agree_with_the_adaptive_ones() {
        // Small integer coordinates make many exact degeneracies; one-ulp nudges make near ones.
        let mut rng = XorShift::new(0x1234_5678_9abc_def0);
        let mut next = || rng.next_u64();
        for _ in 0..20000 {
            let mut p = [Point3::ZERO; 5];
            for q in &mut p {
                let r = next();
                *q = Point3::new((r % 3) as f64, (r >> 8 & 3) as f64, (r >> 16 & 3) as f64) * 0.1
                    + Point3::splat(1e6);
                if r >> 40 & 1 == 1 {
                    q.y = f64::from_bits(q.y.to_bits() + (r >> 50 & 3));
                }
            }
            let [a, b, c, d, e] = p;
            assert_eq!(orient3d(a, b, c, d), orient3d_exact(a, b, c, d));
            assert_eq!(insphere(a, b, c, d, e), insphere_exact(a, b, c, d, e));
        }
    }

    #[test]
    fn static_filter_agrees_with_the_adaptive_predicates() {
        // Near-degenerate configurations (one-ulp nudges of lattice points) inside a box whose
        // extent sets the static bounds, plus points far smaller than the box.
        let mut rng = XorShift::new(0x9e37_79b9_7f4a_7c15);
        let mut next = || rng.next_u64();
        let mut filter = StaticFilter::default();
        filter.include(Point3::splat(-1.0));
        filter.include(Point3::splat(3.0));
        for _ in 0..20000 {
            let scale = if next() & 1 == 0 { 1.0 } else { 1e-3 };
            let mut p = [Point3::ZERO; 5];
            for q in &mut p {
                let r = next();
                *q = Point3::new((r % 3) as f64, (r >> 8 & 3) as f64, (r >> 16 & 3) as f64) * scale;
                if r >> 40 & 1 == 1 {
                    q.z = f64::from_bits(q.z.to_bits() + (r >> 50 & 3));
                }
                filter.include(*q);
            }
            let [a, b, c, d, e] = p;
            assert_eq!(filter.orient3d(a, b, c, d), orient3d_exact(a, b, c, d));
            assert_eq!(
                filter.insphere(a, b, c, d, e),
                insphere_exact(a, b, c, d, e)
            );
        }
    }

    #[test]
    fn integer_shortcut_agrees_with_the_adaptive_predicates_on_a_grid() {
        // Exact ties everywhere (cospherical cubes, coplanar faces) and differences at the edge
        // of the shortcut's range.
        let coords = [0.0, 1.0, 2.0, 511.0, 512.0, 513.0, -512.0, 65536.0, 65537.0];
        let mut rng = XorShift::new(0x2545_f491_4f6c_dd1d);
        let mut pick = || {
            let state = rng.next_u64();
            let i = (state % coords.len() as u64) as usize;
            coords[i] * if state >> 63 == 1 { 1.0 } else { 0.5 }
        };
        for _ in 0..20000 {
            let p: [Point3; 5] = std::array::from_fn(|_| Point3::new(pick(), pick(), pick()));
            let [a, b, c, d, e] = p;
            assert_eq!(orient3d(a, b, c, d), orient3d_exact(a, b, c, d));
            assert_eq!(insphere(a, b, c, d, e), insphere_exact(a, b, c, d, e));
        }
    }
}
