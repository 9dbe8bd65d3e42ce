//! Sliver perturbation (Tournois, Srinivasan and Alliez 2009): a vertex of a sliver moves along
//! the gradient of the sliver's smallest dihedral angle (or, when that does not help, in a few
//! pseudo-random directions), by a fraction of its distance to the sliver's other vertices. A
//! surface vertex moves in the tangent plane and is put back on its patch by the oracle, a vertex
//! inside a feature curve moves along the curve, corners stay; no boundary facet may fold over
//! or leave the facet distance. A move is kept when the smallest dihedral angle of the cells it
//! changed is larger than that of the cells it destroyed. A sliver lying on the surface with two
//! boundary facets cannot be moved away without changing the surface: it is peeled off instead
//! (see [`Workspace::peel`]), which flips the surface edge under it.

use super::state::{Workspace, min_dihedral};
use super::{Deadline, SLIVER_DEG};
use crate::complex::VertexDimension;
use crate::kernel::Point3;
use crate::oracle::{CurveId, Oracle, PatchId, SurfaceHit};
use crate::random::XorShift;
use crate::refine::curves::Polyline;
use crate::refine::protect::SHARP_TURN;
use crate::triangulation::{CellId, Triangulation, VertexId};

/// Step lengths tried along a direction, as fractions of the distance to the nearest other
/// vertex of the sliver (smallest last: a small step is the likeliest to be accepted but gains
/// least).
const STEPS: [f64; 3] = [0.25, 0.1, 0.04];
/// Pseudo-random directions tried when the gradient does not help (with the middle step).
const RANDOM_TRIES: usize = 2;
/// Pseudo-random directions tried in the last sweep (with the middle step), which ends at the
/// stuck floor as the others do: moves along the gradient of the cells left there were refused
/// for what they do to their neighbours, and a few more directions cost little on so few cells.
const STUCK_RANDOM_TRIES: usize = 8;
/// Sweeps over the slivers at most.
const MAX_SWEEPS: usize = 6;

/// The first bound (degrees) of the perturbation and the step by which it rises to `bound`, as
/// CGAL's perturber raises its own: the worst cells first get every move (a cell at 15° no
/// longer takes the move that a 3° neighbour needed), then the bound rises and the cells a step
/// refused are tried again with their neighbours.
const FIRST_BOUND_DEG: f64 = 10.0;
const BOUND_STEP_DEG: f64 = 1.0;
/// Once the worst cell of a sweep is stuck, the sweep still works on the cells up to this much
/// (degrees) above it, whose moves can free it (see [`Workspace::sweep_slivers`]).
const FLOOR_MARGIN_DEG: f64 = 2.0;

/// Perturbs the vertices of the cells below a bound rising from [`FIRST_BOUND_DEG`] to `bound`,
/// worst first, until a sweep improves nothing or the deadline passes. Each bound stops once its
/// worst cell is stuck, but for the slivers below 10°, and the rise ends at the first bound that
/// did not raise the smallest angle, once that is above 10°: past that point it would only
/// reshape cells that are no slivers, which took most of the phase's time. A last sweep at the
/// final bound then tries [`STUCK_RANDOM_TRIES`] random directions per vertex instead of
/// [`RANDOM_TRIES`]. Returns the number of moves kept.
pub(super) fn perturb(ws: &mut Workspace<'_>, bound: f64, deadline: &Deadline) -> usize {
    let mut rng = XorShift::new(0x9E37_79B9_7F4A_7C15);
    let mut kept = 0;
    let mut floor = ws.min_dihedral();
    let mut b = FIRST_BOUND_DEG.min(bound);
    loop {
        kept += ws.sweep_slivers(b, deadline, MAX_SWEEPS, Some(FLOOR_MARGIN_DEG), |ws, c| {
            ws.peel(c) || perturb_cell(ws, c, RANDOM_TRIES, &mut rng)
        });
        let now = ws.min_dihedral();
        if b >= bound || deadline.passed() || (now <= floor && now >= SLIVER_DEG) {
            break;
        }
        floor = now;
        b = (b + BOUND_STEP_DEG).min(bound);
    }
    kept + ws.sweep_slivers(b, deadline, MAX_SWEEPS, Some(FLOOR_MARGIN_DEG), |ws, c| {
        perturb_cell(ws, c, STUCK_RANDOM_TRIES, &mut rng)
    })
}

/// Where a vertex of a sliver may go: anywhere (inside a subdomain), along its patch (a
/// surface vertex: the unit normal there and the patch), or along its feature curve.
enum Freedom<'a> {
    Volume,
    Surface(Point3, PatchId),
    Curve(CurveId, &'a Polyline, [VertexId; 2]),
}

/// A curve vertex sliding along its curve between its two neighbours there, so that its two
/// feature edges keep following the curve as protection made them (within the bend tolerance,
/// every vertex the curve must keep still a mesh vertex; see [`Polyline::chord_follows`]). It
/// slides along the polyline, and each place it may go is put on the curve itself by the oracle,
/// as protection put the ball centres.
struct Slide<'a> {
    curve: &'a Polyline,
    /// The curve's id and its domain, which maps a point of the polyline onto the curve.
    id: CurveId,
    oracle: &'a dyn Oracle,
    /// Arc length of the neighbour the parameter `t` starts from.
    start: f64,
    /// Arc length from that neighbour to the other one, through the vertex.
    span: f64,
    /// The vertex's `t`.
    at: f64,
    tolerance: f64,
}

impl<'a> Slide<'a> {
    /// The slide of the vertex at `p` between `ends`; `None` where it must stay (on a vertex the
    /// curve keeps, or not between its neighbours).
    fn new(
        (id, curve): (CurveId, &'a Polyline),
        oracle: &'a dyn Oracle,
        p: Point3,
        ends: [Point3; 2],
        tolerance: f64,
    ) -> Option<Self> {
        let eps = 1e-9 * curve.length();
        let s = curve.project(p).s;
        if curve
            .vertex_at(s, eps)
            .is_some_and(|i| curve.keeps_vertex(i, tolerance, SHARP_TURN))
        {
            return None;
        }
        let [a, b] = ends.map(|e| curve.project(e).s);
        let forward = |x: f64, y: f64| {
            if curve.is_closed() {
                (y - x).rem_euclid(curve.length())
            } else {
                y - x
            }
        };
        // From the neighbour the vertex follows, forward along the curve to the other one.
        let (start, span, at) = if (0.0..forward(a, b)).contains(&forward(a, s)) {
            (a, forward(a, b), forward(a, s))
        } else {
            (b, forward(b, a), forward(b, s))
        };
        (at > eps && span - at > eps).then_some(Slide {
            curve,
            id,
            oracle,
            start,
            span,
            at,
            tolerance,
        })
    }

    /// The point at signed arc length `d` from the vertex (for a gradient: no check).
    fn point(&self, d: f64) -> Point3 {
        self.curve.point_at(self.start + self.at + d)
    }

    /// The point of the curve at signed arc length `d` along the polyline from the vertex, if the
    /// vertex may go there: strictly between its neighbours, and both new feature edges
    /// following the curve.
    fn to(&self, d: f64) -> Option<Point3> {
        let t = self.at + d;
        let eps = 1e-9 * self.curve.length();
        let c = self.curve;
        (t > eps
            && self.span - t > eps
            && c.chord_follows(self.start, t, self.tolerance, SHARP_TURN)
            && c.chord_follows(self.start + t, self.span - t, self.tolerance, SHARP_TURN))
        .then(|| self.oracle.project_to_curve(self.id, self.point(d)))
    }
}

/// Tries to improve sliver `c` by moving one of its vertices (along the gradient of its angle,
/// then in `random_tries` pseudo-random directions).
fn perturb_cell(
    ws: &mut Workspace<'_>,
    c: CellId,
    random_tries: usize,
    rng: &mut XorShift,
) -> bool {
    let cell = ws.rt.cell(c);
    for k in 0..4 {
        let v = cell[k];
        let p = ws.rt.point(v);
        let others: Vec<Point3> = (0..4)
            .filter(|&j| j != k)
            .map(|j| ws.rt.point(cell[j]))
            .collect();
        let reach = others
            .iter()
            .map(|q| q.distance(p))
            .fold(f64::INFINITY, f64::min);
        let angle_at = |x: Point3| {
            let mut t = cell.map(|u| ws.rt.point(u));
            t[k] = x;
            t.swap(0, 1);
            min_dihedral(&t)
        };
        let freedom = match ws.dimension[v.0 as usize] {
            VertexDimension::Volume => Freedom::Volume,
            VertexDimension::Surface => match surface_frame(ws, v) {
                Some((n, patch)) => Freedom::Surface(n, patch),
                None => continue,
            },
            VertexDimension::Curve => match ws.curve(v) {
                Some((id, curve, ends)) => Freedom::Curve(id, curve, ends),
                None => continue,
            },
            VertexDimension::Corner => continue,
        };
        let tries: Vec<Point3> = match &freedom {
            Freedom::Volume | Freedom::Surface(..) => {
                let tangent = |d: Point3| match &freedom {
                    Freedom::Surface(n, _) => d - *n * d.dot(*n),
                    _ => d,
                };
                let mut tries = Vec::with_capacity(STEPS.len() + random_tries);
                let g = tangent(gradient(angle_at, p, 1e-4 * reach));
                if g.length() > 0.0 {
                    tries.extend(STEPS.map(|s| p + g.normalize() * (s * reach)));
                }
                for _ in 0..random_tries {
                    let d = tangent(random_unit(rng));
                    if d.length() > 1e-3 {
                        tries.push(p + d.normalize() * (STEPS[1] * reach));
                    }
                }
                match freedom {
                    Freedom::Surface(n, patch) => tries
                        .into_iter()
                        .filter_map(|q| project(ws, q, n, reach, patch))
                        .collect(),
                    _ => tries,
                }
            }
            Freedom::Curve(id, curve, ends) => {
                let ends = ends.map(|u| ws.rt.point(u));
                let Some(slide) =
                    Slide::new((*id, *curve), ws.oracle, p, ends, ws.bend_tolerance())
                else {
                    continue;
                };
                // Along the curve, the way the angle grows first, then the other way.
                let h = 1e-4 * reach;
                let up = angle_at(slide.point(h)) >= angle_at(slide.point(-h));
                let sign = if up { 1.0 } else { -1.0 };
                let mut tries: Vec<Point3> = STEPS
                    .iter()
                    .filter_map(|&s| slide.to(sign * s * reach))
                    .collect();
                tries.extend(slide.to(-sign * STEPS[1] * reach));
                tries
            }
        };
        let fixed_boundary = !matches!(freedom, Freedom::Volume);
        let normals = if fixed_boundary {
            ws.boundary_normals(v)
        } else {
            Vec::new()
        };
        for q in tries {
            let w = ws.rt.weight(v);
            // The surface checks query the oracle: only for a move that helps.
            if let Some(change) = ws.try_move(v, q, w, |before, after| after > before) {
                if !fixed_boundary || (ws.none_folded(v, &normals) && ws.surface_near_around(v)) {
                    return true;
                }
                ws.undo(change);
            }
        }
    }
    false
}

/// Central-difference gradient of `f` at `p` with step `h`.
fn gradient(f: impl Fn(Point3) -> f64, p: Point3, h: f64) -> Point3 {
    let axis = [Point3::X, Point3::Y, Point3::Z];
    let d = axis.map(|e| (f(p + e * h) - f(p - e * h)) / (2.0 * h));
    Point3::new(d[0], d[1], d[2])
}

/// A pseudo-random unit vector (xorshift; the sequence is fixed, so runs repeat).
fn random_unit(rng: &mut XorShift) -> Point3 {
    let mut next = || rng.next_f64() * 2.0 - 1.0;
    let d = Point3::new(next(), next(), next());
    if d.length() > 0.0 {
        d.normalize()
    } else {
        Point3::X
    }
}

/// The unit normal of the surface at surface vertex `v` (area-weighted over its boundary
/// facets) and its patch, when all its boundary facets lie on one patch between the same two
/// subdomains (a vertex on several patches, or where a third subdomain meets them, sits on a
/// feature and stays).
pub(super) fn surface_frame(ws: &Workspace<'_>, v: VertexId) -> Option<(Point3, PatchId)> {
    let facets = ws.boundary_normals(v);
    let (first, _) = facets.first()?;
    let (patch, sides) = (ws.patch(first)?, ws.sides(first)?);
    if facets
        .iter()
        .any(|(k, _)| ws.patch(k) != Some(patch) || ws.sides(k) != Some(sides))
    {
        return None;
    }
    let normal = facets.iter().fold(Point3::ZERO, |s, &(_, n)| s + n);
    (normal.length() > 0.0).then(|| (normal.normalize(), patch))
}

/// The point of `patch` nearest to `q` along the line through `q` with direction `n`, within
/// `reach` of `q`.
pub(super) fn project(
    ws: &Workspace<'_>,
    q: Point3,
    n: Point3,
    reach: f64,
    patch: PatchId,
) -> Option<Point3> {
    let mut hits: Vec<SurfaceHit> = Vec::new();
    ws.oracle
        .segment_hits(q - n * reach, q + n * reach, &mut hits);
    hits.iter()
        .filter(|h| h.patch == patch)
        .min_by(|a, b| (a.t - 0.5).abs().total_cmp(&(b.t - 0.5).abs()))
        .map(|h| h.point)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::oracle::UnitBallWithEquator;

    /// A vertex sliding along a polyline that samples the equator lands on the equator, off
    /// the polyline's chords.
    #[test]
    fn a_slide_puts_the_vertex_on_the_curve_the_polyline_samples() {
        let equator = UnitBallWithEquator.feature_curves().remove(0);
        let at = |k: usize| equator.points[k];
        let line = Polyline::new(&equator.points, true).expect("valid");
        // Chords of four segments leave the circle by 1 − cos(π/16) ≈ 0.019.
        let slide = Slide::new(
            (CurveId(1), &line),
            &UnitBallWithEquator,
            at(8),
            [at(6), at(10)],
            0.05,
        )
        .expect("free to slide");
        for d in [-0.07, -0.02, 0.03, 0.08] {
            let q = slide.to(d).expect("between its neighbours");
            assert!((q.length() - 1.0).abs() < 1e-15, "{q} off the equator");
            assert!(line.project(q).distance > 1e-5, "{q} on a vertex");
        }
    }
}
