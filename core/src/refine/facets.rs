//! The surface-facet level: restricted Delaunay facets and their surface Delaunay balls
//! (thesis, ch. 3, rules R1 and R2; R3.2 through `check`).
//!
//! A facet is restricted to the boundary when its dual Voronoi edge (the segment joining the
//! circumcentres of its two cells, or a ray when one cell is infinite) crosses the boundary. Each
//! crossing is the centre of an empty ball through the facet's vertices: a surface Delaunay ball.
//! The ball is stored in both cells sharing the facet, as CGAL does, so that a cell knows its
//! boundary facets without a global facet map.

use super::criteria::{FacetCriteria, FeatureExemption};
use super::engine::{Candidate, Check, MesherLevel};
use super::geometry::{
    cell_vertices, clipped_dual_edge, crowds_a_vertex, dual_parameter, facet_normal_away_from_apex,
    facet_vertices, is_same_cell, triangle_circumcenter, triangle_min_angle_deg,
    weighted_triangle_circumcenter,
};
use super::queue::RefineQueue;
use crate::kernel::Point3;
use crate::oracle::{Aabb, Oracle, PatchId, SurfaceHit};
use crate::triangulation::{CellId, ConflictZone, InsertReport, Triangulation, VertexId};
use rustc_hash::FxHashSet;
use std::cell::RefCell;
use std::rc::Rc;

/// An empty ball centred on the boundary, through the vertices of a restricted facet.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceBall {
    /// The ball's centre, on the boundary.
    pub center: Point3,
    /// The squared radius.
    pub radius2: f64,
    /// The patch the centre lies on.
    pub patch: PatchId,
    /// Patch of another crossing of the facet's dual edge closer to the centre than the
    /// refinement floor (0: none): the two sheets are not resolved there, so vertices on either
    /// belong to the facet (see [`SurfaceLevel::off_patch`]).
    pub twin_patch: PatchId,
}

/// The facets whose dual edge the surface level found crossing no boundary, as a bit per facet of
/// each cell slot. Shared with the cell level, which labels a new cell like its old neighbour
/// across such a facet instead of querying the same segment again.
#[derive(Clone, Debug, Default)]
pub struct ClearFacets(Rc<RefCell<Vec<u8>>>);

impl ClearFacets {
    fn set(&self, c: CellId, i: usize, clear: bool) {
        let mut bits = self.0.borrow_mut();
        let k = c.0 as usize;
        if bits.len() <= k {
            bits.resize(k + 1, 0);
        }
        if clear {
            bits[k] |= 1 << i;
        } else {
            bits[k] &= !(1 << i);
        }
    }

    /// Whether the dual edge of facet `(c, i)` crosses no boundary, as last computed.
    pub fn is_clear(&self, c: CellId, i: usize) -> bool {
        self.0
            .borrow()
            .get(c.0 as usize)
            .is_some_and(|b| b & (1 << i) != 0)
    }
}

/// A queued facet: the cell it was seen from, the index of the opposite vertex, and the cell's
/// vertices at that time (to detect that the cell was destroyed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueuedFacet {
    /// The cell the facet was seen from.
    pub cell: CellId,
    /// The index in `cell` of the vertex opposite the facet.
    pub index: u8,
    /// Queued by R3.2 (a cell's circumcentre lies in its ball): refined whatever its quality.
    pub forced: bool,
    /// The cell's vertices when queued.
    pub vertices: [VertexId; 4],
}

/// Priority of facets with a vertex off the surface (R1) and of facets encroached by a cell's
/// refinement point (R3.2): before any R2 facet.
const URGENT: f64 = f64::INFINITY;

/// The level refining the restricted surface facets (R1, R2) with their surface balls.
pub struct SurfaceLevel<'o> {
    oracle: &'o dyn Oracle,
    /// The oracle's bounding box: dual edges are clipped to its neighbourhood.
    bbox: Aabb,
    criteria: FacetCriteria,
    /// Surface ball of each facet of each cell, indexed by `CellId` then by opposite vertex.
    balls: Vec<[Option<SurfaceBall>; 4]>,
    clear: ClearFacets,
    /// Vertices lying on the boundary (P0 and surface-ball centres), indexed by `VertexId`.
    on_surface: Vec<bool>,
    /// Patch of each surface vertex when patches are checked (rule R3 of chapter 4), indexed by
    /// `VertexId`; 0 for vertices on curves and corners, which lie on several patches.
    vertex_patch: Option<Vec<PatchId>>,
    queue: RefineQueue<QueuedFacet>,
    /// Squared radius under which a surface ball is never refined (see [`SurfaceLevel::min_radius`]).
    min_radius2: f64,
    /// Marks the cells created by the insertion being processed: `created_mark[c] == stamp`.
    created_mark: Vec<u64>,
    stamp: u64,
    hits: Vec<SurfaceHit>,
    zone: ConflictZone,
    /// Squared radius of the ball whose centre was last proposed.
    proposed_radius2: f64,
    /// Centres (as bits) of the surface balls whose refinement point was refused forever (inside
    /// a protecting ball, crowding a vertex): such a ball refuses no point of a lower level
    /// either, or the cell proposing it would bounce on it until dropped.
    stuck: FxHashSet<[u64; 3]>,
    /// Patch of the ball whose centre was last proposed.
    proposed_patch: PatchId,
}

impl<'o> SurfaceLevel<'o> {
    /// The level for the boundary of `oracle`, under `criteria`.
    pub fn new(oracle: &'o dyn Oracle, criteria: FacetCriteria) -> Self {
        SurfaceLevel {
            oracle,
            bbox: oracle.bounding_box(),
            criteria,
            balls: Vec::new(),
            clear: ClearFacets::default(),
            on_surface: Vec::new(),
            vertex_patch: None,
            queue: RefineQueue::default(),
            min_radius2: 0.0,
            stuck: FxHashSet::default(),
            created_mark: Vec::new(),
            stamp: 0,
            hits: Vec::new(),
            zone: ConflictZone::default(),
            proposed_radius2: 0.0,
            proposed_patch: PatchId(0),
        }
    }

    /// Never refine a facet whose surface ball is smaller than `r`, whatever the criteria or the
    /// repairs ask: near a seam finer than the mesh (micro-triangles of a CSG boolean, two sheets
    /// closer than the sizes), each refinement point can make a smaller facet next to it, and
    /// the cascade converges to a point instead of ending. Below the smallest protecting ball
    /// the surface is not resolved anyway.
    pub fn min_radius(mut self, r: f64) -> Self {
        self.min_radius2 = r * r;
        self
    }

    /// Also refine every restricted facet with a vertex on another patch than the facet's
    /// (rule R3 of chapter 4), so that each patch is meshed on its own: for piecewise-smooth
    /// domains, whose patches meet along sharp curves.
    pub fn check_patches(mut self) -> Self {
        self.vertex_patch = Some(Vec::new());
        self
    }

    /// The facets found crossing no boundary, kept up to date by this level (see [`ClearFacets`]).
    pub fn clear_facets(&self) -> ClearFacets {
        self.clear.clone()
    }

    /// Record that `v` lies on surface patch `patch` (0: on a curve or a corner, several patches).
    pub fn mark_on_patch(&mut self, v: VertexId, patch: PatchId) {
        self.mark_on_surface(v);
        if let Some(patches) = &mut self.vertex_patch {
            let i = v.0 as usize;
            if patches.len() <= i {
                patches.resize(i + 1, PatchId(0));
            }
            patches[i] = patch;
        }
    }

    /// Does a vertex of the facet lie on another patch than its ball's? Only when patches are
    /// checked; vertices on curves and corners are on every patch they bound, and vertices on
    /// the ball's unresolved twin sheet on the facet's: rule R3 would refine two sheets closer
    /// than the floor down to it, with points the complex then mostly leaves out.
    fn off_patch(&self, fv: &[VertexId; 3], ball: &SurfaceBall) -> bool {
        self.vertex_patch.as_ref().is_some_and(|patches| {
            fv.iter().any(|v| {
                let p = patches.get(v.0 as usize).copied().unwrap_or(PatchId(0));
                p != PatchId(0) && p != ball.patch && p != ball.twin_patch
            })
        })
    }

    /// Record that `v` lies on the boundary (the initial points are inserted by the caller).
    pub fn mark_on_surface(&mut self, v: VertexId) {
        let i = v.0 as usize;
        if self.on_surface.len() <= i {
            self.on_surface.resize(i + 1, false);
        }
        self.on_surface[i] = true;
    }

    /// Whether `v` was inserted on the boundary.
    pub fn is_on_surface(&self, v: VertexId) -> bool {
        self.on_surface.get(v.0 as usize).copied().unwrap_or(false)
    }

    /// The surface ball of the facet of `c` opposite its vertex `i`, if that facet is restricted.
    pub fn ball(&self, c: CellId, i: usize) -> Option<&SurfaceBall> {
        self.balls.get(c.0 as usize).and_then(|b| b[i].as_ref())
    }

    fn grow(&mut self, capacity: usize) {
        if self.balls.len() < capacity {
            self.balls.resize(capacity, [None; 4]);
            self.created_mark.resize(capacity, 0);
        }
    }

    /// The surface ball of facet `(c, i)`, computed from its dual Voronoi edge. When the edge
    /// crosses the boundary several times, the largest ball wins (thesis: the centre with the
    /// largest r/σ is inserted).
    fn compute_ball<T: Triangulation<Point = Point3>>(
        &mut self,
        tr: &T,
        c: CellId,
        i: usize,
    ) -> (Option<SurfaceBall>, bool) {
        let Some((from, to)) = self.dual_edge(tr, c, i) else {
            return (None, false);
        };
        self.hits.clear();
        self.oracle.segment_hits(from, to, &mut self.hits);
        // The ball is orthogonal to the vertices' balls: its squared radius is a power distance.
        let v = cell_vertices(tr, c)[(i + 1) % 4];
        let (a, w) = (tr.point(v), tr.weight(v));
        let ball = self
            .hits
            .iter()
            .map(|h| SurfaceBall {
                center: h.point,
                radius2: h.point.distance_squared(a) - w,
                patch: h.patch,
                twin_patch: PatchId(0),
            })
            .max_by(|x, y| x.radius2.total_cmp(&y.radius2))
            .map(|mut ball| {
                ball.twin_patch = self
                    .hits
                    .iter()
                    .find(|h| {
                        h.patch != ball.patch
                            && h.point.distance_squared(ball.center) < self.min_radius2
                    })
                    .map_or(PatchId(0), |h| h.patch);
                ball
            });
        (ball, self.hits.is_empty())
    }

    /// The dual Voronoi edge of facet `(c, i)`, clipped to the neighbourhood of the domain.
    ///
    /// Its ends, the circumcentres of `c` and of its neighbour, are found as parameters along
    /// the facet's normal line from each cell's apex rather than from the cells'
    /// circumcentres: the circumcentre of a nearly flat cell is 10¹⁴ away and may even come
    /// out on the wrong side, which would turn an edge far outside into a line through the
    /// whole domain. With weights (protecting balls) the line passes through the facet's
    /// weighted circumcentre and the ends are the cells' orthocentres.
    fn dual_edge<T: Triangulation<Point = Point3>>(
        &self,
        tr: &T,
        c: CellId,
        i: usize,
    ) -> Option<(Point3, Point3)> {
        let cell = cell_vertices(tr, c);
        let fv = facet_vertices(&cell, i);
        let [a, b, d] = fv.map(|v| tr.point(v));
        let weights = fv.map(|v| tr.weight(v));
        let n = tr.neighbor(c, i);
        let axis = facet_normal_away_from_apex([a, b, d], i).normalize_or_zero();
        let (center, radius2) = if weights == [0.0; 3] {
            let center = triangle_circumcenter(a, b, d);
            (center, center.distance_squared(a))
        } else {
            weighted_triangle_circumcenter([a, b, d], weights)
        };
        if axis == Point3::ZERO || !center.is_finite() {
            // Collinear facet vertices: no circumcircle, only the cells' circumcentres.
            let there = (!tr.is_infinite_cell(n)).then(|| tr.circumcenter(n));
            return Some((tr.circumcenter(c), there?))
                .filter(|(p, q)| p.is_finite() && q.is_finite());
        }
        // An apex of weight w is at power distance |x - apex|² - w: the same parameter as an
        // unweighted apex against a ball of squared radius `radius2 + w`.
        let t_here = if tr.is_infinite_cell(c) {
            f64::NEG_INFINITY
        } else {
            let apex = cell[i];
            -dual_parameter(center, radius2 + tr.weight(apex), -axis, tr.point(apex))
        };
        let t_there = if tr.is_infinite_cell(n) {
            f64::INFINITY
        } else {
            let apex = tr.cell(n).as_ref()[tr.mirror_index(c, i)];
            dual_parameter(center, radius2 + tr.weight(apex), axis, tr.point(apex))
        };
        clipped_dual_edge(center, axis, t_here, t_there, &self.bbox)
    }

    /// Why facet `(c, i)` with ball `ball` needs refinement, as a queue priority (`None`: good).
    fn badness<T: Triangulation<Point = Point3>>(
        &self,
        tr: &T,
        cell: &[VertexId; 4],
        i: usize,
        ball: &SurfaceBall,
    ) -> Option<f64> {
        if ball.radius2 < self.min_radius2 {
            return None;
        }
        let fv = facet_vertices(cell, i);
        if fv.iter().any(|&v| !self.is_on_surface(v)) || self.off_patch(&fv, ball) {
            return Some(URGENT);
        }
        let [a, b, c] = fv.map(|v| tr.point(v));
        let weights = fv.map(|v| tr.weight(v));
        // With weights (protecting balls), shape is measured against the smallest orthogonal
        // sphere, as CGAL does: a facet fanning around a heavy vertex is not a sliver.
        let weighted = weights != [0.0; 3];
        // Facets fanning out of protecting balls: CGAL's exemptions (see [`FeatureExemption`]).
        let exempt = if weighted {
            FeatureExemption::of_facet([a, b, c], weights)
        } else {
            FeatureExemption::default()
        };
        if exempt.all {
            return None;
        }
        let r = ball.radius2.sqrt();
        let size = self.criteria.size.at(ball.center, ball.patch.0);
        let mut worst: Option<f64> = None;
        let mut note = |q: f64| worst = Some(worst.map_or(q, |w: f64| w.max(q)));
        if r > size && !exempt.size {
            note(r / size);
        }
        let (center, radius2) = if weighted {
            weighted_triangle_circumcenter([a, b, c], weights)
        } else {
            (triangle_circumcenter(a, b, c), 0.0)
        };
        if self.criteria.angle_deg > 0.0 && !exempt.angle {
            let angle = if weighted {
                let shortest2 = a
                    .distance_squared(b)
                    .min(b.distance_squared(c))
                    .min(c.distance_squared(a));
                (0.5 * (shortest2 / radius2.max(f64::MIN_POSITIVE)).sqrt())
                    .min(1.0)
                    .asin()
                    .to_degrees()
            } else {
                triangle_min_angle_deg(a, b, c)
            };
            if angle < self.criteria.angle_deg {
                note(self.criteria.angle_deg / angle.max(1e-9));
            }
        }
        let distance = self.criteria.distance.at(ball.center, ball.patch.0);
        if distance.is_finite() && !exempt.distance {
            let d = center.distance(ball.center);
            if d > distance {
                note(d / distance);
            }
        }
        worst
    }

    /// Recompute facet `(c, i)` and its mirror, and queue it when bad.
    fn update_facet<T: Triangulation<Point = Point3>>(&mut self, tr: &T, c: CellId, i: usize) {
        let (ball, clear) = self.compute_ball(tr, c, i);
        self.balls[c.0 as usize][i] = ball;
        self.clear.set(c, i, clear);
        let n = tr.neighbor(c, i);
        if !tr.is_infinite_cell(n) {
            let j = tr.mirror_index(c, i);
            self.balls[n.0 as usize][j] = ball;
            self.clear.set(n, j, clear);
        }
        if let Some(ball) = ball {
            let cell = cell_vertices(tr, c);
            if let Some(priority) = self.badness(tr, &cell, i, &ball) {
                self.queue.push(
                    priority,
                    QueuedFacet {
                        cell: c,
                        index: i as u8,
                        forced: false,
                        vertices: cell,
                    },
                );
            }
        }
    }

    /// Queue the restricted facet `(c, i)` for refinement whatever its quality, first in line:
    /// a facet at a non-manifold spot of the boundary or on a component with the wrong topology.
    pub fn force<T: Triangulation<Point = Point3>>(&mut self, tr: &T, c: CellId, i: usize) {
        if tr.is_live(c) && self.ball(c, i).is_some() {
            self.queue.push(
                URGENT,
                QueuedFacet {
                    cell: c,
                    index: i as u8,
                    forced: true,
                    vertices: cell_vertices(tr, c),
                },
            );
        }
    }

    /// Every restricted facet once, as `(cell, opposite vertex index, ball)`, in cell order.
    pub fn restricted_facets<'s, T: Triangulation<Point = Point3>>(
        &'s self,
        tr: &'s T,
    ) -> impl Iterator<Item = (CellId, usize, SurfaceBall)> + 's {
        tr.finite_cells().flat_map(move |c| {
            (0..4).filter_map(move |i| {
                let ball = *self.ball(c, i)?;
                let n = tr.neighbor(c, i);
                (tr.is_infinite_cell(n) || c.0 < n.0).then_some((c, i, ball))
            })
        })
    }
}

impl<'o, T: Triangulation<Point = Point3>> MesherLevel<T> for SurfaceLevel<'o> {
    type Element = QueuedFacet;

    fn name(&self) -> &'static str {
        "surface facets"
    }

    fn scan(&mut self, tr: &T) {
        self.grow(tr.cell_capacity());
        let cells: Vec<CellId> = tr.finite_cells().collect();
        for c in cells {
            for i in 0..4 {
                let n = tr.neighbor(c, i);
                if tr.is_infinite_cell(n) || c.0 < n.0 {
                    self.update_facet(tr, c, i);
                }
            }
        }
    }

    fn next_element(&mut self, tr: &T) -> Option<QueuedFacet> {
        while let Some(&f) = self.queue.peek() {
            let i = f.index as usize;
            if is_same_cell(tr, f.cell, &f.vertices) {
                // The neighbour may have changed since queuing: judge the facet as it is now.
                if let Some(ball) = self.balls[f.cell.0 as usize][i] {
                    let forced = f.forced && ball.radius2 >= self.min_radius2;
                    if forced || self.badness(tr, &f.vertices, i, &ball).is_some() {
                        return Some(f);
                    }
                }
            }
            self.queue.pop();
        }
        None
    }

    fn pop_element(&mut self) {
        self.queue.pop();
    }

    fn drop_element(&mut self) {
        if let Some(&f) = self.queue.peek()
            && let Some(ball) = self.balls[f.cell.0 as usize][f.index as usize]
        {
            self.stuck.insert(center_bits(ball.center));
        }
        self.queue.pop();
    }

    fn refinement_point(&mut self, _tr: &T, f: &QueuedFacet) -> Option<Candidate<Point3>> {
        let ball = self.balls[f.cell.0 as usize][f.index as usize]?;
        self.proposed_radius2 = ball.radius2;
        self.proposed_patch = ball.patch;
        Some(Candidate {
            point: ball.center,
            hint: Some(f.cell),
        })
    }

    /// R3.2: a point of a lower level inside a surface ball is refused, and the facet queued.
    fn check(&mut self, tr: &T, c: &Candidate<Point3>, own: bool) -> Check {
        if own {
            return if crowds_a_vertex(tr, c, self.proposed_radius2) {
                Check::RejectedForever
            } else {
                Check::Accepted
            };
        }
        let mut zone = std::mem::take(&mut self.zone);
        tr.conflict_zone(c.point, c.hint, &mut zone);
        let mut verdict = Check::Accepted;
        'cells: for &cell in &zone.cells {
            if tr.is_infinite_cell(cell) {
                continue;
            }
            for i in 0..4 {
                // A ball below the floor is never refined, so it cannot refuse a point either
                // (the point's cell would be proposed again and again).
                if let Some(ball) = self.balls[cell.0 as usize][i]
                    && ball.radius2 >= self.min_radius2
                    && ball.center.distance_squared(c.point) < ball.radius2
                    && !self.stuck.contains(&center_bits(ball.center))
                {
                    let vertices = cell_vertices(tr, cell);
                    self.queue.push(
                        URGENT,
                        QueuedFacet {
                            cell,
                            index: i as u8,
                            forced: true,
                            vertices,
                        },
                    );
                    verdict = Check::Rejected;
                    break 'cells;
                }
            }
        }
        self.zone = zone;
        verdict
    }

    fn after_insertion(&mut self, tr: &T, v: VertexId, report: &InsertReport, own: bool) {
        if own {
            self.mark_on_patch(v, self.proposed_patch);
        }
        self.grow(tr.cell_capacity());
        self.stamp += 1;
        for &c in &report.removed {
            self.balls[c.0 as usize] = [None; 4];
        }
        for &c in &report.created {
            self.created_mark[c.0 as usize] = self.stamp;
        }
        for &c in &report.created {
            if tr.is_infinite_cell(c) {
                continue;
            }
            for i in 0..4 {
                let n = tr.neighbor(c, i);
                let both_new =
                    self.created_mark[n.0 as usize] == self.stamp && !tr.is_infinite_cell(n);
                if !both_new || c.0 < n.0 {
                    self.update_facet(tr, c, i);
                }
            }
        }
    }

    fn pending(&self) -> usize {
        self.queue.len()
    }
}

/// A surface ball's centre as exact bits: a recomputed ball of the same facet has the same centre.
fn center_bits(p: Point3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}
