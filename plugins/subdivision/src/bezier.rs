//! Bézier patches: the closed form of the limit surface over a regular face (bicubic for
//! Catmull–Clark, quartic triangles for Loop), their evaluation with derivatives, and their
//! restriction to a part of the parameter domain (for the intersection's recursive splitting).
//!
//! Every fit goes through one interpolation: values at a fixed set of dyadic nodes, times the
//! inverse of the Bernstein collocation matrix at those nodes. Dyadic, because limit positions
//! are known exactly at the vertices of subdivided nets.

use crate::Scheme;
use glam::{DVec2, DVec3};
use std::sync::OnceLock;

/// Number of Bézier control points of a patch: 16 (bicubic), 15 (quartic triangle).
pub(crate) fn bezier_len(scheme: Scheme) -> usize {
    match scheme {
        Scheme::CatmullClark => 16,
        Scheme::Loop => 15,
    }
}

/// A polynomial patch over the unit square (`u`, `v` ∈ [0, 1]) or the unit triangle
/// (`u`, `v` ≥ 0, `u + v` ≤ 1).
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct Bezier {
    pub scheme: Scheme,
    /// Square: index `i + 4 j` for `u`ⁱ-side `i`, `v`-side `j`. Triangle: the order of
    /// [`triangle_indices`].
    pub points: [DVec3; 16],
}

/// A position with its two parameter derivatives.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Eval {
    pub point: DVec3,
    pub du: DVec3,
    pub dv: DVec3,
}

/// The `(i, j)` exponents of `u` and `v` of the quartic Bernstein polynomials, in storage order
/// (the exponent of `w = 1 − u − v` is `4 − i − j`).
pub(crate) fn triangle_indices() -> [(u32, u32); 15] {
    let mut out = [(0, 0); 15];
    let mut n = 0;
    for j in 0..=4 {
        for i in 0..=4 - j {
            out[n] = (i, j);
            n += 1;
        }
    }
    out
}

fn cubic(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * t * s,
            6.0 * t * s - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

/// Basis values and their `u`, `v` derivatives at `(u, v)`.
pub(crate) fn basis(scheme: Scheme, p: DVec2) -> [[f64; 16]; 3] {
    let mut out = [[0.0; 16]; 3];
    match scheme {
        Scheme::CatmullClark => {
            let ((bu, du), (bv, dv)) = (cubic(p.x), cubic(p.y));
            for j in 0..4 {
                for i in 0..4 {
                    out[0][i + 4 * j] = bu[i] * bv[j];
                    out[1][i + 4 * j] = du[i] * bv[j];
                    out[2][i + 4 * j] = bu[i] * dv[j];
                }
            }
        }
        Scheme::Loop => {
            // Power tables: the hot path of Newton's method on Loop patches (`powi` was most of
            // a query's time).
            let powers = |x: f64| {
                let x2 = x * x;
                [1.0, x, x2, x2 * x, x2 * x2]
            };
            let (u, v) = (p.x, p.y);
            let (pu, pv, pw) = (powers(u), powers(v), powers(1.0 - u - v));
            // x^(n-1) times n: the derivative's factor, zero for n = 0.
            let lower = |pw: &[f64; 5], n: usize| if n == 0 { 0.0 } else { n as f64 * pw[n - 1] };
            for (n, &(i, j, c)) in LOOP_TERMS.iter().enumerate() {
                let k = 4 - i - j;
                out[0][n] = c * pu[i] * pv[j] * pw[k];
                out[1][n] = c * pv[j] * (lower(&pu, i) * pw[k] - pu[i] * lower(&pw, k));
                out[2][n] = c * pu[i] * (lower(&pv, j) * pw[k] - pv[j] * lower(&pw, k));
            }
        }
    }
    out
}

/// The quartic Bernstein terms in storage order: exponents of `u` and `v` ([`triangle_indices`])
/// and the multinomial coefficient `4! / (i! j! k!)`.
const LOOP_TERMS: [(usize, usize, f64); 15] = {
    const FACT: [usize; 5] = [1, 1, 2, 6, 24];
    let mut out = [(0, 0, 0.0); 15];
    let (mut n, mut j) = (0, 0);
    while j <= 4 {
        let mut i = 0;
        while i <= 4 - j {
            out[n] = (i, j, (24 / (FACT[i] * FACT[j] * FACT[4 - i - j])) as f64);
            n += 1;
            i += 1;
        }
        j += 1;
    }
    out
};

/// For every quartic Bézier point `(i, j)` with `i + j ≤ 3`: its index and those of `(i + 1, j)`
/// and `(i, j + 1)`, in storage order.
const LOOP_STEPS: [(usize, usize, usize); 10] = {
    // Row `j` holds 5 − j points, after j (11 − j) / 2 others.
    const fn index(i: usize, j: usize) -> usize {
        j * (11 - j) / 2 + i
    }
    let mut out = [(0, 0, 0); 10];
    let (mut m, mut j) = (0, 0);
    while j <= 3 {
        let mut i = 0;
        while i <= 3 - j {
            out[m] = (index(i, j), index(i + 1, j), index(i, j + 1));
            m += 1;
            i += 1;
        }
        j += 1;
    }
    out
};

/// The dyadic nodes the fits interpolate at: `{0, ¼, ¾, 1}²` on the square, the quarter
/// lattice on the triangle.
pub(crate) fn fit_nodes(scheme: Scheme) -> Vec<DVec2> {
    match scheme {
        Scheme::CatmullClark => {
            const T: [f64; 4] = [0.0, 0.25, 0.75, 1.0];
            (0..16).map(|n| DVec2::new(T[n % 4], T[n / 4])).collect()
        }
        Scheme::Loop => triangle_indices()
            .iter()
            .map(|&(i, j)| DVec2::new(i as f64, j as f64) / 4.0)
            .collect(),
    }
}

/// The inverse of the collocation matrix (basis `b` at node `n` in row `n`), row-major: Bézier
/// point `b` is `Σ_n inverse[b][n] · value(node n)`.
pub(crate) fn fit_inverse(scheme: Scheme) -> &'static [Vec<f64>] {
    static CACHE: [OnceLock<Vec<Vec<f64>>>; 2] = [OnceLock::new(), OnceLock::new()];
    CACHE[scheme as usize].get_or_init(|| {
        let n = bezier_len(scheme);
        let rows: Vec<Vec<f64>> = fit_nodes(scheme)
            .iter()
            .map(|&p| basis(scheme, p)[0][..n].to_vec())
            .collect();
        invert(rows)
    })
}

/// Gauss–Jordan inverse with partial pivoting of a small well-conditioned matrix (the
/// collocation matrices are fixed and invertible; a zero pivot would be a programming error,
/// left as a zero row rather than a panic).
fn invert(mut a: Vec<Vec<f64>>) -> Vec<Vec<f64>> {
    let n = a.len();
    let mut inv: Vec<Vec<f64>> = (0..n)
        .map(|i| (0..n).map(|j| f64::from(u8::from(i == j))).collect())
        .collect();
    for col in 0..n {
        let pivot = (col..n)
            .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
            .unwrap_or(col);
        a.swap(col, pivot);
        inv.swap(col, pivot);
        let d = a[col][col];
        if d == 0.0 {
            continue;
        }
        for j in 0..n {
            a[col][j] /= d;
            inv[col][j] /= d;
        }
        for r in 0..n {
            if r != col {
                let f = a[r][col];
                if f != 0.0 {
                    for j in 0..n {
                        a[r][j] -= f * a[col][j];
                        inv[r][j] -= f * inv[col][j];
                    }
                }
            }
        }
    }
    inv
}

impl Bezier {
    /// The patch interpolating `values` at [`fit_nodes`].
    pub fn fit(scheme: Scheme, values: &[DVec3]) -> Bezier {
        let inverse = fit_inverse(scheme);
        let mut points = [DVec3::ZERO; 16];
        for (b, row) in inverse.iter().enumerate() {
            points[b] = row.iter().zip(values).map(|(&w, &p)| w * p).sum();
        }
        Bezier { scheme, points }
    }

    pub fn len(&self) -> usize {
        bezier_len(self.scheme)
    }

    pub fn eval(&self, p: DVec2) -> Eval {
        let b = basis(self.scheme, p);
        let mut e = Eval {
            point: DVec3::ZERO,
            du: DVec3::ZERO,
            dv: DVec3::ZERO,
        };
        for (n, &q) in self.points[..self.len()].iter().enumerate() {
            e.point += b[0][n] * q;
            e.du += b[1][n] * q;
            e.dv += b[2][n] * q;
        }
        e
    }

    /// The patches over the children of the reference domain ([`child_domains`], in order):
    /// de Casteljau halving in both directions for the square, fixed linear maps for the
    /// triangle ([`loop_child_maps`]); exact both, and the hot path of segment queries.
    pub fn children(&self) -> [(Affine, Bezier); 4] {
        let domains = child_domains(self.scheme);
        if self.scheme == Scheme::Loop {
            let maps = loop_child_maps();
            return std::array::from_fn(|k| {
                let mut points = [DVec3::ZERO; 16];
                for (b, row) in maps[k].iter().enumerate() {
                    for (&w, &p) in row.iter().zip(&self.points) {
                        if w != 0.0 {
                            points[b] += w * p;
                        }
                    }
                }
                (
                    domains[k],
                    Bezier {
                        scheme: self.scheme,
                        points,
                    },
                )
            });
        }
        // The 7 × 7 net of the four quadrants: halve every row, then every column.
        let mut rows = [[DVec3::ZERO; 7]; 4];
        for (j, row) in rows.iter_mut().enumerate() {
            let p: [DVec3; 4] = std::array::from_fn(|i| self.points[i + 4 * j]);
            *row = halve(p);
        }
        let mut grid = [DVec3::ZERO; 49];
        for i in 0..7 {
            let column = halve(std::array::from_fn(|j| rows[j][i]));
            for (j, &q) in column.iter().enumerate() {
                grid[i + 7 * j] = q;
            }
        }
        let at = square_child_nodes();
        std::array::from_fn(|k| {
            (
                domains[k],
                Bezier {
                    scheme: self.scheme,
                    points: std::array::from_fn(|n| grid[at[k][n]]),
                },
            )
        })
    }

    /// The same surface over the part `origin + s·du + t·dv` of the domain, as a patch in
    /// `(s, t)`.
    pub fn restrict(&self, map: &Affine) -> Bezier {
        let values: Vec<DVec3> = fit_nodes(self.scheme)
            .iter()
            .map(|&n| self.eval(map.apply(n)).point)
            .collect();
        Bezier::fit(self.scheme, &values)
    }

    /// Is the patch transversal to direction `d` everywhere, so that a line along `d` crosses it
    /// at most once (for a piece small against its curvature)? Sufficient test: `S_u` and `S_v`
    /// are positive combinations of the differences of neighbouring control points, so if every
    /// pair of differences has a triple product with `d` of one strict sign, so has
    /// `(S_u × S_v) · d` (the projection along `d` never folds).
    pub fn transversal(&self, d: DVec3) -> bool {
        let p = &self.points;
        // Differences along `u`, and `Δv × d` for the differences along `v`: then each triple
        // product is one dot product.
        let mut du = [DVec3::ZERO; 12];
        let mut dv_d = [DVec3::ZERO; 12];
        let n = match self.scheme {
            Scheme::CatmullClark => {
                for j in 0..4 {
                    for i in 0..3 {
                        du[3 * j + i] = p[i + 1 + 4 * j] - p[i + 4 * j];
                        dv_d[3 * j + i] = (p[j + 4 * (i + 1)] - p[j + 4 * i]).cross(d);
                    }
                }
                12
            }
            Scheme::Loop => {
                for (m, &(at, right, up)) in LOOP_STEPS.iter().enumerate() {
                    du[m] = p[right] - p[at];
                    dv_d[m] = (p[up] - p[at]).cross(d);
                }
                LOOP_STEPS.len()
            }
        };
        let sign = du[0].dot(dv_d[0]);
        if sign == 0.0 {
            return false;
        }
        for a in &du[..n] {
            for b in &dv_d[..n] {
                let s = a.dot(*b);
                if s == 0.0 || (s > 0.0) != (sign > 0.0) {
                    return false;
                }
            }
        }
        true
    }

    /// Does the line `a + t d` pass beside the patch? Sufficient test: across `d`, the control
    /// points (whose hull holds the patch) all lie more than `slack` to one side of the line
    /// along one of four directions 45° apart. Most pieces a short query's box meets lie beside
    /// it, and this costs less than Newton's method.
    pub fn misses_line(&self, a: DVec3, d: DVec3, slack: f64) -> bool {
        let (e1, e2) = d.normalize_or_zero().any_orthonormal_pair();
        let axes = [e1, e2, e1 + e2, e1 - e2];
        let mut lo = [f64::INFINITY; 4];
        let mut hi = [f64::NEG_INFINITY; 4];
        for p in &self.points[..self.len()] {
            let r = *p - a;
            for (k, w) in axes.iter().enumerate() {
                let s = w.dot(r);
                lo[k] = lo[k].min(s);
                hi[k] = hi[k].max(s);
            }
        }
        // The diagonal axes are √2 long: their slack too.
        (0..4).any(|k| {
            let slack = if k < 2 {
                slack
            } else {
                slack * std::f64::consts::SQRT_2
            };
            lo[k] > slack || hi[k] < -slack
        })
    }

    /// Box of the control points, which contains the patch (Bernstein bases are non-negative
    /// and sum to one).
    pub fn bounds(&self) -> (DVec3, DVec3) {
        bounds(&self.points[..self.len()])
    }
}

/// A cubic's Bézier points split at one half: the 7 points of both halves (the middle one
/// shared).
fn halve(p: [DVec3; 4]) -> [DVec3; 7] {
    let m01 = 0.5 * (p[0] + p[1]);
    let m12 = 0.5 * (p[1] + p[2]);
    let m23 = 0.5 * (p[2] + p[3]);
    let a = 0.5 * (m01 + m12);
    let b = 0.5 * (m12 + m23);
    let mid = 0.5 * (a + b);
    [p[0], m01, a, mid, b, m23, p[3]]
}

/// The smallest box around `points`.
pub(crate) fn bounds(points: &[DVec3]) -> (DVec3, DVec3) {
    points
        .iter()
        .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &p| {
            (lo.min(p), hi.max(p))
        })
}

/// A map of the parameter plane, `origin + s·du + t·dv`: a child's domain in its parent's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Affine {
    pub origin: DVec2,
    pub du: DVec2,
    pub dv: DVec2,
}

impl Affine {
    pub const IDENTITY: Affine = Affine {
        origin: DVec2::ZERO,
        du: DVec2::X,
        dv: DVec2::Y,
    };

    /// The map sending the reference corners `(0,0)`, `(1,0)` and the last one (`(0,1)`) to
    /// `corners[0]`, `corners[1]` and `corners[last]`.
    pub fn of_corners(corners: &[DVec2]) -> Affine {
        let o = corners[0];
        Affine {
            origin: o,
            du: corners[1] - o,
            dv: corners[corners.len() - 1] - o,
        }
    }

    pub fn apply(&self, p: DVec2) -> DVec2 {
        self.origin + p.x * self.du + p.y * self.dv
    }

    /// `self` after `inner`: first `inner`, then `self`.
    pub fn compose(&self, inner: &Affine) -> Affine {
        Affine {
            origin: self.apply(inner.origin),
            du: inner.du.x * self.du + inner.du.y * self.dv,
            dv: inner.dv.x * self.du + inner.dv.y * self.dv,
        }
    }

    /// The preimage of `p` (the maps used are rotations and halvings, never singular).
    pub fn invert(&self, p: DVec2) -> DVec2 {
        let det = self.du.perp_dot(self.dv);
        let q = p - self.origin;
        DVec2::new(q.perp_dot(self.dv), self.du.perp_dot(q)) / det
    }
}

/// The corners of the reference domain: the unit square or the unit triangle.
pub(crate) fn reference_corners(scheme: Scheme) -> &'static [DVec2] {
    const SQUARE: [DVec2; 4] = [
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(1.0, 1.0),
        DVec2::new(0.0, 1.0),
    ];
    const TRIANGLE: [DVec2; 3] = [
        DVec2::new(0.0, 0.0),
        DVec2::new(1.0, 0.0),
        DVec2::new(0.0, 1.0),
    ];
    match scheme {
        Scheme::CatmullClark => &SQUARE,
        Scheme::Loop => &TRIANGLE,
    }
}

/// Is `p` in the reference domain, up to `slack`?
pub(crate) fn in_domain(scheme: Scheme, p: DVec2, slack: f64) -> bool {
    let unit = |x: f64| (-slack..=1.0 + slack).contains(&x);
    match scheme {
        Scheme::CatmullClark => unit(p.x) && unit(p.y),
        Scheme::Loop => p.x >= -slack && p.y >= -slack && p.x + p.y <= 1.0 + slack,
    }
}

/// The children of the reference face after one subdivision step, in the order the net's
/// subdivision creates them, each as its corners in the parent's parameters.
pub(crate) fn child_domains(scheme: Scheme) -> &'static [Affine; 4] {
    static CACHE: [OnceLock<[Affine; 4]>; 2] = [OnceLock::new(), OnceLock::new()];
    CACHE[scheme as usize].get_or_init(|| {
        let c = reference_corners(scheme);
        let n = c.len();
        let mid = |a: usize, b: usize| 0.5 * (c[a] + c[b]);
        std::array::from_fn(|k| {
            let (next, prev) = ((k + 1) % n, (k + n - 1) % n);
            match scheme {
                Scheme::CatmullClark => {
                    Affine::of_corners(&[c[k], mid(k, next), DVec2::splat(0.5), mid(k, prev)])
                }
                // The three corner triangles, then the middle one.
                Scheme::Loop if k < n => Affine::of_corners(&[c[k], mid(k, next), mid(k, prev)]),
                Scheme::Loop => Affine::of_corners(&[mid(0, 1), mid(1, 2), mid(2, 0)]),
            }
        })
    })
}

/// Where each child's Bézier points sit on the 7 × 7 net of the square's halving (index
/// `i + 7 j`): point `(a, b)` of child `k` is at parameter `d(a/3, b/3)` of the parent, six
/// times that on the net.
fn square_child_nodes() -> &'static [[usize; 16]; 4] {
    static CACHE: OnceLock<[[usize; 16]; 4]> = OnceLock::new();
    CACHE.get_or_init(|| {
        let domains = child_domains(Scheme::CatmullClark);
        std::array::from_fn(|k| {
            std::array::from_fn(|n| {
                let p = domains[k].apply(DVec2::new((n % 4) as f64, (n / 4) as f64) / 3.0) * 6.0;
                let (i, j) = (p.x.round() as usize, p.y.round() as usize);
                i.min(6) + 7 * j.min(6)
            })
        })
    })
}

/// The Bézier points of a quartic triangle's children as weights of its own: `maps[k][b][n]`.
/// Blossom values at parameters in {0, ½, 1}, so every weight is a multiple of 1/16: the fit's
/// rounding is removed.
fn loop_child_maps() -> &'static [[[f64; 15]; 15]; 4] {
    static CACHE: OnceLock<[[[f64; 15]; 15]; 4]> = OnceLock::new();
    CACHE.get_or_init(|| {
        let mut maps = [[[0.0; 15]; 15]; 4];
        for n in 0..15 {
            let mut points = [DVec3::ZERO; 16];
            points[n] = DVec3::X;
            let unit = Bezier {
                scheme: Scheme::Loop,
                points,
            };
            for (k, d) in child_domains(Scheme::Loop).iter().enumerate() {
                let child = unit.restrict(d);
                for (b, row) in maps[k].iter_mut().enumerate() {
                    row[n] = (child.points[b].x * 16.0).round() / 16.0;
                }
            }
        }
        maps
    })
}

/// The child (index into [`child_domains`]) whose domain holds `p`.
pub(crate) fn child_at(scheme: Scheme, p: DVec2) -> usize {
    match scheme {
        Scheme::CatmullClark => match (p.x >= 0.5, p.y >= 0.5) {
            (false, false) => 0,
            (true, false) => 1,
            (true, true) => 2,
            (false, true) => 3,
        },
        Scheme::Loop => {
            if 1.0 - p.x - p.y >= 0.5 {
                0
            } else if p.x >= 0.5 {
                1
            } else if p.y >= 0.5 {
                2
            } else {
                3
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn children_are_the_patch_over_their_domains() {
        for scheme in [Scheme::CatmullClark, Scheme::Loop] {
            let points = std::array::from_fn(|n| {
                let x = n as f64;
                DVec3::new((0.9 * x).sin(), (0.4 * x).cos(), 0.1 * x * x)
            });
            let patch = Bezier { scheme, points };
            for (d, child) in patch.children() {
                for p in [
                    DVec2::new(0.1, 0.2),
                    DVec2::new(0.5, 0.3),
                    DVec2::new(0.7, 0.25),
                ] {
                    let there = patch.eval(d.apply(p)).point;
                    assert!(child.eval(p).point.distance(there) < 1e-12, "{scheme:?}");
                }
            }
        }
    }

    /// A line through a point of the patch is never said to pass beside it, whatever its
    /// direction; a line twice the box's diagonal away from a point of the patch always is (one
    /// of the four directions lies within 22.5° of the way to it).
    #[test]
    fn a_line_through_the_patch_is_never_missed() {
        let directions = (0..40).map(|k| {
            let (a, b) = (0.7 * k as f64, 1.3 * k as f64 + 0.2);
            DVec3::new(a.cos() * b.sin(), a.sin() * b.sin(), b.cos())
        });
        let directions: Vec<DVec3> = directions.collect();
        for scheme in [Scheme::CatmullClark, Scheme::Loop] {
            let points = std::array::from_fn(|n| {
                let x = n as f64;
                DVec3::new((0.9 * x).sin(), (0.4 * x).cos(), 0.1 * x * x)
            });
            let patch = Bezier { scheme, points };
            let (lo, hi) = patch.bounds();
            let mut tried = 0;
            for i in 0..=10 {
                for j in 0..=10 {
                    let uv = DVec2::new(i as f64, j as f64) / 10.0;
                    if !in_domain(scheme, uv, 0.0) {
                        continue;
                    }
                    let on = patch.eval(uv).point;
                    for &d in &directions {
                        // The queries' slack: rounding, a point on the hull's border.
                        let slack = 1e-12 * (hi - lo).length();
                        assert!(
                            !patch.misses_line(on - 3.0 * d, d, slack),
                            "{scheme:?} {uv}"
                        );
                        let beside = on + d.any_orthogonal_vector() * 2.0 * (hi - lo).length();
                        assert!(patch.misses_line(beside, d, 1e-12), "{scheme:?} {uv} {d}");
                        tried += 1;
                    }
                }
            }
            assert!(tried > 1000, "{scheme:?}: {tried} lines");
        }
    }
}
