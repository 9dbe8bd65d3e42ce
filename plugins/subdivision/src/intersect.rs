//! Segment–patch intersection: recursive splitting of the patch while the box of its control
//! points (which contains it) meets the segment, then Newton's method on the exact polynomial
//! of the regular piece reached, from the centre of the piece.

use crate::Scheme;
use crate::bezier::{Affine, Bezier, in_domain};
use crate::patch::{MAX_DEPTH, Surface};
use glam::{DMat3, DVec2, DVec3};

/// Splits of a polynomial piece before Newton's method is tried (smaller pieces give a better
/// start), and at most (when Newton's method does not converge in a piece, it is split more).
/// The oracle splits its regular pieces `NEWTON_DEPTH` times ahead ([`crossings`]).
pub(crate) const NEWTON_DEPTH: u32 = 2;
const MAX_SPLITS: u32 = 10;
/// Newton iterations at most.
const NEWTON_STEPS: u32 = 16;

/// A crossing found on one patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Crossing {
    pub t: f64,
    pub point: DVec3,
}

/// The query: the segment `a + t d`, `t ∈ [0, 1]`, the slack added to boxes (rounding), and
/// the size below which a piece is a point (not split: at most `MAX_DEPTH` steps, and pieces
/// smaller than the slack would all meet the segment).
pub(crate) struct Query {
    pub a: DVec3,
    pub d: DVec3,
    pub slack: f64,
    pub point_size: f64,
}

impl Query {
    /// The crossing of a piece too small to split: where the segment passes its centre.
    fn point_crossing(&self, lo: DVec3, hi: DVec3) -> Crossing {
        let c = 0.5 * (lo + hi);
        let t = ((c - self.a).dot(self.d) / self.d.length_squared()).clamp(0.0, 1.0);
        Crossing {
            t,
            point: self.a + t * self.d,
        }
    }

    /// Does the segment meet the box `[lo, hi]` widened by the slack? (slab test)
    fn meets(&self, lo: DVec3, hi: DVec3) -> bool {
        let (lo, hi) = (lo - DVec3::splat(self.slack), hi + DVec3::splat(self.slack));
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for k in 0..3 {
            let (a, d) = (self.a[k], self.d[k]);
            if d == 0.0 {
                if a < lo[k] || a > hi[k] {
                    return false;
                }
                continue;
            }
            let (mut s0, mut s1) = ((lo[k] - a) / d, (hi[k] - a) / d);
            if s0 > s1 {
                std::mem::swap(&mut s0, &mut s1);
            }
            t0 = t0.max(s0);
            t1 = t1.min(s1);
            if t0 > t1 {
                return false;
            }
        }
        true
    }
}

/// Every crossing of the query with the surface, whose box is `bounds`, appended to `out`
/// (duplicates on shared borders of pieces are possible; the caller merges them). A regular
/// `surface` is a piece already split [`NEWTON_DEPTH`] times: Newton's method may start on it.
pub(crate) fn crossings(
    scheme: Scheme,
    surface: &Surface,
    bounds: (DVec3, DVec3),
    q: &Query,
    out: &mut Vec<Crossing>,
) {
    visit(scheme, surface, bounds, q, 0, NEWTON_DEPTH, out);
}

/// `split` is how many times a regular `surface` was split already. The boxes travel with the
/// pieces: a Bézier piece's box is a pass over its control points, and every query asks for
/// it.
fn visit(
    scheme: Scheme,
    surface: &Surface,
    (lo, hi): (DVec3, DVec3),
    q: &Query,
    depth: u32,
    split: u32,
    out: &mut Vec<Crossing>,
) {
    if !q.meets(lo, hi) {
        return;
    }
    match surface {
        Surface::Regular(b) => visit_piece(b, b, &Affine::IDENTITY, (lo, hi), q, split, out),
        Surface::Irregular(_) if depth >= MAX_DEPTH || (hi - lo).length() <= q.point_size => {
            out.push(q.point_crossing(lo, hi));
        }
        Surface::Irregular(ring) => {
            for (_, child) in ring.children(scheme) {
                visit(scheme, child, child.bounds(), q, depth + 1, 0, out);
            }
        }
    }
}

/// `piece`, whose box is `[lo, hi]`, is `root` over the part `map` of its domain.
fn visit_piece(
    root: &Bezier,
    piece: &Bezier,
    map: &Affine,
    (lo, hi): (DVec3, DVec3),
    q: &Query,
    depth: u32,
    out: &mut Vec<Crossing>,
) {
    if !q.meets(lo, hi) || piece.misses_line(q.a, q.d, q.slack) {
        return;
    }
    let scheme = root.scheme;
    if (hi - lo).length() <= q.point_size {
        out.push(q.point_crossing(lo, hi));
        return;
    }
    // Newton's method finds one crossing: only in a piece crossed at most once, or as a last
    // resort in the smallest pieces.
    let single = depth >= NEWTON_DEPTH && piece.transversal(q.d);
    if single || depth >= MAX_SPLITS {
        let centre = match scheme {
            Scheme::CatmullClark => DVec2::splat(0.5),
            Scheme::Loop => DVec2::splat(1.0 / 3.0),
        };
        if let Some((uv, t)) = newton(root, map.apply(centre), q) {
            let local = map.invert(uv);
            if in_domain(scheme, local, 1e-6) && in_domain(scheme, uv, 1e-12) {
                // The line crosses the piece here and nowhere else: the segment does when the
                // crossing lies within it (most short queries beside the surface end before).
                if (-1e-12..=1.0 + 1e-12).contains(&t) {
                    out.push(Crossing {
                        t: t.clamp(0.0, 1.0),
                        point: root.eval(uv).point,
                    });
                }
                return;
            }
        }
        // A transversal piece where Newton's method finds nothing from two levels of starts
        // is not crossed.
        if depth >= MAX_SPLITS || (single && depth >= NEWTON_DEPTH + 2) {
            return;
        }
    }
    for (d, sub) in piece.children() {
        visit_piece(
            root,
            &sub,
            &map.compose(&d),
            sub.bounds(),
            q,
            depth + 1,
            out,
        );
    }
}

/// Solves `S(u, v) = a + t d` from `start`: where the query's line crosses the surface (`t`
/// outside `[0, 1]` off the segment), when it converges.
fn newton(patch: &Bezier, start: DVec2, q: &Query) -> Option<(DVec2, f64)> {
    let mut uv = start;
    let mut e = patch.eval(uv);
    let mut t = ((e.point - q.a).dot(q.d) / q.d.length_squared()).clamp(0.0, 1.0);
    for _ in 0..NEWTON_STEPS {
        let r = e.point - q.a - t * q.d;
        let j = DMat3::from_cols(e.du, e.dv, -q.d);
        let det = j.determinant();
        if !det.is_finite() || det.abs() < 1e-300 {
            return None;
        }
        let step = j.inverse() * r;
        uv -= DVec2::new(step.x, step.y);
        t -= step.z;
        if !(uv.is_finite() && t.is_finite()) || uv.abs().max_element() > 3.0 {
            return None;
        }
        // Converged when the step moves the point (on the surface and on the line) by no more
        // than rounding: measured in space, whatever the sizes of the patch and the segment.
        let tol = 1e-14 * (1.0 + e.point.abs().max_element());
        let moved = (step.x * e.du + step.y * e.dv)
            .length()
            .max(step.z.abs() * q.d.length());
        if moved <= tol || r.length() <= tol {
            return Some((uv, t));
        }
        e = patch.eval(uv);
    }
    None
}
