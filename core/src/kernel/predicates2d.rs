//! Exact 2D predicates for the planar code (`Delaunay2`, `mesh2d`), returning `Ordering`: the
//! orientation and in-circle signs (adaptive arithmetic from `robust`), the lifting-map symbolic
//! perturbation that makes a planar Delaunay triangulation unique, and the exact diametral-disk
//! test (angle sign) that constraint meshing needs.

use glam::DVec2;
use std::cmp::Ordering;

fn coord(p: DVec2) -> robust::Coord<f64> {
    robust::Coord { x: p.x, y: p.y }
}

/// Sign of the orientation of `(a, b, c)`: `Greater` when counter-clockwise, `Less` when clockwise,
/// `Equal` when exactly collinear.
pub fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> Ordering {
    sign(robust::orient2d(coord(a), coord(b), coord(c)))
}

/// Exact in-circle sign: `Greater` when `d` is strictly inside the circle through the
/// counter-clockwise triangle `(a, b, c)`, `Less` outside, `Equal` on it.
pub fn incircle(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> Ordering {
    sign(robust::incircle(coord(a), coord(b), coord(c), coord(d)))
}

fn sign(v: f64) -> Ordering {
    v.partial_cmp(&0.0).unwrap_or(Ordering::Equal)
}

/// The total order on points used by the perturbation: lexicographic on (x, y). It depends only on
/// coordinates, never on insertion order, so the perturbed triangulation is order independent.
/// Collinear points are also sorted along their line by this order.
pub fn lex_cmp(a: DVec2, b: DVec2) -> Ordering {
    a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y))
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

/// `a * b` as an exact unevaluated sum `hi + lo`.
fn two_product(a: f64, b: f64) -> (f64, f64) {
    let hi = a * b;
    (hi, a.mul_add(b, -hi))
}

/// Adds `b` to the non-overlapping expansion `e` (increasing magnitude), exactly.
fn grow_expansion(e: &mut Vec<f64>, mut b: f64) {
    let mut out = Vec::with_capacity(e.len() + 1);
    for &x in e.iter() {
        let s = b + x;
        let bv = s - b;
        let err = (b - (s - bv)) + (x - bv);
        if err != 0.0 {
            out.push(err);
        }
        b = s;
    }
    if b != 0.0 || out.is_empty() {
        out.push(b);
    }
    *e = out;
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
    let mut e = Vec::with_capacity(16);
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
        grow_expansion(&mut e, hi);
        grow_expansion(&mut e, lo);
    }
    e.iter()
        .rev()
        .find(|&&x| x != 0.0)
        .map_or(Ordering::Equal, |&x| sign(x))
}
