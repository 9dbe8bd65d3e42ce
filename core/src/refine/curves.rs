//! Polyline feature curves with their arc-length parametrisation: the geometry protecting balls
//! are placed with (a ball centre is a point of the curve at some arc length `s`).

use crate::kernel::Point3;

/// A polyline curve parametrised by arc length `s ∈ [0, length]`. A closed curve wraps around:
/// its last point joins its first, and parameters are taken modulo the length.
#[derive(Clone, Debug, PartialEq)]
pub struct Polyline {
    points: Vec<Point3>,
    /// Arc length at each point; one more entry than `points` for a closed curve (the return to
    /// the first point).
    arc: Vec<f64>,
    closed: bool,
    /// Padded bounding boxes of runs of [`CHUNK`] consecutive segments, so nearest-point
    /// queries skip whole runs that cannot beat the best distance found so far.
    chunks: Vec<(Point3, Point3)>,
}

/// Segments per bounding box in [`Polyline::chunks`].
const CHUNK: usize = 8;

/// The point of a curve nearest to a query point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Projection {
    /// Arc length of the nearest point.
    pub s: f64,
    /// The nearest point.
    pub point: Point3,
    /// Its distance to the query point.
    pub distance: f64,
}

impl Polyline {
    /// The curve through `points` (consecutive duplicates dropped); `None` when fewer than two
    /// distinct points are left or a coordinate is not finite.
    pub fn new(points: &[Point3], closed: bool) -> Option<Self> {
        if points.iter().any(|p| !p.is_finite()) {
            return None;
        }
        let mut pts: Vec<Point3> = Vec::with_capacity(points.len());
        for &p in points {
            if pts.last() != Some(&p) {
                pts.push(p);
            }
        }
        if closed && pts.len() > 1 && pts.first() == pts.last() {
            pts.pop();
        }
        if pts.len() < 2 {
            return None;
        }
        let mut arc = Vec::with_capacity(pts.len() + 1);
        arc.push(0.0);
        let mut total = 0.0;
        for w in pts.windows(2) {
            total += w[0].distance(w[1]);
            arc.push(total);
        }
        if closed {
            total += pts[pts.len() - 1].distance(pts[0]);
            arc.push(total);
        }
        let mut line = Polyline {
            points: pts,
            arc,
            closed,
            chunks: Vec::new(),
        };
        line.chunks = (0..line.segment_count())
            .step_by(CHUNK)
            .map(|first| {
                let last = (first + CHUNK).min(line.segment_count());
                let (mut lo, mut hi) = (line.points[first], line.points[first]);
                for i in first..last {
                    let (a, b) = line.segment(i);
                    lo = lo.min(a).min(b);
                    hi = hi.max(a).max(b);
                }
                // Padding covers rounding in the nearest points computed on the segments, so a
                // skipped run never holds a strictly nearer computed distance.
                let pad =
                    1e-9 * (hi - lo).max_element() + 1e-12 * lo.abs().max(hi.abs()).max_element();
                (lo - Point3::splat(pad), hi + Point3::splat(pad))
            })
            .collect();
        Some(line)
    }

    /// Whether the last point joins the first.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// The arc length of the whole curve.
    pub fn length(&self) -> f64 {
        self.arc[self.arc.len() - 1]
    }

    /// Arc length of vertex `i`.
    pub fn arc_at(&self, i: usize) -> f64 {
        self.arc[i]
    }

    /// The curve's vertices (without the repeated first point of a closed curve).
    pub fn points(&self) -> &[Point3] {
        &self.points
    }

    /// The first point.
    pub fn start(&self) -> Point3 {
        self.points[0]
    }

    /// The last vertex of an open curve (the first one of a closed curve).
    pub fn end(&self) -> Point3 {
        if self.closed {
            self.points[0]
        } else {
            self.points[self.points.len() - 1]
        }
    }

    fn segment_count(&self) -> usize {
        self.arc.len() - 1
    }

    fn segment(&self, i: usize) -> (Point3, Point3) {
        (self.points[i], self.points[(i + 1) % self.points.len()])
    }

    /// `s` brought into `[0, length]`: wrapped on a closed curve, clamped on an open one.
    pub fn normalize(&self, s: f64) -> f64 {
        let l = self.length();
        if self.closed {
            s.rem_euclid(l)
        } else {
            s.clamp(0.0, l)
        }
    }

    /// The point at arc length `s` (see [`Polyline::normalize`]).
    pub fn point_at(&self, s: f64) -> Point3 {
        let s = self.normalize(s);
        // The last segment whose start is at or before `s`.
        let i = self
            .arc
            .partition_point(|&a| a <= s)
            .saturating_sub(1)
            .min(self.segment_count() - 1);
        let (a, b) = self.segment(i);
        let len = self.arc[i + 1] - self.arc[i];
        if len <= 0.0 {
            return a;
        }
        let t = ((s - self.arc[i]) / len).clamp(0.0, 1.0);
        if t == 1.0 { b } else { a + t * (b - a) }
    }

    /// Whether vertex `i` is a bend the mesh must keep as a vertex: the curve turns there by
    /// more than `max_turn` (radians), or leaves the chord of the vertex's two neighbours by more
    /// than `tol`. The ends of an open curve are always kept.
    pub fn keeps_vertex(&self, i: usize, tol: f64, max_turn: f64) -> bool {
        let n = self.points.len();
        if !self.closed && (i == 0 || i + 1 >= n) {
            return true;
        }
        let (a, x, b) = (
            self.points[(i + n - 1) % n],
            self.points[i % n],
            self.points[(i + 1) % n],
        );
        (x - a).angle_between(b - x) > max_turn || point_segment_distance(x, a, b) > tol
    }

    /// The vertex at arc length `s`, within `eps`, if any.
    pub fn vertex_at(&self, s: f64, eps: f64) -> Option<usize> {
        let s = self.normalize(s);
        let i = self.arc.partition_point(|&a| a < s - eps);
        let i = (i < self.arc.len() && self.arc[i] <= s + eps).then_some(i)?;
        Some(i % self.points.len())
    }

    /// Whether the chord from the point at `s0` to the point `len ≥ 0` further along the curve
    /// (wrapping round a closed curve) follows it: every vertex strictly between lies within
    /// `tol` of the chord and is no vertex to keep ([`Polyline::keeps_vertex`]), so a feature
    /// edge along that chord stays as close to the curve as protection places them.
    pub fn chord_follows(&self, s0: f64, len: f64, tol: f64, max_turn: f64) -> bool {
        let (l, n) = (self.length(), self.points.len());
        let eps = 1e-9 * l;
        let (a, b) = (self.point_at(s0), self.point_at(s0 + len));
        let s0 = self.normalize(s0);
        let mut i = self.arc.partition_point(|&x| x <= s0 + eps);
        let mut offset = 0.0;
        for _ in 0..=n {
            if i >= self.arc.len() - usize::from(self.closed) {
                if !self.closed {
                    return true;
                }
                i = 0;
                offset += l;
            }
            if self.arc[i] + offset >= s0 + len - eps {
                return true;
            }
            if self.keeps_vertex(i, tol, max_turn)
                || point_segment_distance(self.points[i], a, b) > tol
            {
                return false;
            }
            i += 1;
        }
        true
    }

    /// The parameter at signed geodesic distance `d` from parameter `s`, or `None` when an open
    /// curve ends before.
    pub fn advance(&self, s: f64, d: f64) -> Option<f64> {
        let t = s + d;
        if self.closed {
            Some(self.normalize(t))
        } else {
            (0.0..=self.length()).contains(&t).then_some(t)
        }
    }

    /// Geodesic distance along the curve between parameters `s0` and `s1` (the shorter way round
    /// on a closed curve).
    pub fn geodesic_distance(&self, s0: f64, s1: f64) -> f64 {
        let d = (self.normalize(s1) - self.normalize(s0)).abs();
        if self.closed {
            d.min(self.length() - d)
        } else {
            d
        }
    }

    /// The nearest point of the curve to `p` (ties: the smallest parameter).
    pub fn project(&self, p: Point3) -> Projection {
        let mut best = Projection {
            s: 0.0,
            point: self.points[0],
            distance: f64::INFINITY,
        };
        self.scan_near(p, f64::INFINITY, |i, bound| {
            let (a, b) = self.segment(i);
            let t = nearest_parameter(p, a, b);
            let q = a + t * (b - a);
            let d = q.distance(p);
            if d >= bound {
                return bound;
            }
            best = Projection {
                s: self.arc[i] + t * (self.arc[i + 1] - self.arc[i]),
                point: q,
                distance: d,
            };
            d
        });
        best
    }

    /// Distance from `p` to the curve, or `bound` when that is smaller: [`Polyline::project`]'s
    /// distance without looking at the parts no nearer than `bound`.
    pub fn distance_below(&self, p: Point3, bound: f64) -> f64 {
        self.scan_near(p, bound, |i, best| {
            let (a, b) = self.segment(i);
            best.min(point_segment_distance(p, a, b))
        })
    }

    /// Distance from `p` to the part of the curve farther than `radius` from `center`: how close
    /// the curve comes to `p` once it has left a ball around `center` (a protecting ball that
    /// the curve crosses), or `bound` when that is smaller: parts no nearer than `bound` are
    /// skipped. Infinite when no such part exists and `bound` is infinite.
    pub fn distance_outside_ball(&self, p: Point3, center: Point3, radius: f64, bound: f64) -> f64 {
        self.scan_near(p, bound, |i, best| {
            let (a, b) = self.segment(i);
            // The parts of [a, b] are no nearer than the whole segment.
            if point_segment_distance(p, a, b) >= best {
                return best;
            }
            // The part of [a, b] outside the ball: up to two sub-segments.
            segment_outside_ball(a, b, center, radius)
                .into_iter()
                .flatten()
                .fold(best, |best, (x, y)| {
                    best.min(point_segment_distance(p, x, y))
                })
        })
    }

    /// The chunk walk of the nearest-point queries: `visit(i, best)` for each segment `i` of the
    /// chunks whose padded box is nearer to `p` than the current best distance, which starts at
    /// `bound` and becomes what `visit` returns. Returns the final best distance.
    fn scan_near(&self, p: Point3, bound: f64, mut visit: impl FnMut(usize, f64) -> f64) -> f64 {
        let mut best = bound;
        for (k, &(lo, hi)) in self.chunks.iter().enumerate() {
            if box_distance(p, lo, hi) >= best {
                continue;
            }
            for i in k * CHUNK..((k + 1) * CHUNK).min(self.segment_count()) {
                best = visit(i, best);
            }
        }
        best
    }

    /// The curve vertices strictly between parameters `s0 < s1` (no wrapping), then the two
    /// end points: what must be covered between two consecutive ball centres.
    pub fn arc_points(&self, s0: f64, s1: f64) -> Vec<Point3> {
        let mut out = vec![self.point_at(s0)];
        let (lo, hi) = if self.closed && s1 > self.length() {
            (s0, s1)
        } else {
            (s0, s1.min(self.length()))
        };
        for shift in [0.0, self.length()] {
            if shift > 0.0 && !self.closed {
                break;
            }
            for (i, &a) in self.arc[..self.points.len()].iter().enumerate() {
                let s = a + shift;
                if s > lo && s < hi {
                    out.push(self.points[i]);
                }
            }
        }
        out.push(self.point_at(s1));
        out
    }
}

/// Distance from `p` to the axis-aligned box `[lo, hi]` (0 inside).
fn box_distance(p: Point3, lo: Point3, hi: Point3) -> f64 {
    (lo - p).max(p - hi).max(Point3::ZERO).length()
}

/// Distance from `p` to the segment `[a, b]`.
pub fn point_segment_distance(p: Point3, a: Point3, b: Point3) -> f64 {
    (a + nearest_parameter(p, a, b) * (b - a)).distance(p)
}

/// The parameter in `[0, 1]` of the point of segment `[a, b]` nearest to `p` (0 when `a == b`).
#[inline]
fn nearest_parameter(p: Point3, a: Point3, b: Point3) -> f64 {
    let ab = b - a;
    let len2 = ab.length_squared();
    if len2 > 0.0 {
        ((p - a).dot(ab) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// The parts of segment `[a, b]` outside the open ball `(center, radius)`: at most two.
fn segment_outside_ball(
    a: Point3,
    b: Point3,
    center: Point3,
    radius: f64,
) -> [Option<(Point3, Point3)>; 2] {
    let d = b - a;
    let len2 = d.length_squared();
    let f = a - center;
    if len2 == 0.0 {
        return [(f.length() >= radius).then_some((a, a)), None];
    }
    // |f + t d|² = r²: t² len2 + 2 t f·d + |f|² − r² = 0.
    let half_b = f.dot(d);
    let c = f.length_squared() - radius * radius;
    let disc = half_b * half_b - len2 * c;
    if disc <= 0.0 {
        return [Some((a, b)), None];
    }
    let root = disc.sqrt();
    let (t0, t1) = ((-half_b - root) / len2, (-half_b + root) / len2);
    [
        (t0 > 0.0).then(|| (a, a + t0.min(1.0) * d)),
        (t1 < 1.0).then(|| (a + t1.max(0.0) * d, b)),
    ]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A chord follows the curve when the vertices it passes lie within the tolerance and none
    /// is a corner to keep; a closed curve's chords wrap round its first point.
    #[test]
    fn chords_follow_a_fine_arc_but_not_across_a_corner() {
        // A quarter circle of 32 segments, then a square corner: a closed loop.
        let mut pts: Vec<Point3> = (0..=32)
            .map(|k| {
                let a = std::f64::consts::FRAC_PI_2 * k as f64 / 32.0;
                Point3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        pts.push(Point3::ZERO);
        let line = Polyline::new(&pts, true).expect("valid");
        let (l, turn) = (line.length(), 0.35);
        // A vertex off the chord of its two neighbours: 1 − cos(π/64) ≈ 1.2e-3; off the chord
        // of the vertices four away: 1 − cos(π/16) ≈ 1.9e-2.
        let tol = 2e-3;
        assert!(!line.keeps_vertex(16, tol, turn));
        assert!(
            line.keeps_vertex(16, 1e-5, turn),
            "too far from its neighbours' chord"
        );
        assert!(line.keeps_vertex(0, tol, turn) && line.keeps_vertex(33, tol, turn));
        let s8 = line.arc_at(8);
        assert!(line.chord_follows(s8, line.arc_at(10) - s8, tol, turn));
        assert!(!line.chord_follows(s8, line.arc_at(16) - s8, tol, turn));
        // Across the right-angle corner at the origin (vertex 33), whatever the tolerance.
        let s32 = line.arc_at(32);
        assert!(!line.chord_follows(s32, l - s32 + 0.1, 10.0, turn));
        // Within one segment, no vertex is passed: a chord of the curve itself.
        assert!(line.chord_follows(s8 + 1e-3, 1e-3, 0.0, turn));
        assert_eq!(line.vertex_at(s8 + 1e-12, 1e-9), Some(8));
        assert_eq!(line.vertex_at(s8 + 1e-3, 1e-9), None);
        assert_eq!(line.vertex_at(l - 1e-12, 1e-9), Some(0));
    }

    /// A random walk of `n` points, so runs of segments have overlapping and far-apart boxes.
    fn random_walk(rng: &mut impl rand::Rng, n: usize) -> Vec<Point3> {
        let mut p = Point3::ZERO;
        (0..n)
            .map(|_| {
                p += Point3::new(
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                    rng.random_range(-1.0..1.0),
                );
                p
            })
            .collect()
    }

    #[test]
    fn pruned_queries_equal_a_scan_of_every_segment() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand::rngs::StdRng::seed_from_u64(7);
        for n in [2, 3, 9, 17, 40] {
            for closed in [false, true] {
                let line = Polyline::new(&random_walk(&mut rng, n), closed).expect("valid");
                for _ in 0..50 {
                    let p = Point3::new(
                        rng.random_range(-6.0..6.0),
                        rng.random_range(-6.0..6.0),
                        rng.random_range(-6.0..6.0),
                    );
                    let segments: Vec<(Point3, Point3)> =
                        (0..line.segment_count()).map(|i| line.segment(i)).collect();
                    let nearest = segments
                        .iter()
                        .map(|&(a, b)| point_segment_distance(p, a, b))
                        .fold(f64::INFINITY, f64::min);
                    assert_eq!(line.project(p).distance, nearest);
                    let (center, radius) = (line.points()[n / 2], rng.random_range(0.1..3.0));
                    // Every segment in turn, skipping those whose whole is no nearer.
                    let mut outside = f64::INFINITY;
                    for &(a, b) in &segments {
                        if point_segment_distance(p, a, b) < outside {
                            for (x, y) in segment_outside_ball(a, b, center, radius)
                                .into_iter()
                                .flatten()
                            {
                                outside = outside.min(point_segment_distance(p, x, y));
                            }
                        }
                    }
                    assert_eq!(
                        line.distance_outside_ball(p, center, radius, f64::INFINITY),
                        outside
                    );
                    let bound = rng.random_range(0.0..4.0);
                    assert_eq!(line.distance_below(p, bound), nearest.min(bound));
                    assert_eq!(
                        line.distance_outside_ball(p, center, radius, bound),
                        outside.min(bound)
                    );
                }
            }
        }
    }

    fn square() -> Polyline {
        let pts = [
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(1.0, 1.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
        ];
        Polyline::new(&pts, true).expect("valid")
    }

    #[test]
    fn arc_length_of_open_and_closed_curves() {
        let sq = square();
        assert_eq!(sq.length(), 4.0);
        let open = Polyline::new(&sq.points()[..3], false).expect("valid");
        assert_eq!(open.length(), 2.0);
        assert_eq!(open.end(), Point3::new(1.0, 1.0, 0.0));
        assert!(Polyline::new(&[Point3::ZERO, Point3::ZERO], false).is_none());
        assert!(Polyline::new(&[Point3::ZERO, Point3::NAN], false).is_none());
    }

    #[test]
    fn point_at_walks_the_curve_and_wraps() {
        let sq = square();
        assert_eq!(sq.point_at(0.5), Point3::new(0.5, 0.0, 0.0));
        assert_eq!(sq.point_at(1.0), Point3::new(1.0, 0.0, 0.0));
        assert_eq!(sq.point_at(3.5), Point3::new(0.0, 0.5, 0.0));
        assert_eq!(sq.point_at(4.5), sq.point_at(0.5));
        assert_eq!(sq.point_at(-0.5), sq.point_at(3.5));
    }

    #[test]
    fn geodesic_distance_takes_the_short_way_on_closed_curves() {
        let sq = square();
        assert_eq!(sq.geodesic_distance(0.5, 3.5), 1.0);
        assert_eq!(sq.geodesic_distance(0.5, 2.0), 1.5);
        let open = Polyline::new(sq.points(), false).expect("valid");
        assert_eq!(open.geodesic_distance(0.5, 2.5), 2.0);
        assert_eq!(open.advance(2.5, 1.0), None);
        assert_eq!(sq.advance(3.5, 1.0), Some(0.5));
        assert_eq!(open.advance(2.5, -1.0), Some(1.5));
    }

    #[test]
    fn projection_is_the_nearest_point_and_inverts_point_at() {
        let sq = square();
        let p = sq.project(Point3::new(1.5, 0.25, 0.3));
        assert_eq!(p.point, Point3::new(1.0, 0.25, 0.0));
        assert!((p.s - 1.25).abs() < 1e-15);
        for k in 0..40 {
            let s = k as f64 * 0.1;
            let q = sq.project(sq.point_at(s));
            assert!(q.distance < 1e-12);
            assert!(sq.geodesic_distance(q.s, s) < 1e-12);
        }
    }

    #[test]
    fn distance_outside_a_ball_ignores_the_covered_part() {
        let line = Polyline::new(&[Point3::ZERO, Point3::new(4.0, 0.0, 0.0)], false).expect("ok");
        let p = Point3::new(1.0, 1.0, 0.0);
        let d = line.distance_outside_ball(p, Point3::new(1.0, 0.0, 0.0), 2.0, f64::INFINITY);
        assert!((d - 5.0f64.sqrt()).abs() < 1e-12, "{d}");
        let far = line.distance_outside_ball(p, Point3::new(2.0, 0.0, 0.0), 10.0, f64::INFINITY);
        assert!(far.is_infinite());
    }

    #[test]
    fn arc_points_list_the_vertices_between_two_parameters() {
        let sq = square();
        let pts = sq.arc_points(0.5, 2.5);
        assert_eq!(pts.len(), 4);
        assert_eq!(pts[1], Point3::new(1.0, 0.0, 0.0));
        assert_eq!(pts[2], Point3::new(1.0, 1.0, 0.0));
        let wrapped = sq.arc_points(3.5, 4.5);
        assert_eq!(
            wrapped,
            vec![sq.point_at(3.5), Point3::ZERO, sq.point_at(0.5)]
        );
    }
}
