//! Exact 2D predicates for the planar code (`Delaunay2`, `mesh2d`), returning `Ordering`: the
//! orientation and in-circle signs (adaptive arithmetic from `robust`), the lifting-map symbolic
//! perturbation that makes a planar Delaunay triangulation unique, and the exact diametral-disk
//! test (angle sign) that constraint meshing needs.

use super::Sign;
use super::double_double::{dd_add, dd_mul, dd_neg, fast_two_sum, two_diff, two_product, two_sum};
use super::exact::{expansions_are_exact, incircle_big};
use glam::DVec2;
use std::cmp::Ordering;

fn coord(p: DVec2) -> robust::Coord<f64> {
    robust::Coord { x: p.x, y: p.y }
}

/// Sign of the orientation of `(a, b, c)`: `Greater` when counter-clockwise, `Less` when clockwise,
/// `Equal` when exactly collinear.
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> Ordering {
    super::predicates::orient2d(a, b, c).cmp(&Sign::Zero)
}

/// Exact in-circle sign: `Greater` when `d` is strictly inside the circle through the
/// counter-clockwise triangle `(a, b, c)`, `Less` outside, `Equal` on it.
///
/// Three stages: the floating-point determinant with Shewchuk's first error bound; when that
/// cannot decide and the differences to `d` are exact, the exact determinant of those differences
/// by expansion arithmetic in small stack buffers; otherwise `robust`'s full adaptive evaluation.
/// The middle stage exists because near-cocircular split points (symmetric spikes) reach the
/// fallback often, and `robust` pays for zeroing kilobytes of scratch arrays on every such call.
#[inline]
pub fn incircle(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Ordering {
    let (ad, bd, cd) = (a - d, b - d, c - d);
    let bc = bd.perp_dot(cd);
    let ca = cd.perp_dot(ad);
    let ab = ad.perp_dot(bd);
    let (la, lb, lc) = (
        ad.length_squared(),
        bd.length_squared(),
        cd.length_squared(),
    );
    let det = la * bc + lb * ca + lc * ab;
    let permanent = la * ((bd.x * cd.y).abs() + (cd.x * bd.y).abs())
        + lb * ((cd.x * ad.y).abs() + (ad.x * cd.y).abs())
        + lc * ((ad.x * bd.y).abs() + (bd.x * ad.y).abs());
    // Shewchuk's bound holds without underflow or overflow: differences inside the expansion
    // range make every product exact up to rounding (a subnormal product times a huge lift
    // would not be).
    let in_range = |x: f64| x == 0.0 || (EXPANSION_RANGE.0..=EXPANSION_RANGE.1).contains(&x.abs());
    if det.abs() > INCIRCLE_ERROR * permanent
        && [ad.x, ad.y, bd.x, bd.y, cd.x, cd.y]
            .into_iter()
            .all(in_range)
    {
        return sign(det);
    }
    incircle_exact(a, b, c, d, permanent)
}

/// Shewchuk's in-circle error bounds (with ε = 2⁻⁵³): the floating-point determinant, relative to
/// the permanent (`A`); the exactly summed determinant of the rounded differences (`B`); the
/// latter corrected to first order in the differences' rounding errors (`C`, plus `RESULT` of it).
const EPS: f64 = f64::EPSILON / 2.0;
const INCIRCLE_ERROR: f64 = (10.0 + 96.0 * EPS) * EPS;
const INCIRCLE_ERROR_B: f64 = (4.0 + 48.0 * EPS) * EPS;
const INCIRCLE_ERROR_C: f64 = (44.0 + 576.0 * EPS) * EPS * EPS;
const RESULT_ERROR: f64 = (3.0 + 8.0 * EPS) * EPS;
/// Error bound of [`incircle_double_double`] relative to the permanent, with a factor-2 margin.
const INCIRCLE_ERROR_DD: f64 = 66.0 * EPS * EPS;

/// Differences whose magnitude lies outside this range are left to `robust`: inside it, no
/// product of the expansion stage can overflow or lose its rounding error to underflow.
const EXPANSION_RANGE: (f64, f64) = (1e-50, 1e50);

/// The in-circle sign when the first filter failed: Shewchuk's second and third adaptive stages
/// in stack buffers sized for them, then `robust`'s complete evaluation when those cannot decide.
#[cold]
#[inline(never)]
fn incircle_exact(a: DVec2, b: DVec2, c: DVec2, d: DVec2, permanent: f64) -> Ordering {
    let diffs = exact_differences(a, b, c, d);
    let in_range = |x: f64| x == 0.0 || (EXPANSION_RANGE.0..=EXPANSION_RANGE.1).contains(&x.abs());
    if diffs.iter().all(|&(hi, _)| in_range(hi)) {
        // Double-double arithmetic on the exact differences settles nearly every case the first
        // filter leaves, for a tenth of the cost of the exact expansions.
        let det = incircle_double_double(diffs);
        if det.abs() > INCIRCLE_ERROR_DD * permanent {
            return sign(det);
        }
        let [adx, ady, bdx, bdy, cdx, cdy] = diffs.map(|(hi, _)| hi);
        // Exact determinant of the rounded differences: the exact answer when they are exact,
        // since the determinant is translation invariant.
        let mut exact = Expansion::<96>::default();
        let row_a = lifted_row(adx, ady, (bdx, bdy), (cdx, cdy));
        let row_b = lifted_row(bdx, bdy, (cdx, cdy), (adx, ady));
        let row_c = lifted_row(cdx, cdy, (adx, ady), (bdx, bdy));
        let mut ab = Expansion::<64>::default();
        ab.set_sum(&row_a, &row_b);
        exact.set_sum(&ab, &row_c);
        let mut det: f64 = exact.as_slice().iter().sum();
        if det.abs() >= INCIRCLE_ERROR_B * permanent {
            return sign(det);
        }
        let [adxt, adyt, bdxt, bdyt, cdxt, cdyt] = diffs.map(|(_, lo)| lo);
        if [adxt, adyt, bdxt, bdyt, cdxt, cdyt] == [0.0; 6] {
            return sign(exact.top());
        }
        // First-order correction: the derivative of the determinant along the rounding errors.
        let bound = INCIRCLE_ERROR_C * permanent + RESULT_ERROR * det.abs();
        // Each point's difference and its rounding error, (x, y, x error, y error).
        type Difference = (f64, f64, f64, f64);
        let row = |(x, y, xt, yt): Difference, u: Difference, v: Difference| {
            let (ux, uy, uxt, uyt) = u;
            let (vx, vy, vxt, vyt) = v;
            (x * x + y * y) * ((ux * vyt + vy * uxt) - (uy * vxt + vx * uyt))
                + 2.0 * (x * xt + y * yt) * (ux * vy - uy * vx)
        };
        let (ad, bd, cd) = (
            (adx, ady, adxt, adyt),
            (bdx, bdy, bdxt, bdyt),
            (cdx, cdy, cdxt, cdyt),
        );
        det += row(ad, bd, cd) + row(bd, cd, ad) + row(cd, ad, bd);
        if det.abs() >= bound {
            return sign(det);
        }
    }
    if expansions_are_exact(&[a.x, a.y, b.x, b.y, c.x, c.y, d.x, d.y], 4) {
        sign(robust::incircle(coord(a), coord(b), coord(c), coord(d)))
    } else {
        incircle_big([a, b, c, d].map(|p| p.to_array())).cmp(&Sign::Zero)
    }
}

/// `a − d`, `b − d`, `c − d` coordinate by coordinate, each as an exact `(hi, lo)` pair.
fn exact_differences(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> [(f64, f64); 6] {
    [
        two_diff(a.x, d.x),
        two_diff(a.y, d.y),
        two_diff(b.x, d.x),
        two_diff(b.y, d.y),
        two_diff(c.x, d.x),
        two_diff(c.y, d.y),
    ]
}

/// The in-circle determinant of the exact differences `(hi, lo)` in double-double arithmetic.
/// Each operation has a relative error of at most 7u² (u = 2⁻⁵³; Joldes, Muller, Popescu,
/// "Tight and rigorous error bounds for basic building blocks of double-word arithmetic", 2017),
/// so the result is within 33u² of the permanent: [`INCIRCLE_ERROR_DD`] allows twice that.
fn incircle_double_double(d: [(f64, f64); 6]) -> f64 {
    let [ax, ay, bx, by, cx, cy] = d;
    let lift = |x, y| dd_add(dd_mul(x, x), dd_mul(y, y));
    let cross = |ux, uy, vx, vy| dd_add(dd_mul(ux, vy), dd_neg(dd_mul(uy, vx)));
    let row_a = dd_mul(lift(ax, ay), cross(bx, by, cx, cy));
    let row_b = dd_mul(lift(bx, by), cross(cx, cy, ax, ay));
    let row_c = dd_mul(lift(cx, cy), cross(ax, ay, bx, by));
    let (hi, lo) = dd_add(dd_add(row_a, row_b), row_c);
    hi + lo
}

/// `(x² + y²) · (u × v)` exactly, for the in-circle row of a point at `(x, y)` relative to `d`.
fn lifted_row(x: f64, y: f64, u: (f64, f64), v: (f64, f64)) -> Expansion<32> {
    let (p1, p0) = two_product(u.0, v.1);
    let (q1, q0) = two_product(v.0, u.1);
    let mut minor = Expansion::<4>::default();
    minor.set_two_two_diff((p1, p0), (q1, q0));
    let mut t8 = Expansion::<8>::default();
    let mut xx = Expansion::<16>::default();
    let mut yy = Expansion::<16>::default();
    t8.set_scaled(&minor, x);
    xx.set_scaled(&t8, x);
    t8.set_scaled(&minor, y);
    yy.set_scaled(&t8, y);
    let mut row = Expansion::<32>::default();
    row.set_sum(&xx, &yy);
    row
}

fn sign(v: f64) -> Ordering {
    v.partial_cmp(&0.0).unwrap_or(Ordering::Equal)
}

/// The total order on points used by the perturbation: lexicographic on (x, y). It depends only on
/// coordinates, never on insertion order, so the perturbed triangulation is order independent.
/// Collinear points are also sorted along their line by this order, so -0 and +0 must compare
/// equal as the predicates see them (adding +0 turns -0 into +0): otherwise points of a vertical
/// line at x = -0 and x = +0 are sorted by sign before height.
pub fn lex_cmp(a: DVec2, b: DVec2) -> Ordering {
    (a.x + 0.0)
        .total_cmp(&(b.x + 0.0))
        .then((a.y + 0.0).total_cmp(&(b.y + 0.0)))
}

/// In-circle with symbolic perturbation: never `Equal` for four distinct points of which
/// `(a, b, c)` are not collinear.
///
/// Each point's lifted height `x² + y²` is raised by an infinitesimal that is larger for points later
/// in [`lex_cmp`] order. The sign of the perturbed determinant is the sign of the first non-zero
/// coefficient, taking points from the largest to the smallest; the coefficient of point `d` is
/// `-orient(a, b, c)`, and the others follow from the antisymmetry of the determinant.
pub fn incircle_perturbed(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Ordering {
    let exact = incircle(a, b, c, d);
    if exact != Ordering::Equal {
        return exact;
    }
    let pts = [a, b, c, d];
    let mut order = [0usize, 1, 2, 3];
    order.sort_unstable_by(|&i, &j| lex_cmp(pts[j], pts[i]));
    for &i in &order {
        let s = match i {
            0 => orient2d(b, c, d),
            1 => orient2d(a, c, d).reverse(),
            2 => orient2d(a, b, d),
            _ => orient2d(a, b, c).reverse(),
        };
        if s != Ordering::Equal {
            return s;
        }
    }
    Ordering::Equal
}

/// Circumcentre of the triangle `(a, b, c)`, computed relative to `a` for accuracy.
pub fn circumcenter(a: DVec2, b: DVec2, c: DVec2) -> DVec2 {
    let ab = b - a;
    let ac = c - a;
    let d = 2.0 * ab.perp_dot(ac);
    let ab2 = ab.length_squared();
    let ac2 = ac.length_squared();
    a + DVec2::new(ac.y * ab2 - ab.y * ac2, ab.x * ac2 - ac.x * ab2) / d
}

/// A non-overlapping floating-point expansion of at most `N` components, in increasing
/// magnitude, without zeros: its exact value is the sum of its components and its sign that of
/// the largest one. A fixed-size stack buffer sized for the one formula that fills it.
struct Expansion<const N: usize> {
    terms: [f64; N],
    len: usize,
}

impl<const N: usize> Default for Expansion<N> {
    fn default() -> Self {
        Expansion {
            terms: [0.0; N],
            len: 0,
        }
    }
}

impl<const N: usize> Expansion<N> {
    fn as_slice(&self) -> &[f64] {
        &self.terms[..self.len]
    }

    fn push(&mut self, x: f64) {
        if x != 0.0 {
            self.terms[self.len] = x;
            self.len += 1;
        }
    }

    /// The component of largest magnitude (zero for an empty expansion): it has the sign of the sum.
    fn top(&self) -> f64 {
        self.as_slice().last().copied().unwrap_or(0.0)
    }

    /// Adds `b` exactly (Shewchuk's grow-expansion with zero elimination); needs `len < N`.
    fn grow(&mut self, b: f64) {
        let mut q = b;
        let mut kept = 0;
        for i in 0..self.len {
            let (sum, lo) = two_sum(q, self.terms[i]);
            if lo != 0.0 {
                self.terms[kept] = lo;
                kept += 1;
            }
            q = sum;
        }
        self.len = kept;
        self.push(q);
    }

    /// `(a1 + a0) - (b1 + b0)` for two exact products.
    fn set_two_two_diff(&mut self, a: (f64, f64), b: (f64, f64)) {
        self.len = 0;
        let mut e = Expansion::<2>::default();
        e.push(a.1);
        e.push(a.0);
        let mut f = Expansion::<2>::default();
        f.push(-b.1);
        f.push(-b.0);
        self.set_sum(&e, &f);
    }

    /// `e · b` exactly (Shewchuk's scale-expansion with zero elimination); needs `N ≥ 2 M`.
    fn set_scaled<const M: usize>(&mut self, e: &Expansion<M>, b: f64) {
        self.len = 0;
        let e = e.as_slice();
        let Some((&first, rest)) = e.split_first() else {
            return;
        };
        let (mut q, lo) = two_product(first, b);
        self.push(lo);
        for &x in rest {
            let (p1, p0) = two_product(x, b);
            let (sum, lo) = two_sum(q, p0);
            self.push(lo);
            let (nq, lo) = fast_two_sum(p1, sum);
            self.push(lo);
            q = nq;
        }
        self.push(q);
    }

    /// `e + f` exactly (Shewchuk's fast expansion sum with zero elimination: merge by magnitude,
    /// then accumulate); needs `N ≥ M + K`.
    fn set_sum<const M: usize, const K: usize>(&mut self, e: &Expansion<M>, f: &Expansion<K>) {
        self.len = 0;
        let (e, f) = (e.as_slice(), f.as_slice());
        let (mut i, mut j) = (0, 0);
        let mut next = || {
            let take_e = match (e.get(i), f.get(j)) {
                (Some(x), Some(y)) => x.abs() < y.abs(),
                (Some(_), None) => true,
                (None, Some(_)) => false,
                (None, None) => return None,
            };
            if take_e {
                i += 1;
                Some(e[i - 1])
            } else {
                j += 1;
                Some(f[j - 1])
            }
        };
        let Some(mut q) = next() else {
            return;
        };
        if let Some(g) = next() {
            let (nq, lo) = fast_two_sum(g, q);
            self.push(lo);
            q = nq;
            while let Some(g) = next() {
                let (nq, lo) = two_sum(q, g);
                self.push(lo);
                q = nq;
            }
        }
        self.push(q);
    }
}

/// Exact sign of `(a - p) · (b - p)`: `Less` when the angle `a p b` is obtuse (p strictly inside
/// the circle with diameter `ab`), `Equal` when right (p on that circle), `Greater` when acute.
pub fn dot_sign(p: DVec2, a: DVec2, b: DVec2) -> Ordering {
    let fast = (a - p).dot(b - p);
    let bound = 8.0 * f64::EPSILON * ((a - p).abs().dot((b - p).abs()) + p.abs().dot(p.abs()));
    if fast.abs() > bound {
        return sign(fast);
    }
    // (a - p)·(b - p) = a·b - a·p - p·b + p·p, each product split exactly.
    let mut e = Expansion::<16>::default();
    for (x, y, s) in [
        (a.x, b.x, 1.0),
        (a.y, b.y, 1.0),
        (a.x, p.x, -1.0),
        (a.y, p.y, -1.0),
        (p.x, b.x, -1.0),
        (p.y, b.y, -1.0),
        (p.x, p.x, 1.0),
        (p.y, p.y, 1.0),
    ] {
        let (hi, lo) = two_product(s * x, y);
        e.grow(hi);
        e.grow(lo);
    }
    sign(e.top())
}

#[cfg(test)]
mod tests;
