//! Protecting balls on the sharp features of a piecewise-smooth domain (CGAL Mesh_3's
//! protection, after Cheng–Dey–Ramos): every corner is the centre of a ball, every curve is
//! covered by a chain of balls centred on it, consecutive balls overlap and all other pairs are
//! disjoint. Inserted as weighted points (weight = r²) in a regular triangulation, the balls make
//! each curve the union of the edges joining consecutive centres, whatever the angles at which
//! curves and patches meet: refinement points are never inside a ball (every point of the power
//! diagram off the balls has a non-negative power distance to its owners), so small angles cannot
//! make refinement cascade.
//!
//! The balls are placed with a sizing function along each curve: at most `edge_size`, a fraction
//! of the distance to other features, and growing slowly away from corners; then pairs that
//! violate the rules shrink and the curves are repopulated until every rule holds (CGAL's
//! `refine_balls`).

use super::criteria::Sizing;
use super::curves::{Polyline, point_segment_distance};
use super::feature_grid::{FeatureGrid, Item};
use crate::kernel::Point3;
use crate::oracle::{CurveId, FeatureCurve};
use std::time::Instant;

/// Largest growth of ball radii per unit of arc length: keeps neighbouring radii comparable, so
/// that consecutive balls overlap (the radius is also capped by [`GAP_FRACTION`] of the gaps to
/// the neighbours, which keeps the next ones disjoint).
const GROWTH: f64 = 0.3;
/// Spacing of consecutive centres along a curve, in radii: about one radius, as CGAL's
/// protection, so that the facets fanning out of the balls are exempt from the facet criteria
/// (see `FeatureExemption`) instead of being refined down to the curve's spacing.
const SPACING: f64 = 1.1;
/// Ball radius as a fraction of the distance to the nearest other feature (below 1/2: balls on two
/// features are disjoint).
const FEATURE_FRACTION: f64 = 0.45;
/// Largest curve ball radius as a fraction of the gaps to its chain neighbours (below 1: balls
/// two steps apart on a straight run stay disjoint; above 1/2: neighbours overlap).
const GAP_FRACTION: f64 = 0.95;
/// Corner ball radius as a fraction of the shortest straight run leaving it along a curve piece
/// (CGAL: a third of the distance to the nearest corner): a bend is always a centre, so it must
/// lie outside the corner ball.
const INCIDENT_FRACTION: f64 = 1.0 / 3.0;
/// Distance, relative to a curve's extent, under which a polyline vertex counts as on the chord
/// of its neighbours (no bend): rounding noise, far below any fidelity that matters.
const COLLINEAR: f64 = 1e-11;
/// Most polyline segments in one straight run of [`bends`]: each extension re-checks the run's
/// vertices, so this bounds the work at `MAX_RUN` per vertex (a finely tessellated, nearly
/// straight curve gets a bend every `MAX_RUN` vertices, harmless at any ball size).
const MAX_RUN: usize = 256;
/// Turning angle (radians, 20°) above which a polyline vertex is a bend even within the bend
/// tolerance: a tessellated smooth curve turns far less per vertex.
pub(crate) const SHARP_TURN: f64 = 0.35;
/// Radius of a ball on a bend, as a fraction of the longer straight run next to it (above 1/2 so
/// that consecutive bends' balls overlap).
const BEND_FRACTION: f64 = 0.6;
/// How much of a spacing a straight run may exceed before it gets one more ball: the runs
/// between fixed centres are not cut for a small excess (the two end balls still overlap).
const RUN_SLACK: f64 = 0.5;
/// Rounds of shrink-and-repopulate before giving up.
const MAX_ROUNDS: usize = 200;
/// Distance, in radii, within which a corner ball's boundary on a piece counts as the bend
/// there: the bend is a centre anyway, and two centres that close (on an image's border, a
/// bend two voxels from a corner whose ball is two voxels wide, one ulp apart) leave cells
/// flattened along the edge between them, which no refinement point can destroy.
const ANCHOR_MERGE: f64 = 0.1;

/// What a protecting ball's centre lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Feature {
    /// A corner, by its index in the corner list.
    Corner(u32),
    Curve(CurveId),
}

/// A ball centred on a feature; its centre becomes a vertex of weight `radius²`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProtectingBall {
    pub center: Point3,
    pub radius: f64,
    pub feature: Feature,
}

/// The balls covering one piece of a curve (between two corners, or a whole closed curve), in
/// order along the curve. Consecutive balls overlap; a closed chain's last ball overlaps its first.
#[derive(Clone, Debug, PartialEq)]
pub struct Chain {
    pub curve: CurveId,
    /// Indices into [`Protection::balls`]; corner balls at the ends of an open chain.
    pub balls: Vec<usize>,
    pub closed: bool,
}

impl Chain {
    /// Consecutive ball pairs: the restricted edges the curve becomes.
    pub fn links(&self) -> impl Iterator<Item = (usize, usize)> + '_ {
        let n = self.balls.len();
        let count = if self.closed { n } else { n.saturating_sub(1) };
        (0..count).map(move |i| (self.balls[i], self.balls[(i + 1) % n]))
    }
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Protection {
    /// Corner balls first (ball `k` is corner `k`), then the curve balls chain by chain.
    pub balls: Vec<ProtectingBall>,
    pub chains: Vec<Chain>,
    /// The corners, with the end points of open curves that were not given as corners.
    pub corners: Vec<Point3>,
    /// Arc length of each chain ball along its piece of curve.
    chain_params: Vec<Vec<f64>>,
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ProtectError {
    #[error("feature curve {curve} has fewer than two distinct points or a non-finite coordinate")]
    BadCurve { curve: CurveId },
    #[error("corner {index} has a non-finite coordinate")]
    BadCorner { index: usize },
    #[error(
        "protecting the sharp features needs more than {limit} vertices; raise --max-vertices, or --edge-size / --edge-min-size"
    )]
    TooManyBalls { limit: usize },
    #[error(
        "protecting the sharp features took longer than the time limit; raise --time-limit or --edge-min-size"
    )]
    TimeLimit,
    #[error("protecting balls did not settle in {rounds} rounds; raise --edge-min-size")]
    NotSettled { rounds: usize },
}

/// Guards that bound the protection whatever the features.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ProtectLimits {
    /// Smallest ball radius (CGAL's `edge_min_size`): features closer than this are not split
    /// further, their balls stay at this radius (and may then intersect; the curves are still
    /// meshed, less faithfully there).
    pub min_radius: f64,
    /// Most balls ([`ProtectError::TooManyBalls`] past it).
    pub max_balls: usize,
    /// Wall-clock time after which the protection gives up ([`ProtectError::TimeLimit`]).
    pub deadline: Option<Instant>,
    /// Distance to the chord of its run under which a polyline vertex is not a bend (see
    /// [`bends`]). A CAD export tessellates each smooth curve (a circle as 2,000 segments):
    /// following it vertex by vertex would put a ball on every one, far more than the edge size
    /// asks; within this distance the curve is followed by its chords instead. 0 keeps every
    /// vertex off a straight line.
    pub bend_tolerance: f64,
}

impl Default for ProtectLimits {
    fn default() -> Self {
        ProtectLimits {
            min_radius: 0.0,
            max_balls: 2_000_000,
            deadline: None,
            bend_tolerance: 0.0,
        }
    }
}

/// A curve between two corners, or a closed curve without corner.
struct Piece {
    curve: CurveId,
    line: Polyline,
    ends: Option<[usize; 2]>,
    /// `(s, r)`: the radius at `s` is at most `r + GROWTH · |s' − s|` (shrunk balls).
    limits: Vec<(f64, f64)>,
    /// Bounding box of the polyline, to skip far pieces in distance queries.
    bounds: (Point3, Point3),
    /// Arc lengths of the vertices where the piece bends (see [`bends`]), increasing.
    bends: Vec<f64>,
}

impl Piece {
    fn new(curve: CurveId, line: Polyline, ends: Option<[usize; 2]>, bend_tolerance: f64) -> Self {
        let pts = line.points();
        let bounds = pts
            .iter()
            .fold((pts[0], pts[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
        Piece {
            curve,
            bends: bends(&line, bend_tolerance),
            line,
            ends,
            limits: Vec::new(),
            bounds,
        }
    }

    /// The largest radius of a ball centred at `s` when `s` is a bend: a fraction of the longer
    /// straight run next to it, so that the balls on consecutive bends overlap while those two
    /// bends apart stay disjoint (unless the curve turns back sharply). Infinite elsewhere.
    fn bend_cap(&self, s: f64) -> f64 {
        let l = self.line.length();
        let eps = 1e-12 * l;
        let k = self.bends.partition_point(|&b| b < s - eps);
        if self.bends.get(k).is_none_or(|&b| b > s + eps) {
            return f64::INFINITY;
        }
        let n = self.bends.len();
        let (prev, next) = if self.ends.is_none() {
            let prev = self.bends[(k + n - 1) % n];
            let next = self.bends[(k + 1) % n];
            ((s - prev).rem_euclid(l), (next - s).rem_euclid(l))
        } else {
            let prev = if k > 0 { self.bends[k - 1] } else { 0.0 };
            let next = self.bends.get(k + 1).copied().unwrap_or(l);
            (s - prev, next - s)
        };
        let longest = if n == 1 && self.ends.is_none() {
            l
        } else {
            prev.max(next)
        };
        BEND_FRACTION * longest
    }

    /// Drop the bends closer than `min_sep` (arc length) to a kept bend or to an end: every bend
    /// is a ball centre, and a zigzag finer than the smallest ball (a CSG seam's micro-triangles)
    /// would otherwise force balls far below it, and the surface around them would be refined
    /// down to that scale. The balls at the smallest size cover such a zigzag anyway.
    fn thin_bends(&mut self, min_sep: f64) {
        if min_sep <= 0.0 {
            return;
        }
        let l = self.line.length();
        let closed = self.ends.is_none();
        let mut kept: Vec<f64> = Vec::with_capacity(self.bends.len());
        for &s in &self.bends {
            let after = kept
                .last()
                .map_or(!closed && s < min_sep, |&k| s - k < min_sep);
            if !after && (closed || l - s >= min_sep) {
                kept.push(s);
            }
        }
        // Around a closed curve the last bend also has the first one after it.
        while closed && kept.len() > 1 && kept[0] + l - kept[kept.len() - 1] < min_sep {
            kept.pop();
        }
        self.bends = kept;
    }

    /// A lower bound on the distance from `p` to the piece.
    fn distance_bound(&self, p: Point3) -> f64 {
        let (lo, hi) = self.bounds;
        (lo - p).max(p - hi).max(Point3::ZERO).length()
    }
}

/// Maps a point of a curve's polyline onto the curve itself (the domain's
/// [`Oracle::project_to_curve`](crate::oracle::Oracle::project_to_curve)).
pub type OntoCurve<'a> = dyn Fn(CurveId, Point3) -> Point3 + 'a;

/// Place protecting balls on `curves` and `corners`. `edge_size` bounds the radii (evaluated at
/// the centre with the curve id as label; corners use label 0); `limits` bounds the work: no
/// radius below `limits.min_radius` (features closer than that are protected at that size
/// rather than refused), at most `limits.max_balls` balls, no round past the deadline. Centres
/// are placed along the polylines and moved onto the curves by `onto_curve`, before the rules
/// are checked, so the rules hold for the balls as inserted.
pub fn protect(
    curves: &[FeatureCurve],
    corners: &[Point3],
    edge_size: &Sizing,
    limits: &ProtectLimits,
    onto_curve: &OntoCurve<'_>,
) -> Result<Protection, ProtectError> {
    let mut corners: Vec<Point3> = corners.to_vec();
    if let Some(index) = corners.iter().position(|p| !p.is_finite()) {
        return Err(ProtectError::BadCorner { index });
    }
    let mut lines = Vec::with_capacity(curves.len());
    for c in curves {
        let line =
            Polyline::new(&c.points, c.closed).ok_or(ProtectError::BadCurve { curve: c.id })?;
        lines.push((c.id, line));
    }
    // Tolerance for a corner to lie on a curve: relative to the features' extent.
    let scale = lines
        .iter()
        .flat_map(|(_, l)| l.points().iter())
        .chain(corners.iter())
        .fold(0.0f64, |m, p| m.max(p.abs().max_element()));
    let tol = 1e-12 * scale.max(f64::MIN_POSITIVE);
    // Open curve ends are corners too.
    for (_, line) in &lines {
        if !line.is_closed() {
            for p in [line.start(), line.end()] {
                if !corners.iter().any(|q| q.distance(p) <= tol) {
                    corners.push(p);
                }
            }
        }
    }
    let mut pieces = Vec::new();
    for (id, line) in &lines {
        split_at_corners(*id, line, &corners, tol, limits.bend_tolerance, &mut pieces);
    }
    let min_radius = limits.min_radius;
    for piece in &mut pieces {
        piece.thin_bends(min_radius);
    }
    let mut corner_limit = vec![f64::INFINITY; corners.len()];
    let grid = feature_grid(&pieces, &corners);
    let mut placed = vec![None; pieces.len()];
    for _ in 0..MAX_ROUNDS {
        if limits.deadline.is_some_and(|d| Instant::now() > d) {
            return Err(ProtectError::TimeLimit);
        }
        let features = Features {
            pieces: &pieces,
            corners: &corners,
            grid: &grid,
        };
        let protection = populate(
            &features,
            &corner_limit,
            edge_size,
            limits,
            onto_curve,
            &mut placed,
        )?;
        let mut shrunk = false;
        for (ball, radius) in violations(&protection, &pieces) {
            // A ball already at the smallest radius stays as it is (CGAL's special balls).
            if protection.balls[ball].radius <= min_radius {
                continue;
            }
            let radius = radius.max(min_radius);
            shrunk = true;
            match owner(&protection, ball) {
                Owner::Corner(k) => corner_limit[k] = corner_limit[k].min(radius),
                Owner::Piece(i, s) => pieces[i].limits.push((s, radius)),
            }
        }
        if !shrunk {
            return Ok(protection);
        }
    }
    Err(ProtectError::NotSettled { rounds: MAX_ROUNDS })
}

enum Owner {
    Corner(usize),
    /// Piece index and arc length of the centre.
    Piece(usize, f64),
}

/// Which corner or piece placed ball `b`.
fn owner(p: &Protection, b: usize) -> Owner {
    if b < p.corners.len() {
        return Owner::Corner(b);
    }
    for (i, chain) in p.chains.iter().enumerate() {
        if let Some(k) = chain.balls.iter().position(|&x| x == b) {
            return Owner::Piece(i, p.chain_params[i][k]);
        }
    }
    Owner::Corner(0)
}

/// Cut a curve at the corners lying on it (other than its ends).
fn split_at_corners(
    id: CurveId,
    line: &Polyline,
    corners: &[Point3],
    tol: f64,
    bend_tolerance: f64,
    out: &mut Vec<Piece>,
) {
    let mut cuts: Vec<(f64, usize)> = corners
        .iter()
        .enumerate()
        .filter_map(|(k, &c)| {
            let p = line.project(c);
            (p.distance <= tol).then_some((p.s, k))
        })
        .collect();
    cuts.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    cuts.dedup_by(|a, b| (a.0 - b.0).abs() <= tol);
    let l = line.length();
    if line.is_closed() {
        if cuts.is_empty() {
            out.push(Piece::new(id, line.clone(), None, bend_tolerance));
            return;
        }
        for i in 0..cuts.len() {
            let (s0, k0) = cuts[i];
            let (mut s1, k1) = cuts[(i + 1) % cuts.len()];
            if s1 <= s0 {
                s1 += l;
            }
            push_piece(id, line, (s0, s1), [k0, k1], bend_tolerance, out);
        }
    } else {
        // The ends are corners (added by the caller); interior corners cut the curve.
        let nearest = |p: Point3| {
            (0..corners.len())
                .min_by(|&a, &b| corners[a].distance(p).total_cmp(&corners[b].distance(p)))
                .unwrap_or(0)
        };
        cuts.retain(|&(s, _)| s > tol && s < l - tol);
        cuts.insert(0, (0.0, nearest(line.start())));
        cuts.push((l, nearest(line.end())));
        for w in cuts.windows(2) {
            if w[1].0 > w[0].0 {
                push_piece(
                    id,
                    line,
                    (w[0].0, w[1].0),
                    [w[0].1, w[1].1],
                    bend_tolerance,
                    out,
                );
            }
        }
    }
}

fn push_piece(
    id: CurveId,
    line: &Polyline,
    (s0, s1): (f64, f64),
    ends: [usize; 2],
    bend_tolerance: f64,
    out: &mut Vec<Piece>,
) {
    if let Some(sub) = Polyline::new(&line.arc_points(s0, s1), false) {
        out.push(Piece::new(id, sub, Some(ends), bend_tolerance));
    }
}

/// Distance from `p` to the features other than piece `i`: other corners and pieces, ignoring
/// the parts of neighbouring pieces inside the ball of a shared corner. Distances of `cap` or
/// more are not looked for (`cap` is returned).
fn distance_to_other_features(
    features: &Features<'_>,
    i: usize,
    p: Point3,
    corner_radius: &[f64],
    cap: f64,
) -> f64 {
    let Features {
        pieces,
        corners,
        grid,
    } = features;
    let own = pieces[i].ends;
    let mut d = cap;
    for item in grid.near(p, cap) {
        match item {
            Item::Corner(k) => {
                let k = k as usize;
                if own.is_none_or(|e| !e.contains(&k)) {
                    d = d.min(corners[k].distance(p));
                }
            }
            Item::Curve(j) => {
                let (j, piece) = (j as usize, &pieces[j as usize]);
                if j == i || piece.distance_bound(p) >= d {
                    continue;
                }
                let shared = match (own, piece.ends) {
                    (Some(a), Some(b)) => a.iter().copied().find(|k| b.contains(k)),
                    _ => None,
                };
                // Each distance is taken below `d`: only a nearer piece changes it.
                d = match shared {
                    Some(k) => piece
                        .line
                        .distance_outside_ball(p, corners[k], corner_radius[k], d),
                    None => piece.line.distance_below(p, d),
                };
            }
        }
    }
    d
}

/// The pieces and corners of the features, with a grid over them for nearest-feature queries.
/// (The grid depends on the geometry only, so it outlives the rounds that change the pieces'
/// limits.)
struct Features<'a> {
    pieces: &'a [Piece],
    corners: &'a [Point3],
    grid: &'a FeatureGrid,
}

/// The grid of the pieces and corners.
fn feature_grid(pieces: &[Piece], corners: &[Point3]) -> FeatureGrid {
    let lines = pieces.iter().map(|p| (p.line.points(), p.line.is_closed()));
    FeatureGrid::new(lines, corners)
}

/// The radius of the ball centred at arc length `s` of piece `i`.
fn piece_radius(
    features: &Features<'_>,
    i: usize,
    s: f64,
    corner_radius: &[f64],
    edge_size: &Sizing,
) -> f64 {
    let piece = &features.pieces[i];
    let p = piece.line.point_at(s);
    let mut r = edge_size.at(p, piece.curve.0);
    if let Some([a, b]) = piece.ends {
        r = r.min(corner_radius[a] + GROWTH * s);
        r = r.min(corner_radius[b] + GROWTH * (piece.line.length() - s));
    }
    for &(s0, r0) in &piece.limits {
        r = r.min(r0 + GROWTH * piece.line.geodesic_distance(s, s0));
    }
    r = r.min(piece.bend_cap(s));
    let cap = r / FEATURE_FRACTION;
    r.min(FEATURE_FRACTION * distance_to_other_features(features, i, p, corner_radius, cap))
}

/// The interior balls a round placed on a piece, and what they were placed from: a piece's balls
/// depend only on its own limits, the radii of its end corners and the ball budget left, so a
/// later round whose inputs for the piece are the same reuses them (most rounds shrink a few
/// balls on a few pieces, and placing is the cost of a round).
#[derive(Clone)]
struct PlacedPiece {
    /// The number of the piece's limits (they only grow), its end corners' radii, the budget.
    key: (usize, [f64; 2], usize),
    /// Arc length, centre and radius of each interior ball.
    balls: Vec<(f64, Point3, f64)>,
}

/// Balls for the current limits: corners first, then each piece's chain, centred on the curves
/// (`onto_curve`); `placed` keeps each piece's balls from round to round.
fn populate(
    features: &Features<'_>,
    corner_limit: &[f64],
    edge_size: &Sizing,
    limits: &ProtectLimits,
    onto_curve: &OntoCurve<'_>,
    placed: &mut [Option<PlacedPiece>],
) -> Result<Protection, ProtectError> {
    let Features {
        pieces, corners, ..
    } = *features;
    let corner_radius: Vec<f64> = corners
        .iter()
        .enumerate()
        .map(|(k, &c)| {
            let mut d = f64::INFINITY;
            for (j, &q) in corners.iter().enumerate() {
                if j != k {
                    d = d.min(q.distance(c));
                }
            }
            // The pieces ending here: room for their own balls between the corner balls.
            let mut incident = f64::INFINITY;
            for piece in pieces {
                if let Some([a, b]) = piece.ends.filter(|e| e.contains(&k)) {
                    // Up to the first bend from this end: a bend is always a centre.
                    let l = piece.line.length();
                    let first = piece.bends.first().map_or(l, |&s| s);
                    let last = piece.bends.last().map_or(l, |&s| l - s);
                    if a == k {
                        incident = incident.min(first);
                    }
                    if b == k {
                        incident = incident.min(last);
                    }
                } else if piece.distance_bound(c) < d {
                    d = piece.line.distance_below(c, d);
                }
            }
            edge_size
                .at(c, 0)
                .min(FEATURE_FRACTION * d)
                .min(INCIDENT_FRACTION * incident)
                .min(corner_limit[k])
                .max(limits.min_radius)
        })
        .collect();
    let mut protection = Protection {
        balls: corners
            .iter()
            .zip(&corner_radius)
            .enumerate()
            .map(|(k, (&center, &radius))| ProtectingBall {
                center,
                radius,
                feature: Feature::Corner(k as u32),
            })
            .collect(),
        chains: Vec::with_capacity(pieces.len()),
        corners: corners.to_vec(),
        chain_params: Vec::new(),
    };
    let mut params = Vec::with_capacity(pieces.len());
    for (i, piece) in pieces.iter().enumerate() {
        let budget = limits.max_balls.saturating_sub(protection.balls.len());
        let end_radii = piece
            .ends
            .map_or([0.0; 2], |[a, b]| [corner_radius[a], corner_radius[b]]);
        let key = (piece.limits.len(), end_radii, budget);
        let balls = match &placed[i] {
            Some(p) if p.key == key => &p.balls,
            _ => {
                let balls = place_balls(features, i, &corner_radius, edge_size, limits, budget)?
                    .into_iter()
                    .map(|(s, radius)| (s, onto_curve(piece.curve, piece.line.point_at(s)), radius))
                    .collect();
                &placed[i].insert(PlacedPiece { key, balls }).balls
            }
        };
        let mut chain = Vec::with_capacity(balls.len() + 2);
        let mut chain_s = Vec::with_capacity(balls.len() + 2);
        if let Some([a, _]) = piece.ends {
            chain.push(a);
            chain_s.push(0.0);
        }
        for &(s, center, radius) in balls {
            chain.push(protection.balls.len());
            chain_s.push(s);
            protection.balls.push(ProtectingBall {
                center,
                radius,
                feature: Feature::Curve(piece.curve),
            });
        }
        if let Some([_, b]) = piece.ends {
            chain.push(b);
            chain_s.push(piece.line.length());
        }
        protection.chains.push(Chain {
            curve: piece.curve,
            balls: chain,
            closed: piece.ends.is_none(),
        });
        params.push(chain_s);
    }
    protection.chain_params = params;
    Ok(protection)
}

/// The interior balls of piece `i` for the current limits, as arc lengths and radii, within
/// `budget` balls.
fn place_balls(
    features: &Features<'_>,
    i: usize,
    corner_radius: &[f64],
    edge_size: &Sizing,
    limits: &ProtectLimits,
    budget: usize,
) -> Result<Vec<(f64, f64)>, ProtectError> {
    let piece = &features.pieces[i];
    let radius =
        |s: f64| piece_radius(features, i, s, corner_radius, edge_size).max(limits.min_radius);
    let l = piece.line.length();
    let (from, to) = match piece.ends {
        Some([a, b]) => (
            corner_radius[a].min(0.5 * l),
            (l - corner_radius[b]).max(0.5 * l),
        ),
        None => (0.0, l),
    };
    let positions =
        place_on_piece(piece, from, to, &radius, budget).ok_or(ProtectError::TooManyBalls {
            limit: limits.max_balls,
        })?;
    let gaps = gaps_along(&positions, l, piece.ends.is_none());
    Ok(positions
        .iter()
        .zip(gaps)
        .map(|(&s, gap)| {
            let r = radius(s).min(GAP_FRACTION * gap).max(limits.min_radius);
            (s, r)
        })
        .collect())
}

/// For each ball of a chain (arc lengths `positions` on a piece of length `length`), the arc
/// length to its nearer chain neighbour, the corner balls of an open piece left out: a ball no
/// larger than a fraction of both gaps next to it is disjoint from the balls two steps away
/// along a straight run, whatever the spacing the run's length forced.
fn gaps_along(positions: &[f64], length: f64, closed: bool) -> Vec<f64> {
    let n = positions.len();
    (0..n)
        .map(|k| {
            let prev = if k > 0 {
                positions[k] - positions[k - 1]
            } else if closed && n > 1 {
                positions[0] + length - positions[n - 1]
            } else {
                f64::INFINITY
            };
            let next = if k + 1 < n {
                positions[k + 1] - positions[k]
            } else if closed && n > 1 {
                positions[0] + length - positions[n - 1]
            } else {
                f64::INFINITY
            };
            prev.min(next)
        })
        .collect()
}

/// Arc lengths of the interior balls of a curve piece. Every bend of the polyline is a centre,
/// so that the chords joining consecutive centres follow the input exactly; the straight runs
/// between bends (and the boundaries `from`, `to` of an open piece's corner balls) are filled by
/// [`spread`]. The parameters of a closed piece are in `[0, length)`, in chain order.
/// `None` when more than `budget` balls would be needed.
fn place_on_piece(
    piece: &Piece,
    from: f64,
    to: f64,
    radius: &dyn Fn(f64) -> f64,
    budget: usize,
) -> Option<Vec<f64>> {
    let (line, bends) = (&piece.line, piece.bends.clone());
    if piece.ends.is_none() {
        let Some(&first) = bends.first() else {
            return spread(line, true, 0.0, line.length(), radius, 3, budget);
        };
        // A closed curve needs three balls at least: split each run into enough intervals.
        let min_intervals = 3usize.div_ceil(bends.len());
        let mut out = Vec::new();
        for (k, &s0) in bends.iter().enumerate() {
            let s1 = bends.get(k + 1).copied().unwrap_or(first + line.length());
            let run = spread(
                line,
                false,
                s0,
                s1,
                radius,
                min_intervals,
                budget - out.len(),
            )?;
            out.extend(run[..run.len() - 1].iter().map(|&s| line.normalize(s)));
            if out.len() > budget {
                return None;
            }
        }
        return Some(out);
    }
    let mut anchors: Vec<f64> = bends;
    for s in [from, to] {
        if !anchors
            .iter()
            .any(|&a| (a - s).abs() <= ANCHOR_MERGE * radius(s))
        {
            anchors.push(s);
        }
    }
    anchors.sort_by(f64::total_cmp);
    let mut out = vec![anchors[0]];
    for w in anchors.windows(2) {
        let budget = budget.checked_sub(out.len())?;
        out.extend_from_slice(&spread(line, false, w[0], w[1], radius, 1, budget)?[1..]);
    }
    (out.len() <= budget).then_some(out)
}

/// Arc lengths of the polyline vertices where the curve bends: greedily, the vertices that end
/// the longest runs whose intermediate vertices all lie on the chord of the run (within a
/// rounding tolerance relative to the curve's extent, or within `tolerance` when larger). The
/// ends of an open curve are not listed; a closed curve's first vertex is listed only when the
/// curve bends there.
fn bends(line: &Polyline, tolerance: f64) -> Vec<f64> {
    let pts = line.points();
    let n = pts.len();
    let (lo, hi) = pts
        .iter()
        .fold((pts[0], pts[0]), |(lo, hi), &p| (lo.min(p), hi.max(p)));
    let tol = (COLLINEAR * lo.distance(hi)).max(tolerance);
    let count = if line.is_closed() { n + 1 } else { n };
    let at = |i: usize| pts[i % n];
    let straight =
        |a: usize, b: usize| (a + 1..b).all(|k| point_segment_distance(at(k), at(a), at(b)) <= tol);
    let mut ends = Vec::new();
    let mut start = 0;
    let mut end = 1;
    // A vertex where the curve turns sharply stays a bend whatever the tolerance: cutting it
    // within the tolerance would round a real corner of the curve off.
    let sharp = |k: usize| {
        let (a, b, c) = (at(k + n - 1), at(k), at(k + 1));
        (b - a).angle_between(c - b) > SHARP_TURN
    };
    while end + 1 < count {
        if end + 1 - start <= MAX_RUN
            && !(tolerance > 0.0 && sharp(end))
            && straight(start, end + 1)
        {
            end += 1;
        } else {
            ends.push(end);
            start = end;
            end += 1;
        }
    }
    // A closed curve bends at its first vertex unless the run ending there goes straight on.
    if let Some(&first) = ends.first()
        && line.is_closed()
        && !straight(start, n + first)
    {
        ends.insert(0, 0);
    }
    ends.into_iter().map(|i| line.arc_at(i)).collect()
}

/// Arc lengths of the interior balls of a curve piece, spread over `[from, to]`: equally spaced
/// in the measure `ds / (SPACING r)`, so that centres are about `SPACING` radii apart. An open
/// piece's first and last balls sit on the boundaries of its corner balls (`from`, `to`), so
/// they overlap them while the next ones do not.
fn spread(
    line: &Polyline,
    closed: bool,
    from: f64,
    to: f64,
    radius: &dyn Fn(f64) -> f64,
    min_intervals: usize,
    budget: usize,
) -> Option<Vec<f64>> {
    let floor = line.length() * 1e-9;
    // (s, u) samples of the cumulative measure.
    // Trapezoids: each radius evaluation (a distance query to every nearby feature) serves the
    // two steps it ends and starts.
    let mut samples = vec![(from, 0.0)];
    let (mut s, mut u) = (from, 0.0);
    let mut r = radius(s).max(floor);
    while s < to {
        let ds = (0.2 * r).min(to - s);
        let r_next = radius(s + ds).max(floor);
        u += 0.5 * ds * (1.0 / r + 1.0 / r_next) / SPACING;
        s += ds;
        r = r_next;
        samples.push((s, u));
        // Each sample step is a fifth of a radius: far past the budget, stop sampling.
        if u > budget as f64 + 1.0 {
            return None;
        }
    }
    let mut n = ((u - RUN_SLACK).ceil().max(0.0) as usize).max(min_intervals);
    // A run is straight (its ends are bends or corner-ball boundaries): two overlapping end
    // balls already cover it, and a ball between them would make them intersect without being
    // consecutive.
    if !closed && n > 1 && radius(from) + radius(to) > to - from {
        n = 1.max(min_intervals);
    }
    let count = if closed { n } else { n + 1 };
    let mut out = Vec::with_capacity(count);
    let mut j = 0;
    for k in 0..count {
        let target = u * k as f64 / n as f64;
        while j + 1 < samples.len() && samples[j + 1].1 < target {
            j += 1;
        }
        let (s0, u0) = samples[j];
        let (s1, u1) = samples[(j + 1).min(samples.len() - 1)];
        let t = if u1 > u0 {
            (target - u0) / (u1 - u0)
        } else {
            0.0
        };
        out.push(s0 + t.clamp(0.0, 1.0) * (s1 - s0));
    }
    Some(out)
}

/// Balls breaking a rule, with the radius each must shrink to: consecutive balls that do not
/// cover the curve between their centres, and other pairs that intersect.
fn violations(p: &Protection, pieces: &[Piece]) -> Vec<(usize, f64)> {
    let mut out = Vec::new();
    let mut links: Vec<(usize, usize)> = Vec::new();
    for (i, chain) in p.chains.iter().enumerate() {
        let params = p.chain_params[i].clone();
        let n = chain.balls.len();
        let count = if chain.closed { n } else { n - 1 };
        for k in 0..count {
            let (a, b) = (chain.balls[k], chain.balls[(k + 1) % n]);
            links.push((a.min(b), a.max(b)));
            let (s0, mut s1) = (params[k], params[(k + 1) % n]);
            if s1 <= s0 {
                s1 += pieces[i].line.length();
            }
            if !covers(&p.balls[a], &p.balls[b], &pieces[i].line.arc_points(s0, s1)) {
                out.push((a, 0.7 * p.balls[a].radius));
                out.push((b, 0.7 * p.balls[b].radius));
            }
        }
    }
    links.sort_unstable();
    links.dedup();
    // Sweep along x for intersecting pairs.
    let mut order: Vec<usize> = (0..p.balls.len()).collect();
    let lo = |b: usize| p.balls[b].center.x - p.balls[b].radius;
    order.sort_by(|&a, &b| lo(a).total_cmp(&lo(b)).then(a.cmp(&b)));
    for (k, &a) in order.iter().enumerate() {
        let ba = p.balls[a];
        for &b in &order[k + 1..] {
            let bb = p.balls[b];
            if lo(b) > ba.center.x + ba.radius {
                break;
            }
            let d = ba.center.distance(bb.center);
            if d >= ba.radius + bb.radius || links.binary_search(&(a.min(b), a.max(b))).is_ok() {
                continue;
            }
            let f = (0.9 * d / (ba.radius + bb.radius)).clamp(0.05, 0.9);
            out.push((a, f * ba.radius));
            out.push((b, f * bb.radius));
        }
    }
    out
}

/// Do two balls overlap and cover the polyline `arc` joining their centres? Each straight piece
/// of the arc is checked at a few points (the uncovered part of a segment is an interval).
fn covers(a: &ProtectingBall, b: &ProtectingBall, arc: &[Point3]) -> bool {
    if a.center.distance(b.center) >= a.radius + b.radius {
        return false;
    }
    let inside = |q: Point3| a.center.distance(q) < a.radius || b.center.distance(q) < b.radius;
    arc.windows(2)
        .all(|w| (0..=8).all(|k| inside(w[0] + (k as f64 / 8.0) * (w[1] - w[0]))))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The curves are the polylines themselves.
    fn on_polyline(_: CurveId, p: Point3) -> Point3 {
        p
    }

    fn curve(id: u32, points: &[[f64; 3]], closed: bool) -> FeatureCurve {
        FeatureCurve {
            id: CurveId(id),
            points: points.iter().map(|&p| Point3::from_array(p)).collect(),
            closed,
        }
    }

    /// The 12 edges of the unit cube as curves, and its 8 corners.
    fn cube() -> (Vec<FeatureCurve>, Vec<Point3>) {
        let corner = |i: usize| Point3::new((i & 1) as f64, ((i >> 1) & 1) as f64, (i >> 2) as f64);
        let mut curves = Vec::new();
        for a in 0..8 {
            for bit in [1, 2, 4] {
                if a & bit == 0 {
                    let id = curves.len() as u32 + 1;
                    curves.push(curve(
                        id,
                        &[corner(a).to_array(), corner(a | bit).to_array()],
                        false,
                    ));
                }
            }
        }
        (curves, (0..8).map(corner).collect())
    }

    /// Every rule of a protection, checked by brute force.
    /// A regular `n`-gon inscribed in the unit circle around `(x, 0, 0)` in the plane z = 0.
    fn circle(n: usize, x: f64) -> Vec<[f64; 3]> {
        (0..n)
            .map(|k| {
                let t = std::f64::consts::TAU * k as f64 / n as f64;
                [x + t.cos(), t.sin(), 0.0]
            })
            .collect()
    }

    fn assert_protects(p: &Protection, curves: &[FeatureCurve], max_radius: f64) {
        for chain in &p.chains {
            let line = curves
                .iter()
                .find(|c| c.id == chain.curve)
                .map(|c| Polyline::new(&c.points, c.closed).expect("valid"))
                .expect("chain of a known curve");
            for &b in &chain.balls {
                assert!(
                    line.project(p.balls[b].center).distance < 1e-12,
                    "centre off its curve"
                );
            }
        }
        assert_rules(p, curves, max_radius);
    }

    /// The rules of a protection whatever its centres: links overlap, other pairs are
    /// disjoint, the polylines are covered.
    fn assert_rules(p: &Protection, curves: &[FeatureCurve], max_radius: f64) {
        let mut linked = std::collections::BTreeSet::new();
        for chain in &p.chains {
            for (a, b) in chain.links() {
                let (ba, bb) = (p.balls[a], p.balls[b]);
                assert!(
                    ba.center.distance(bb.center) < ba.radius + bb.radius,
                    "link apart"
                );
                linked.insert((a.min(b), a.max(b)));
            }
        }
        for (i, a) in p.balls.iter().enumerate() {
            assert!(a.radius > 0.0 && a.radius <= max_radius);
            for (j, b) in p.balls.iter().enumerate().skip(i + 1) {
                if !linked.contains(&(i, j)) {
                    assert!(
                        a.center.distance(b.center) >= a.radius + b.radius,
                        "balls {i} and {j} are not consecutive but intersect"
                    );
                }
            }
        }
        // Every point of every curve is inside a ball.
        for c in curves {
            let line = Polyline::new(&c.points, c.closed).expect("valid");
            for k in 0..=400 {
                let q = line.point_at(line.length() * k as f64 / 400.0);
                assert!(
                    p.balls.iter().any(|b| b.center.distance(q) < b.radius),
                    "{q} uncovered"
                );
            }
        }
    }

    #[test]
    fn cube_edges_are_chains_between_exact_corners() {
        let (curves, corners) = cube();
        let p = protect_polylines(&curves, &corners, 0.2, 1e-6).expect("protects");
        assert_eq!(p.corners, corners);
        for (k, &c) in corners.iter().enumerate() {
            assert_eq!(p.balls[k].center, c);
            assert_eq!(p.balls[k].feature, Feature::Corner(k as u32));
        }
        assert_eq!(p.chains.len(), 12);
        for chain in &p.chains {
            assert!(!chain.closed && chain.balls.len() >= 3);
            assert!(chain.balls[0] < 8 && chain.balls[chain.balls.len() - 1] < 8);
        }
        assert_protects(&p, &curves, 0.2);
    }

    #[test]
    fn closed_circle_gets_a_closed_chain() {
        let pts = circle(256, 0.0);
        let curves = [
            curve(1, &pts, true),
            curve(
                2,
                &pts.iter().map(|p| [p[0], p[1], 1.0]).collect::<Vec<_>>(),
                true,
            ),
        ];
        let p = protect_polylines(&curves, &[], 0.1, 1e-6).expect("protects");
        assert!(p.corners.is_empty());
        assert_eq!(p.chains.len(), 2);
        assert!(p.chains.iter().all(|c| c.closed && c.balls.len() >= 3));
        assert_protects(&p, &curves, 0.1);
    }

    /// A polyline sampling a circle, whose domain maps points onto the circle: the curve balls
    /// are centred on the circle itself, off the chords, and the rules hold for those centres.
    #[test]
    fn centres_are_moved_onto_the_curve_the_polyline_samples() {
        let curves = [curve(1, &circle(32, 0.0), true)];
        let onto_circle = |_: CurveId, p: Point3| Point3::new(p.x, p.y, 0.0).normalize();
        // Runs of three chords stay within 0.05 of their chord: a bend (a centre, already on
        // the circle) every third vertex, the centres between inside chords.
        let followed = ProtectLimits {
            bend_tolerance: 0.05,
            ..limits(1e-6)
        };
        let p = protect(
            &curves,
            &[],
            &Sizing::Constant(0.1),
            &followed,
            &onto_circle,
        )
        .expect("protects");
        let line = Polyline::new(&curves[0].points, true).expect("valid");
        let mut off_chords = 0;
        for b in &p.balls {
            assert!((b.center.length() - 1.0).abs() < 1e-15, "{} off", b.center);
            // A chord's middle is 1 − cos(π/32) ≈ 4.8e-3 inside the circle.
            if line.project(b.center).distance > 1e-4 {
                off_chords += 1;
            }
        }
        assert!(off_chords > p.balls.len() / 2, "{off_chords} moved");
        assert_rules(&p, &curves, 0.1);
    }

    #[test]
    fn every_bend_of_a_polyline_is_a_ball_centre() {
        // A coarse closed polygon, an open zigzag with a collinear vertex (not a bend), and
        // ball sizes both above and below the segment lengths.
        let hexagon = circle(6, 3.0);
        let zigzag = [
            [0.0, 0.0, 0.0],
            [0.5, 0.4, 0.0],
            [1.0, 0.0, 0.0],
            [1.25, 0.0, 0.0],
            [1.5, 0.0, 0.0],
            [2.0, 0.5, 0.1],
        ];
        let curves = [curve(1, &hexagon, true), curve(2, &zigzag, false)];
        for size in [0.5, 0.05] {
            let p = protect_polylines(&curves, &[], size, 1e-9).expect("protects");
            assert_protects(&p, &curves, size);
            let is_centre = |q: [f64; 3]| {
                let q = Point3::from_array(q);
                p.balls.iter().any(|b| b.center.distance(q) < 1e-12)
            };
            for q in hexagon.iter().chain(&zigzag) {
                if q != &[1.25, 0.0, 0.0] {
                    assert!(is_centre(*q), "bend {q:?} is not a centre (size {size})");
                }
            }
            // Consecutive centres follow the input: each chord lies on the polyline.
            for chain in &p.chains {
                let c = curves.iter().find(|c| c.id == chain.curve).expect("known");
                let line = Polyline::new(&c.points, c.closed).expect("valid");
                for (a, b) in chain.links() {
                    let mid = p.balls[a].center.lerp(p.balls[b].center, 0.5);
                    assert!(line.project(mid).distance < 1e-12, "chord leaves the curve");
                }
            }
        }
        assert!(
            !protect_polylines(&curves, &[], 0.5, 1e-9)
                .expect("protects")
                .balls
                .iter()
                .any(|b| b.center == Point3::new(1.25, 0.0, 0.0)),
            "a collinear vertex is not a bend"
        );
    }

    /// A circle tessellated far finer than the edge size: within the bend tolerance its vertices
    /// are not centres, so the ball count follows the edge size; every input vertex stays within
    /// the tolerance of the chain's chords, and a polygon corner beyond it is still a centre.
    #[test]
    fn vertices_within_the_bend_tolerance_are_not_centres() {
        let n = 2000;
        let circle = circle(n, 0.0);
        // An open L, finely tessellated, with a right-angle bend at (4, 0, 0).
        let ell: Vec<[f64; 3]> = (0..=1000)
            .map(|k| {
                let t = k as f64 / 500.0;
                if t <= 1.0 {
                    [3.0 + t, 0.0, 0.0]
                } else {
                    [4.0, t - 1.0, 0.0]
                }
            })
            .collect();
        let curves = [curve(1, &circle, true), curve(2, &ell, false)];
        let size = 0.15;
        let tolerance = 2e-3;
        let exact = protect_polylines(&curves, &[], size, 1e-6).expect("protects");
        assert!(
            exact.balls.len() >= n,
            "without tolerance every vertex is a centre"
        );
        let bounded = ProtectLimits {
            bend_tolerance: tolerance,
            ..limits(1e-6)
        };
        let p = protect(
            &curves,
            &[],
            &Sizing::Constant(size),
            &bounded,
            &on_polyline,
        )
        .expect("protects");
        assert_protects(&p, &curves, size);
        // About 2π / (2 · 0.15 · SPACING-ish) balls: far fewer than the 2,000 vertices.
        assert!(p.balls.len() < 200, "{} balls", p.balls.len());
        let bend = Point3::new(4.0, 0.0, 0.0);
        assert!(p.balls.iter().any(|b| b.center.distance(bend) < 1e-12));
        for (chain, c) in p.chains.iter().zip(&curves) {
            let chords: Vec<(Point3, Point3)> = chain
                .links()
                .map(|(a, b)| (p.balls[a].center, p.balls[b].center))
                .collect();
            for &q in &c.points {
                let d = chords
                    .iter()
                    .map(|&(a, b)| point_segment_distance(q, a, b))
                    .fold(f64::INFINITY, f64::min);
                assert!(d <= 2.0 * tolerance, "vertex {q:?} is {d} from the chords");
            }
        }
    }

    #[test]
    fn sharp_angles_get_small_balls() {
        for degrees in [20.0f64, 5.0] {
            let t = degrees.to_radians();
            let tip = [0.0, 0.0, 0.0];
            let a = [1.0, 0.0, 0.0];
            let b = [t.cos(), t.sin(), 0.0];
            let curves = [
                curve(1, &[tip, a], false),
                curve(2, &[tip, b], false),
                curve(3, &[a, b], false),
            ];
            let p = protect_polylines(&curves, &[], 0.1, 1e-9).expect("protects");
            assert_eq!(p.corners.len(), 3);
            assert_protects(&p, &curves, 0.1);
        }
    }

    #[test]
    fn a_curve_through_a_corner_is_cut_there() {
        let curves = [curve(
            1,
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0]],
            false,
        )];
        let p =
            protect_polylines(&curves, &[Point3::new(1.0, 0.0, 0.0)], 0.1, 1e-6).expect("protects");
        assert_eq!(p.corners.len(), 3);
        assert_eq!(p.chains.len(), 2);
        assert_protects(&p, &curves, 0.1);
    }

    /// Guards with the given smallest radius.
    fn limits(min_radius: f64) -> ProtectLimits {
        ProtectLimits {
            min_radius,
            ..ProtectLimits::default()
        }
    }

    /// The protection most tests ask for: curves that are their own polylines, one ball size
    /// and default guards but the smallest radius.
    fn protect_polylines(
        curves: &[FeatureCurve],
        corners: &[Point3],
        size: f64,
        min_radius: f64,
    ) -> Result<Protection, ProtectError> {
        protect(
            curves,
            corners,
            &Sizing::Constant(size),
            &limits(min_radius),
            &on_polyline,
        )
    }

    #[test]
    fn touching_curves_are_protected_at_the_smallest_size() {
        let curves = [
            curve(1, &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0]], false),
            curve(2, &[[0.5, -1.0, 0.0], [0.5, 1.0, 0.0]], false),
        ];
        let p = protect_polylines(&curves, &[], 0.1, 1e-3).expect("protects");
        assert!(p.balls.iter().all(|b| b.radius >= 1e-3 && b.radius <= 0.1));
        // Far from the crossing, the balls keep the requested size.
        assert!(p.balls.iter().any(|b| b.radius == 0.1));
        let bad = [curve(3, &[[0.0, 0.0, 0.0]], false)];
        assert_eq!(
            protect_polylines(&bad, &[], 0.1, 1e-4),
            Err(ProtectError::BadCurve { curve: CurveId(3) })
        );
    }

    /// An image border's curve (labels_7118 of `benches/random_label_images.py`) bends two
    /// voxels from its corner, where the corner ball, at the two-voxel floor, ends: one centre
    /// there, not two an ulp apart.
    #[test]
    fn a_bend_on_a_corner_balls_boundary_is_one_centre() {
        let (a, b) = (
            [37.3618, 37.1886, 11.93162489013672],
            [37.3618, 37.1886, 16.88923010986328],
        );
        let curves = [
            curve(
                1,
                &[
                    a,
                    [33.62562, 37.1886, 11.93162489013672],
                    [30.804329780273438, 37.1886, 13.998701],
                    b,
                ],
                false,
            ),
            curve(2, &[a, b], false),
        ];
        let corners = [Point3::from_array(a), Point3::from_array(b)];
        let min_radius = 2.0 * 1.86809;
        let p = protect_polylines(&curves, &corners, 3.12, min_radius).expect("protects");
        for (i, x) in p.balls.iter().enumerate() {
            for y in &p.balls[i + 1..] {
                assert!(
                    x.center.distance(y.center) > 0.1 * min_radius,
                    "{x:?} {y:?}"
                );
            }
        }
    }

    #[test]
    fn guards_bound_the_number_of_balls_and_the_time() {
        let (curves, corners) = cube();
        let tiny = Sizing::Constant(1e-300);
        let bounded = ProtectLimits {
            max_balls: 1000,
            ..limits(1e-300)
        };
        assert_eq!(
            protect(&curves, &corners, &tiny, &bounded, &on_polyline),
            Err(ProtectError::TooManyBalls { limit: 1000 })
        );
        // The smallest radius wins over the edge size: 12 edges of length 1 at radius 0.01.
        let p = protect_polylines(&curves, &corners, 1e-300, 0.01).expect("protects");
        assert!(p.balls.iter().all(|b| b.radius >= 0.01));
        assert!(p.balls.len() <= 12 * 100 + 8);
        let past = ProtectLimits {
            deadline: Some(Instant::now()),
            ..limits(1e-3)
        };
        std::thread::sleep(std::time::Duration::from_millis(2));
        assert_eq!(
            protect(
                &curves,
                &corners,
                &Sizing::Constant(0.1),
                &past,
                &on_polyline
            ),
            Err(ProtectError::TimeLimit)
        );
    }
}
