//! Crease curves of the limit surface. A control half-edge's limit curve is the border of one
//! Loop patch or of two Catmull–Clark base patches (one parameter fixed): a crease is a chain of
//! such borders. The mesher protects the polyline of their samples; a point placed on it is
//! brought onto the exact curve by [`nearest`] (the oracle's `project_to_curve`).

use crate::Scheme;
use crate::patch::Patch;
use glam::{DVec2, DVec3};

/// Most iterations of the safeguarded Newton search on one border.
const MAX_ITERATIONS: u32 = 64;

/// One patch border along a crease: from `from` to `to` in the patch's reference domain, with
/// the points sampled on it (its stretch of the protected polyline).
pub(crate) struct CreasePiece {
    patch: usize,
    from: DVec2,
    to: DVec2,
    /// `(s, point)`: the limit point at `from + s (to − from)`, `s` increasing from 0 to 1.
    samples: Vec<(f64, DVec3)>,
    /// The samples' bounding box, to skip far borders.
    lo: DVec3,
    hi: DVec3,
}

impl CreasePiece {
    /// The border of `patch` from `from` to `to`, with its samples (at least two, ends
    /// included, in increasing `s`).
    pub fn new(patch: usize, from: DVec2, to: DVec2, samples: Vec<(f64, DVec3)>) -> Self {
        let points: Vec<DVec3> = samples.iter().map(|&(_, p)| p).collect();
        let (lo, hi) = crate::bezier::bounds(&points);
        CreasePiece {
            patch,
            from,
            to,
            samples,
            lo,
            hi,
        }
    }

    /// The sampled points, from `from` to `to`.
    pub fn points(&self) -> impl Iterator<Item = DVec3> + '_ {
        self.samples.iter().map(|&(_, p)| p)
    }

    /// The limit point at `s` and its derivative in `s`.
    fn eval(&self, scheme: Scheme, patches: &[Patch], s: f64) -> (DVec3, DVec3) {
        let d = self.to - self.from;
        let e = patches[self.patch].surface.eval(scheme, self.from + s * d);
        (e.point, d.x * e.du + d.y * e.dv)
    }

    /// The distance from `p` to the sampled polyline and the parameter of its nearest point,
    /// if nearer than `bound`.
    fn nearest_sample(&self, p: DVec3, bound: f64) -> Option<(f64, f64)> {
        let outside = (self.lo - p).max(p - self.hi).max(DVec3::ZERO).length();
        if outside >= bound {
            return None;
        }
        let mut best: Option<(f64, f64)> = None;
        for w in self.samples.windows(2) {
            let ((s0, a), (s1, b)) = (w[0], w[1]);
            let ab = b - a;
            let t = if ab.length_squared() > 0.0 {
                ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let d = (a + t * ab).distance(p);
            if d < bound && best.is_none_or(|(e, _)| d < e) {
                best = Some((d, s0 + t * (s1 - s0)));
            }
        }
        best
    }

    /// The point of the border nearest to `p`, from the guess `s`: Newton's method on the
    /// squared distance (with the curvature term dropped, which costs nothing near the curve),
    /// inside a bracket that the sign of the derivative shrinks; a step leaving the bracket
    /// bisects it instead, or tries the border's end. Stops when a step moves the point by
    /// `tol` at most.
    fn nearest_from(
        &self,
        scheme: Scheme,
        patches: &[Patch],
        p: DVec3,
        mut s: f64,
        tol: f64,
    ) -> DVec3 {
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        let mut ends_tried = [false; 2];
        let mut q = p;
        for _ in 0..MAX_ITERATIONS {
            let (point, tangent) = self.eval(scheme, patches, s);
            q = point;
            let g = (point - p).dot(tangent);
            if g > 0.0 {
                hi = s;
            } else if g < 0.0 {
                lo = s;
            } else {
                break;
            }
            let mut next = s - g / tangent.length_squared();
            if !(next > lo && next < hi) {
                // Past the border's end, the nearest point may be the end itself: tried once.
                let end = usize::from(next >= hi);
                let bound = [lo, hi][end];
                next = if bound == [0.0, 1.0][end] && !ends_tried[end] {
                    ends_tried[end] = true;
                    bound
                } else {
                    0.5 * (lo + hi)
                };
            }
            if (next - s).abs() * tangent.length() <= tol || hi - lo <= f64::EPSILON {
                break;
            }
            s = next;
        }
        q
    }
}

/// The point of the crease made of `pieces` nearest to `p`, a point near it: the borders whose
/// samples come within `slack` of the nearest sample are searched from their nearest sample
/// (`tol`: see `CreasePiece::nearest_from`). `None` when the crease has no border.
pub(crate) fn nearest(
    scheme: Scheme,
    patches: &[Patch],
    pieces: &[CreasePiece],
    p: DVec3,
    slack: f64,
    tol: f64,
) -> Option<DVec3> {
    let mut near: Vec<(f64, usize, f64)> = Vec::new();
    let mut best = f64::INFINITY;
    for (i, piece) in pieces.iter().enumerate() {
        if let Some((d, s)) = piece.nearest_sample(p, best + slack) {
            best = best.min(d);
            near.push((d, i, s));
        }
    }
    near.into_iter()
        .filter(|&(d, _, _)| d <= best + slack)
        .map(|(_, i, s)| pieces[i].nearest_from(scheme, patches, p, s, tol))
        .min_by(|a, b| a.distance(p).total_cmp(&b.distance(p)))
}
