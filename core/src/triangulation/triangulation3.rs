//! `Triangulation3<K>`: the 3D triangulation engine shared by [`Delaunay3`] (Euclidean in-sphere
//! test) and [`Regular3`] (power test on weighted points), built by Bowyer–Watson insertion. The
//! conflict kernel `K` is a type parameter, so the Delaunay instance compiles to the same code as a
//! dedicated implementation: the hidden-vertex bookkeeping of regular triangulations sits behind
//! the constant [`ConflictKernel::WEIGHTED`].
//!
//! Storage is flat: one 32-byte record per cell slot (four vertex indices and four packed
//! neighbour references `cell << 2 | mirror index`), a free list threaded through dead slots, one
//! incident cell per vertex. An infinite vertex closes the hull. Each insertion walks to the point
//! (visibility walk from the last created cell), grows the cavity of cells in conflict under the
//! symbolic perturbation of [`crate::kernel::perturbation`], and stars it from the new vertex.
//!
//! Bulk construction from scratch numbers the points along a Hilbert curve and inserts them in
//! BRIO rounds; the large rounds are split into two parts inserted on two threads (module
//! `parallel`), in a way that makes the cell array the same on any number of cores.

mod cavity;
mod kernel;
#[allow(
    unsafe_code,
    reason = "two threads write disjoint cells of one shared store"
)]
mod parallel;
mod regular;
mod relocate;

use super::spatial_sort::{brio_order, brio_rounds, gather, hilbert_order};
use super::{
    CellId, ConflictZone, InsertOutcome, InsertReport, Triangulation, TriangulationError, VertexId,
};
use crate::kernel::{Point2, Point3, Sign, StaticFilter, WeightedPoint3, orient2d, orient3d};
use crate::random::XorShift;
use cavity::{ByteMarks, CavityMarks, CellWriter, HashMarks, NewCell, Scratch, grow_cavity};
pub use kernel::{ConflictKernel, Euclidean, Power};
pub use regular::MAX_WEIGHT;
pub use relocate::MoveReport;
use std::borrow::Cow;
use std::collections::HashMap;

/// Index of the infinite vertex in cell records.
const INFINITE: u32 = u32::MAX;
/// "No cell" in `vertex_cell` and at the end of the free list.
const NO_CELL: u32 = u32::MAX;
/// `v[0]` of a free cell slot.
const FREE: u32 = u32::MAX - 1;
/// Neighbour references pack a cell index in 30 bits; with about 6.7 cells per vertex (and room
/// for less favourable distributions) this many vertices keep every cell index below 2^30.
pub const MAX_VERTICES: usize = 1 << 27;
/// Coordinates beyond this magnitude could overflow the in-sphere determinant (degree 5).
pub const MAX_COORDINATE: f64 = 1e50;
/// Expected number of cells per vertex of a uniform 3D point set (≈ 6.75 in a cube), rounded
/// up with room for the slots the parallel build reserves and leaves unused: capacity reserved
/// for bulk construction so the cell array is not reallocated on the way.
const CELLS_PER_VERTEX: f64 = 7.0;
/// Seed of the BRIO shuffle: fixed, so construction is deterministic.
const BRIO_SEED: u64 = 0x5EED_DE1A_u64;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(C, align(32))]
struct CellRecord {
    v: [u32; 4],
    /// Neighbour across facet `i`, packed as `cell << 2 | index of the facet in that cell`.
    n: [u32; 4],
}

/// For a new cell whose facet `i` lies on the cavity boundary: its three side facets `j` with the
/// positions `(a, b)` of the boundary edge in each, ordered so that `(i, a, b, j)` is an even
/// permutation. Two positively oriented cells sharing a facet induce opposite orientations on it,
/// so the two new cells sharing a boundary edge list it in opposite directions.
const SIDE_EDGE: [[(usize, usize, usize); 3]; 4] = [
    [(1, 2, 3), (2, 3, 1), (3, 1, 2)],
    [(0, 3, 2), (2, 0, 3), (3, 2, 0)],
    [(0, 1, 3), (1, 3, 0), (3, 0, 1)],
    [(0, 2, 1), (1, 0, 2), (2, 1, 0)],
];

#[inline]
fn pack(c: u32, i: usize) -> u32 {
    (c << 2) | i as u32
}

/// The 3D Delaunay triangulation (see the module documentation and [`Triangulation`]).
pub type Delaunay3 = Triangulation3<Euclidean>;

/// The 3D regular (weighted Delaunay) triangulation: the weighted analogue of [`Delaunay3`], whose
/// cells have empty orthogonal spheres. A weighted point whose power cell would be empty is
/// *hidden*: it keeps its vertex id and point but belongs to no cell. Hidden vertices never come
/// back: insertion only makes power cells smaller, and vertices are never removed.
pub type Regular3 = Triangulation3<Power>;

/// A 3D triangulation closed by an infinite vertex, generic over its conflict kernel (use the
/// aliases [`Delaunay3`] and [`Regular3`]).
#[derive(Clone, Debug)]
pub struct Triangulation3<K: ConflictKernel> {
    points: Vec<Point3>,
    /// Vertex weights and hidden flags (nothing for Delaunay).
    kernel: K,
    vertex_cell: Vec<u32>,
    cells: Vec<CellRecord>,
    free_head: u32,
    num_live: usize,
    num_finite: usize,
    /// A recently created cell: where walks start without a hint.
    last: u32,
    /// Present until four affinely independent points have arrived.
    lower: Option<LowerDimension>,
    /// During bulk insertion `vertex_cell` is left stale and rebuilt once at the end, which saves
    /// four scattered writes per created cell.
    bulk: bool,
    /// Static predicate filters for the bounding box of the vertices.
    filter: StaticFilter,
    scratch: Scratch,
    /// The last vertex removal planned, for the next removal of the same vertex from the same
    /// star (see [`relocate`]).
    fill_memo: Option<Box<relocate::FillMemo>>,
}

/// Writes new cells into the cell array of a sequential insertion, counting the finite ones.
struct SequentialWriter<'a> {
    cells: &'a mut Vec<CellRecord>,
    finite: usize,
}

impl CellWriter for SequentialWriter<'_> {
    #[inline]
    fn place(&mut self, nc: &NewCell) {
        let v = nc.verts;
        self.cells[nc.id as usize] = nc.record();
        let out = nc.outside;
        self.cells[(out >> 2) as usize].n[(out & 3) as usize] = pack(nc.id, nc.apex as usize);
        self.finite += usize::from(v[0].max(v[1]).max(v[2].max(v[3])) != INFINITE);
    }

    #[inline]
    fn link(&mut self, facet: u32, neighbor: u32) {
        self.cells[(facet >> 2) as usize].n[(facet & 3) as usize] = neighbor;
    }
}

/// Where a [`Triangulation3::walk`] ends.
enum Walk {
    /// A cell whose closure contains the point.
    Found(u32),
    /// The walk was about to enter cell `at`, where it had to stop, from cell `before`.
    Stopped { before: u32, at: u32 },
}

/// Bookkeeping while the points span less than 3 dimensions (no cells exist yet).
#[derive(Clone, Debug, Default)]
struct LowerDimension {
    /// Exact coordinates → vertex, for duplicate detection without cells.
    seen: HashMap<[u64; 3], u32>,
    /// Affinely independent vertices found so far (at most three).
    basis: Vec<u32>,
    /// The other vertices, inserted once the cells exist.
    pending: Vec<u32>,
}

fn coordinate_key(p: Point3) -> [u64; 3] {
    // `+ 0.0` maps -0.0 to 0.0 so that equal points have equal keys.
    [
        (p.x + 0.0).to_bits(),
        (p.y + 0.0).to_bits(),
        (p.z + 0.0).to_bits(),
    ]
}

fn collinear(a: Point3, b: Point3, c: Point3) -> bool {
    // The cross product (b - a) × (c - a) vanishes iff its three projections' orientations do.
    let proj = |p: Point3, i: usize, j: usize| Point2::new(p[i], p[j]);
    [(0, 1), (1, 2), (2, 0)]
        .iter()
        .all(|&(i, j)| orient2d(proj(a, i, j), proj(b, i, j), proj(c, i, j)) == Sign::Zero)
}

/// Rejects points the exact predicates cannot handle.
pub(crate) fn validate_point(p: Point3, index: usize) -> Result<(), TriangulationError> {
    if !p.is_finite() {
        return Err(TriangulationError::NonFinite {
            index,
            x: p.x,
            y: p.y,
            z: p.z,
        });
    }
    if p.abs().max_element() > MAX_COORDINATE {
        return Err(TriangulationError::TooLarge {
            index,
            limit: MAX_COORDINATE,
        });
    }
    Ok(())
}

impl<K: ConflictKernel> Default for Triangulation3<K> {
    fn default() -> Self {
        Self::new()
    }
}

impl Delaunay3 {
    /// The Delaunay triangulation of `points` (inserted in a BRIO / Hilbert order; the result does
    /// not depend on the order). Fails without building anything if a point is not finite.
    pub fn from_points(points: &[Point3]) -> Result<Self, TriangulationError> {
        let mut dt = Self::new();
        dt.insert_points(points)?;
        Ok(dt)
    }

    /// Inserts many points in a spatially coherent order and returns the vertex of each input
    /// point (duplicates map to the same vertex). All points are validated before any is inserted.
    pub fn insert_points(
        &mut self,
        points: &[Point3],
    ) -> Result<Vec<VertexId>, TriangulationError> {
        self.insert_many(points, |_| 0.0)
    }

    /// Whether `p` conflicts with the live cell `c`: `p` is strictly inside its circumsphere under
    /// the symbolic perturbation (for an infinite cell: strictly beyond its hull facet, or on its
    /// plane and inside its circle). `p` must not be a vertex of `c`.
    pub fn is_in_conflict(&self, c: CellId, p: Point3) -> bool {
        self.query_conflict(c, p, 0.0)
    }
}

impl<K: ConflictKernel> Triangulation3<K> {
    /// [`Self::in_conflict`] for a query point, which need not be in the triangulation's box:
    /// the static filter's bounds hold only inside the box of the points it was sized for, so a
    /// query beyond it (the far circumcentre of a nearly flat cell) gets one grown to hold it.
    fn query_conflict(&self, c: CellId, p: Point3, w: f64) -> bool {
        self.conflicts(&self.query_filter(p), self.cells[c.0 as usize].v, p, w)
    }

    /// The static filter, grown to hold the query point `p` if it lies outside its box.
    fn query_filter(&self, p: Point3) -> Cow<'_, StaticFilter> {
        if self.filter.contains(p) {
            return Cow::Borrowed(&self.filter);
        }
        let mut filter = self.filter;
        filter.include(p);
        Cow::Owned(filter)
    }
}

impl<K: ConflictKernel> Triangulation3<K> {
    /// An empty triangulation.
    pub fn new() -> Self {
        Triangulation3 {
            points: Vec::new(),
            kernel: K::default(),
            vertex_cell: Vec::new(),
            cells: Vec::new(),
            free_head: NO_CELL,
            num_live: 0,
            num_finite: 0,
            last: NO_CELL,
            lower: Some(LowerDimension::default()),
            bulk: false,
            filter: StaticFilter::default(),
            scratch: Scratch::default(),
            fill_memo: None,
        }
    }

    /// Bulk insertion of validated points with the given weights (see [`Delaunay3::insert_points`]).
    fn insert_many(
        &mut self,
        points: &[Point3],
        weight: impl Fn(usize) -> f64,
    ) -> Result<Vec<VertexId>, TriangulationError> {
        for (i, &p) in points.iter().enumerate() {
            validate_point(p, i)?;
        }
        let total = self.points.len() + points.len();
        if total >= MAX_VERTICES {
            return Err(TriangulationError::TooManyElements);
        }
        self.points.reserve(points.len());
        self.vertex_cell.reserve(points.len());
        let want = (total as f64 * CELLS_PER_VERTEX) as usize + 64;
        self.cells
            .reserve_exact(want.saturating_sub(self.cells.len()));
        let mut vertex_of = vec![VertexId(0); points.len()];
        self.bulk = true;
        let mut result = Ok(());
        if self.points.is_empty() && !K::WEIGHTED {
            // Weighted points take the general path below, which resolves coincident points by
            // weight.
            let threaded = std::thread::available_parallelism().is_ok_and(|t| t.get() > 1);
            self.insert_fresh(points, want, threaded, &mut vertex_of);
        } else {
            for i in brio_order(points, BRIO_SEED) {
                let i = i as usize;
                match self.insert_validated(points[i], weight(i), None, None) {
                    Ok(outcome) => vertex_of[i] = outcome.vertex(),
                    Err(e) => {
                        result = Err(e);
                        break;
                    }
                }
            }
        }
        self.bulk = false;
        self.rebuild_vertex_cells();
        result.map(|()| vertex_of)
    }

    /// Bulk insertion into an empty triangulation of validated points, numbered along the
    /// Hilbert curve (so the points of any cell sit close together in memory) and inserted in
    /// BRIO order, large rounds in parallel parts when `threaded` (which changes nothing in the
    /// result). The cell array stays within `budget` slots. Sets `vertex_of[i]` to the vertex of
    /// `points[i]`.
    fn insert_fresh(
        &mut self,
        points: &[Point3],
        budget: usize,
        threaded: bool,
        vertex_of: &mut [VertexId],
    ) {
        let curve = hilbert_order(points);
        let sorted = gather(points, &curve);
        let mut distinct = Vec::with_capacity(sorted.len());
        for (&i, &p) in curve.iter().zip(&sorted) {
            if distinct.last() != Some(&p) {
                distinct.push(p);
            }
            vertex_of[i as usize] = VertexId((distinct.len() - 1) as u32);
        }
        drop(sorted);
        for &p in &distinct {
            self.filter.include(p);
            self.kernel.push_vertex(0.0);
        }
        self.vertex_cell.resize(distinct.len(), NO_CELL);
        self.points = distinct;
        let (order, rounds) = brio_rounds(self.points.len(), BRIO_SEED);
        let mut part_scratch = Vec::new();
        for round in rounds {
            let round = &order[round];
            if round.len() >= parallel::MIN_PARALLEL_ROUND && self.lower.is_none() {
                self.insert_round_parallel(round, budget, threaded, &mut part_scratch);
            } else {
                for &v in round {
                    self.insert_new_vertex(v, None, None);
                }
            }
        }
    }

    fn rebuild_vertex_cells(&mut self) {
        for (c, r) in self.cells.iter().enumerate() {
            if r.v[0] != FREE {
                for v in r.v {
                    if v != INFINITE {
                        self.vertex_cell[v as usize] = c as u32;
                    }
                }
            }
        }
    }

    /// A cell incident to `v` (`None` for the infinite vertex or before cells exist).
    pub fn vertex_cell(&self, v: VertexId) -> Option<CellId> {
        self.vertex_cell
            .get(v.0 as usize)
            .copied()
            .filter(|&c| c != NO_CELL)
            .map(CellId)
    }

    /// A cell with the edge `u v`, or `None` when `u v` is not an edge. The search walks through
    /// the cells around `u` towards `v`, crossing only facets through `u` that separate a cell
    /// from `v`: a few cells, where collecting `u`'s whole star would visit dozens, or thousands
    /// around a vertex where constraints meet at small angles. The cones at `u` of the cells
    /// around it tile the directions from `u`, and an edge from `u` is a ray on their
    /// boundaries, so the walk either meets `v` or ends in a cell whose closed cone holds the
    /// direction of `v` without it: then no edge `u v` exists. Walks that meet the outside of
    /// the hull, or go on too long, fall back on the whole star.
    pub fn edge_cell(&self, u: VertexId, v: VertexId) -> Option<CellId> {
        /// Longest walk before the whole star is searched instead.
        const MAX_STEPS: usize = 1024;
        if u == v {
            return None;
        }
        if u.0 == INFINITE || v.0 == INFINITE {
            return self.edge_cell_in_star(u, v);
        }
        let mut c = *self.vertex_cell.get(u.0 as usize)?;
        if c == NO_CELL || (v.0 as usize) >= self.points.len() {
            return None;
        }
        let p = self.pt(v.0);
        let mut prev = NO_CELL;
        let mut rnd = XorShift::new(u64::from(u.0) << 32 ^ u64::from(v.0) | 1);
        'walk: for _ in 0..MAX_STEPS {
            let r = self.cells[c as usize];
            if r.v.contains(&v.0) {
                return Some(CellId(c));
            }
            if Self::is_infinite_record(&r) {
                break;
            }
            let first = (rnd.next_u64() >> 62) as usize;
            for k in 0..4 {
                let i = (first + k) & 3;
                let next = r.n[i] >> 2;
                // Only facets through u (not the one opposite it) stay around u.
                if r.v[i] == u.0 || next == prev {
                    continue;
                }
                let mut t = r.v.map(|x| self.pt(x));
                t[i] = p;
                if self.filter.orient3d(t[0], t[1], t[2], t[3]) == Sign::Negative {
                    prev = c;
                    c = next;
                    continue 'walk;
                }
            }
            return None;
        }
        self.edge_cell_in_star(u, v)
    }

    /// [`Self::edge_cell`] by collecting the whole star of `u`.
    fn edge_cell_in_star(&self, u: VertexId, v: VertexId) -> Option<CellId> {
        let mut star = Vec::new();
        self.incident_cells(u, &mut star);
        star.into_iter()
            .find(|&c| self.cells[c.0 as usize].v.contains(&v.0))
    }

    /// A cell with the triangle `u v w`, or `None` when it is not a face: [`Self::edge_cell`]
    /// for `u v`, then a turn around that edge.
    pub fn face_cell(&self, [u, v, w]: [VertexId; 3]) -> Option<CellId> {
        let start = self.edge_cell(u, v)?.0;
        let r = self.cells[start as usize];
        // The cell's vertices off the edge: leave across the facet opposite `away`, keeping
        // `kept`; the next cell's new vertex is opposite the facet entered.
        let mut others = r.v.iter().copied().filter(|&x| x != u.0 && x != v.0);
        let (mut away, mut kept) = (others.next()?, others.next()?);
        let mut c = start;
        // The cells around an edge form one cycle; the bound only guards a corrupt structure.
        for _ in 0..self.cells.len() {
            let r = self.cells[c as usize];
            if r.v.contains(&w.0) {
                return Some(CellId(c));
            }
            let i = r.v.iter().position(|&x| x == away)?;
            let packed = r.n[i];
            c = packed >> 2;
            if c == start {
                return None;
            }
            away = kept;
            kept = self.cells[c as usize].v[(packed & 3) as usize];
        }
        None
    }

    fn live(&self, c: u32) -> bool {
        (c as usize) < self.cells.len() && self.cells[c as usize].v[0] != FREE
    }

    #[inline]
    fn pt(&self, v: u32) -> Point3 {
        self.points[v as usize]
    }

    #[inline]
    fn is_infinite_record(r: &CellRecord) -> bool {
        r.v.contains(&INFINITE)
    }

    /// Whether vertex `v` is hidden: its weighted point lies inside the union of its neighbours'
    /// power cells, so it belongs to no cell. Always false in a Delaunay triangulation.
    pub fn is_hidden(&self, v: VertexId) -> bool {
        K::WEIGHTED && self.kernel.is_hidden(v.0)
    }

    /// The hidden vertices, in increasing order.
    pub fn hidden_vertices(&self) -> impl Iterator<Item = VertexId> + '_ {
        self.vertices().filter(|&v| self.is_hidden(v))
    }

    /// The dimension of the affine hull of the vertices (-1 when empty); cells exist only at 3.
    pub fn dimension(&self) -> i32 {
        match &self.lower {
            None => 3,
            Some(l) => l.basis.len() as i32 - 1,
        }
    }

    /// Inserts the validated point `p` of weight `w` (0 for Delaunay).
    fn insert_validated(
        &mut self,
        p: Point3,
        w: f64,
        hint: Option<CellId>,
        report: Option<&mut InsertReport>,
    ) -> Result<InsertOutcome, TriangulationError> {
        if self.points.len() >= MAX_VERTICES {
            return Err(TriangulationError::TooManyElements);
        }
        if let Some(lower) = &self.lower {
            if let Some(&u) = lower.seen.get(&coordinate_key(p)) {
                let wu = self.kernel.weight(u);
                if w == wu {
                    return Ok(InsertOutcome::Duplicate(VertexId(u)));
                }
                // Same position, different weights: the heavier one takes the place.
                let v = self.push_vertex(p, w);
                if w < wu {
                    self.kernel.hide(v);
                    return Ok(InsertOutcome::Hidden(VertexId(v)));
                }
                self.replace_lower_dimensional(u, v);
                if let Some(rep) = report {
                    rep.hidden.push(VertexId(u));
                }
                return Ok(InsertOutcome::Inserted(VertexId(v)));
            }
            let v = self.push_vertex(p, w);
            self.insert_new_vertex(v, hint, report);
            return Ok(InsertOutcome::Inserted(VertexId(v)));
        }
        let start = self.locate_cell(p, hint.map(|c| c.0));
        let rec = &self.cells[start as usize];
        if !Self::is_infinite_record(rec)
            && let Some(&u) = rec.v.iter().find(|&&u| self.pt(u) == p)
        {
            // A heavier point at the same position hides `u` through the ordinary cavity (every
            // cell around `u` conflicts with it); a lighter one is hidden below.
            if w == self.kernel.weight(u) {
                return Ok(InsertOutcome::Duplicate(VertexId(u)));
            }
        }
        let v = self.push_vertex(p, w);
        if self.insert_at(v, start, report) {
            Ok(InsertOutcome::Inserted(VertexId(v)))
        } else {
            Ok(InsertOutcome::Hidden(VertexId(v)))
        }
    }

    /// Stars new vertex `v` from located cell `start`, or hides it if it conflicts with nothing
    /// (only possible with weights). Returns whether `v` is in the triangulation.
    fn insert_at(&mut self, v: u32, start: u32, report: Option<&mut InsertReport>) -> bool {
        if K::WEIGHTED && !self.in_conflict(start, self.pt(v), self.kernel.weight(v)) {
            self.kernel.hide(v);
            return false;
        }
        self.star_from(v, start, report);
        true
    }

    fn push_vertex(&mut self, p: Point3, w: f64) -> u32 {
        self.filter.include(p);
        self.kernel.push_vertex(w);
        self.points.push(p);
        self.vertex_cell.push(NO_CELL);
        (self.points.len() - 1) as u32
    }

    /// Inserts vertex `v`, already in `points` and known to differ from every other vertex.
    fn insert_new_vertex(
        &mut self,
        v: u32,
        hint: Option<CellId>,
        report: Option<&mut InsertReport>,
    ) {
        if self.lower.is_some() {
            self.add_lower_dimensional(v, report);
        } else {
            let start = self.locate_cell(self.pt(v), hint.map(|c| c.0));
            self.insert_at(v, start, report);
        }
    }

    /// Records a vertex while there are no cells; builds them once it completes a basis.
    fn add_lower_dimensional(&mut self, v: u32, report: Option<&mut InsertReport>) {
        let points = &self.points;
        let p = points[v as usize];
        let lower = self.lower.as_mut().expect("lower-dimensional phase");
        lower.seen.insert(coordinate_key(p), v);
        let b = &lower.basis;
        let independent = match b.len() {
            0 | 1 => true,
            2 => !collinear(points[b[0] as usize], points[b[1] as usize], p),
            _ => {
                let [a, b1, c] = [b[0], b[1], b[2]].map(|i| points[i as usize]);
                orient3d(a, b1, c, p) != Sign::Zero
            }
        };
        if !independent {
            lower.pending.push(v);
            return;
        }
        lower.basis.push(v);
        if lower.basis.len() == 4 {
            // Vertices hidden earlier were reported by the insertions that hid them.
            let hidden_before: Vec<VertexId> = self.hidden_vertices().collect();
            self.build_first_cells();
            if let Some(report) = report {
                report.created.extend(self.cells());
                report.hidden.extend(
                    self.hidden_vertices()
                        .filter(|h| hidden_before.binary_search(h).is_err()),
                );
            }
        }
    }

    /// Puts vertex `v` in place of `u` (same position, lighter) while there are no cells.
    fn replace_lower_dimensional(&mut self, u: u32, v: u32) {
        self.kernel.hide(u);
        let lower = self.lower.as_mut().expect("lower-dimensional phase");
        lower
            .seen
            .insert(coordinate_key(self.points[v as usize]), v);
        for x in lower.basis.iter_mut().chain(lower.pending.iter_mut()) {
            if *x == u {
                *x = v;
            }
        }
    }

    /// Builds the first tetrahedron and its four infinite cells from the basis, then inserts the
    /// vertices that arrived while the input was lower-dimensional.
    fn build_first_cells(&mut self) {
        let lower = self.lower.take().expect("lower-dimensional phase");
        let mut t = [
            lower.basis[0],
            lower.basis[1],
            lower.basis[2],
            lower.basis[3],
        ];
        if orient3d(self.pt(t[0]), self.pt(t[1]), self.pt(t[2]), self.pt(t[3])) == Sign::Negative {
            t.swap(0, 1);
        }
        let mut ids = [0u32; 5];
        ids[0] = self.alloc_cell(t);
        for i in 0..4 {
            // Replacing vertex i by the infinite vertex puts it on the wrong side of facet i:
            // swapping two other vertices restores the orientation convention of infinite cells.
            let mut v = t;
            v[i] = INFINITE;
            let (j, k) = match i {
                0 => (1, 2),
                1 => (0, 2),
                _ => (0, 1),
            };
            v.swap(j, k);
            ids[i + 1] = self.alloc_cell(v);
        }
        self.link_by_shared_facets(&ids);
        for &c in &ids {
            self.touch_vertices(c);
        }
        self.num_finite = 1;
        self.last = ids[0];
        let pending = lower.pending;
        let pending_points: Vec<Point3> = pending.iter().map(|&v| self.pt(v)).collect();
        for i in brio_order(&pending_points, BRIO_SEED) {
            let v = pending[i as usize];
            let start = self.locate_cell(self.pt(v), None);
            self.insert_at(v, start, None);
        }
    }

    /// Sets the neighbour links between the given cells by matching their facets (small sets only).
    fn link_by_shared_facets(&mut self, ids: &[u32]) {
        let facet = |r: &CellRecord, i: usize| relocate::sorted_facet(r.v, i);
        for (a_pos, &a) in ids.iter().enumerate() {
            for &b in &ids[a_pos + 1..] {
                for i in 0..4 {
                    for j in 0..4 {
                        if facet(&self.cells[a as usize], i) == facet(&self.cells[b as usize], j) {
                            self.cells[a as usize].n[i] = pack(b, j);
                            self.cells[b as usize].n[j] = pack(a, i);
                        }
                    }
                }
            }
        }
    }

    fn alloc_cell(&mut self, v: [u32; 4]) -> u32 {
        self.num_live += 1;
        let rec = CellRecord { v, n: [NO_CELL; 4] };
        if self.free_head != NO_CELL {
            let c = self.free_head;
            self.free_head = self.cells[c as usize].n[0];
            self.cells[c as usize] = rec;
            c
        } else {
            if self.cells.len() == self.cells.capacity() {
                // Grow by an eighth rather than doubling: the cell array dominates peak memory.
                self.cells.reserve_exact(self.cells.len() / 8 + 64);
            }
            self.cells.push(rec);
            (self.cells.len() - 1) as u32
        }
    }

    fn free_cell(&mut self, c: u32) {
        self.num_live -= 1;
        self.release_slot(c);
    }

    /// Puts slot `c`, which holds no live cell, on the free list.
    fn release_slot(&mut self, c: u32) {
        let rec = &mut self.cells[c as usize];
        rec.v = [FREE; 4];
        rec.n = [self.free_head, NO_CELL, NO_CELL, NO_CELL];
        self.free_head = c;
    }

    fn touch_vertices(&mut self, c: u32) {
        for v in self.cells[c as usize].v {
            if v != INFINITE {
                self.vertex_cell[v as usize] = c;
            }
        }
    }

    /// Visibility walk: a finite cell whose closure contains `p`, or an infinite cell whose hull
    /// facet has `p` strictly beyond it. Terminates on Delaunay triangulations; on regular ones
    /// a deterministic visibility walk could cycle, and the per-point pseudo-random facet order
    /// (a stochastic walk) is what makes it terminate. Requires cells to exist.
    fn locate_cell(&self, p: Point3, hint: Option<u32>) -> u32 {
        self.locate_cell_under(&self.query_filter(p), p, hint)
    }

    /// [`Self::locate_cell`] under `filter`, whose box must hold `p`.
    fn locate_cell_under(&self, filter: &StaticFilter, p: Point3, hint: Option<u32>) -> u32 {
        let mut c = match hint {
            Some(h) if self.live(h) => h,
            _ if self.live(self.last) => self.last,
            _ => self.cells().next().map(|c| c.0).unwrap_or(0),
        };
        {
            let r = &self.cells[c as usize];
            if let Some(i) = r.v.iter().position(|&v| v == INFINITE) {
                c = r.n[i] >> 2;
            }
        }
        match self.walk(
            filter,
            p,
            c,
            |c| self.cells[c as usize],
            |c| Self::is_infinite_record(&self.cells[c as usize]),
        ) {
            Walk::Found(c) => c,
            Walk::Stopped { at, .. } => at,
        }
    }

    /// Visibility walk from finite cell `c` towards `p`, reading the cells it crosses through
    /// `cell`: ends in a cell whose closure contains `p`, or at the first cell entered for which
    /// `stop` holds (which must hold for infinite cells; `cell` is not called for it).
    #[inline]
    fn walk(
        &self,
        filter: &StaticFilter,
        p: Point3,
        mut c: u32,
        cell: impl Fn(u32) -> CellRecord,
        stop: impl Fn(u32) -> bool,
    ) -> Walk {
        let mut prev = NO_CELL;
        // Deterministic per-point pseudo-random facet order.
        let mut rnd = XorShift::new(
            (p.x.to_bits() ^ p.y.to_bits().rotate_left(21) ^ p.z.to_bits().rotate_left(42)) | 1,
        );
        'walk: loop {
            let r = cell(c);
            let pts = &self.points;
            let (a, b, cc, d) = (
                pts[r.v[0] as usize],
                pts[r.v[1] as usize],
                pts[r.v[2] as usize],
                pts[r.v[3] as usize],
            );
            let first = (rnd.next_u64() >> 62) as usize;
            for k in 0..4 {
                let i = (first + k) & 3;
                let next = r.n[i] >> 2;
                if next == prev {
                    continue;
                }
                // The cell with vertex i replaced by p: negative when p is beyond facet i. The
                // points are placed by index rather than dispatched on i, which varies
                // unpredictably.
                let mut t = [a, b, cc, d];
                t[i] = p;
                let side = filter.orient3d(t[0], t[1], t[2], t[3]);
                if side == Sign::Negative {
                    if stop(next) {
                        return Walk::Stopped {
                            before: c,
                            at: next,
                        };
                    }
                    prev = c;
                    c = next;
                    continue 'walk;
                }
            }
            return Walk::Found(c);
        }
    }

    /// Whether `(p, w)` conflicts with cell `c` (negative power distance to its perturbed
    /// orthogonal sphere; with zero weights, strictly inside its perturbed circumsphere).
    #[inline]
    pub(crate) fn in_conflict(&self, c: u32, p: Point3, w: f64) -> bool {
        self.conflicts(&self.filter, self.cells[c as usize].v, p, w)
    }

    /// [`Self::in_conflict`] for the cell with vertices `v` (reads no cell), under `filter`
    /// (whose box must hold `p` and the cell's points).
    #[inline]
    fn conflicts(&self, filter: &StaticFilter, v: [u32; 4], p: Point3, w: f64) -> bool {
        // The infinite vertex is the largest index: one comparison tells infinite cells apart.
        if v[0].max(v[1]).max(v[2].max(v[3])) == INFINITE {
            return self.in_conflict_infinite(filter, v, p, w);
        }
        self.kernel
            .in_conflict_finite(filter, &self.points, v, WeightedPoint3::new(p, w))
    }

    /// [`Self::in_conflict`] for an infinite cell with vertices `v`.
    #[inline(never)]
    fn in_conflict_infinite(&self, filter: &StaticFilter, v: [u32; 4], p: Point3, w: f64) -> bool {
        let i = v.iter().position(|&w| w == INFINITE).unwrap_or(0);
        let mut t = [p; 4];
        let mut tri = [0u32; 3];
        let mut k = 0;
        for (j, &x) in v.iter().enumerate() {
            if j != i {
                t[j] = self.pt(x);
                tri[k] = x;
                k += 1;
            }
        }
        let o = filter.orient3d(t[0], t[1], t[2], t[3]);
        self.kernel
            .beyond_hull_facet(&self.points, tri, o, WeightedPoint3::new(p, w))
    }

    /// Grows the conflict zone of the weighted point `q` (weight 0 for Delaunay), decided under
    /// `filter`, from `start` (which must conflict with `q`).
    fn find_cavity<M: CavityMarks>(
        &self,
        (filter, q): (&StaticFilter, WeightedPoint3),
        start: u32,
        marks: &mut M,
        stack: &mut Vec<u32>,
        cavity: &mut Vec<u32>,
        boundary: &mut Vec<(u32, u8)>,
    ) {
        grow_cavity(
            start,
            marks,
            stack,
            cavity,
            boundary,
            |c| self.cells[c as usize].n,
            |n| Some(self.conflicts(filter, self.cells[n as usize].v, q.point, q.weight)),
        );
    }

    /// Inserts vertex `v` (already in `points`) by starring its cavity, grown from `start`.
    fn star_from(&mut self, v: u32, start: u32, report: Option<&mut InsertReport>) {
        self.star_from_seeing(v, start, report, |_, _| {});
    }

    /// [`Self::star_from`], showing `destroyed` each cavity cell (slot and vertices) before its
    /// slot is reused: a vertex move records the cells it destroys.
    fn star_from_seeing(
        &mut self,
        v: u32,
        start: u32,
        mut report: Option<&mut InsertReport>,
        mut destroyed: impl FnMut(u32, [u32; 4]),
    ) {
        let p = self.pt(v);
        let w = self.kernel.weight(v);
        let mut s = std::mem::take(&mut self.scratch);
        {
            let mut marks = ByteMarks::new(&mut s.mark, self.cells.len());
            self.find_cavity(
                (&self.filter, WeightedPoint3::new(p, w)),
                start,
                &mut marks,
                &mut s.stack,
                &mut s.cavity,
                &mut s.boundary,
            );
        }
        for &c in &s.cavity {
            destroyed(c, self.cells[c as usize].v);
        }
        s.collect_new_cells(v, |c| self.cells[c as usize]);
        let removed_infinite = s
            .cavity
            .iter()
            .filter(|&&c| Self::is_infinite_record(&self.cells[c as usize]))
            .count();
        self.num_finite -= s.cavity.len() - removed_infinite;
        if let Some(rep) = report.as_deref_mut() {
            rep.removed.extend(s.cavity.iter().map(|&c| CellId(c)));
        }
        if K::WEIGHTED {
            self.hide_swallowed(&mut s, report.as_deref_mut());
        }
        let reused = s.cavity.len().min(s.new_cells.len());
        for k in 0..s.new_cells.len() {
            s.new_cells[k].id = if k < reused {
                s.cavity[k]
            } else {
                self.alloc_cell(s.new_cells[k].verts)
            };
        }
        let mut writer = SequentialWriter {
            cells: &mut self.cells,
            finite: 0,
        };
        s.link_new_cells(self.points.len(), &mut writer);
        self.num_finite += writer.finite;
        if !self.bulk {
            for nc in &s.new_cells {
                for w in nc.verts {
                    if w != INFINITE {
                        self.vertex_cell[w as usize] = nc.id;
                    }
                }
            }
        }
        if let Some(rep) = report {
            rep.created
                .extend(s.new_cells.iter().map(|nc| CellId(nc.id)));
        }
        if let Some(nc) = s.new_cells.last() {
            self.last = nc.id;
        }
        for k in reused..s.cavity.len() {
            let c = s.cavity[k];
            self.free_cell(c);
        }
        for &c in &s.cavity {
            s.mark[c as usize] = 0;
        }
        for nc in &s.new_cells {
            s.mark[(nc.outside >> 2) as usize] = 0;
        }
        self.scratch = s;
    }

    /// Hides the vertices of cavity cells that lie on no cavity-boundary facet: the new vertex's
    /// power cell swallows theirs. Called before the cavity is re-triangulated.
    fn hide_swallowed(&mut self, s: &mut Scratch, report: Option<&mut InsertReport>) {
        // Stamp the boundary vertices, then collect the unstamped cavity vertices once each.
        if s.vertex_stamp.len() < self.points.len() {
            s.vertex_stamp.resize(self.points.len(), 0);
        }
        if s.stamp == u32::MAX {
            s.vertex_stamp.fill(0);
            s.stamp = 0;
        }
        s.stamp += 1;
        let stamp = s.stamp;
        for nc in &s.new_cells {
            for &x in nc.verts.iter().filter(|&&x| x != INFINITE) {
                s.vertex_stamp[x as usize] = stamp;
            }
        }
        s.swallowed.clear();
        for &c in &s.cavity {
            for &x in self.cells[c as usize].v.iter().filter(|&&x| x != INFINITE) {
                if s.vertex_stamp[x as usize] != stamp {
                    s.vertex_stamp[x as usize] = stamp;
                    s.swallowed.push(x);
                }
            }
        }
        for &x in &s.swallowed {
            self.kernel.hide(x);
            self.vertex_cell[x as usize] = NO_CELL;
        }
        if let Some(rep) = report {
            rep.hidden.extend(s.swallowed.iter().map(|&x| VertexId(x)));
        }
    }
}

impl<K: ConflictKernel> Triangulation for Triangulation3<K> {
    type Point = Point3;
    type Cell = [VertexId; 4];

    /// Inserts `p` (with weight 0 in a regular triangulation).
    fn insert(&mut self, p: Point3) -> Result<InsertOutcome, TriangulationError> {
        validate_point(p, self.points.len())?;
        self.insert_validated(p, 0.0, None, None)
    }

    fn insert_reporting(
        &mut self,
        p: Point3,
        hint: Option<CellId>,
        report: &mut InsertReport,
    ) -> Result<InsertOutcome, TriangulationError> {
        report.clear();
        validate_point(p, self.points.len())?;
        self.insert_validated(p, 0.0, hint, Some(report))
    }

    fn locate(&self, p: Point3, hint: Option<CellId>) -> Option<CellId> {
        if self.lower.is_some() || !p.is_finite() {
            return None;
        }
        let filter = self.query_filter(p);
        Some(CellId(self.locate_cell_under(
            &filter,
            p,
            hint.map(|c| c.0),
        )))
    }

    fn conflict_zone(&self, p: Point3, hint: Option<CellId>, out: &mut ConflictZone) {
        out.clear();
        let Some(start) = self.locate(p, hint) else {
            return;
        };
        let r = &self.cells[start.0 as usize];
        if !Self::is_infinite_record(r) && r.v.iter().any(|&v| self.pt(v) == p) {
            return;
        }
        // A weight-0 point is hidden when its own cell does not conflict with it.
        if K::WEIGHTED && !self.query_conflict(start, p, 0.0) {
            return;
        }
        let mut marks = HashMarks::default();
        let (mut stack, mut cavity, mut boundary) = (Vec::new(), Vec::new(), Vec::new());
        self.find_cavity(
            (&self.query_filter(p), WeightedPoint3::new(p, 0.0)),
            start.0,
            &mut marks,
            &mut stack,
            &mut cavity,
            &mut boundary,
        );
        out.cells.extend(cavity.into_iter().map(CellId));
        out.boundary_facets
            .extend(boundary.into_iter().map(|(c, i)| (CellId(c), i as usize)));
    }

    fn num_vertices(&self) -> usize {
        self.points.len()
    }

    fn num_finite_cells(&self) -> usize {
        self.num_finite
    }

    fn num_cells(&self) -> usize {
        self.num_live
    }

    fn point(&self, v: VertexId) -> Point3 {
        self.points[v.0 as usize]
    }

    fn vertices(&self) -> impl Iterator<Item = VertexId> + '_ {
        (0..self.points.len() as u32).map(VertexId)
    }

    fn infinite_vertex(&self) -> VertexId {
        VertexId(INFINITE)
    }

    fn cell(&self, c: CellId) -> [VertexId; 4] {
        self.cells[c.0 as usize].v.map(VertexId)
    }

    fn neighbor(&self, c: CellId, i: usize) -> CellId {
        CellId(self.cells[c.0 as usize].n[i] >> 2)
    }

    fn mirror_index(&self, c: CellId, i: usize) -> usize {
        (self.cells[c.0 as usize].n[i] & 3) as usize
    }

    fn is_infinite_cell(&self, c: CellId) -> bool {
        Self::is_infinite_record(&self.cells[c.0 as usize])
    }

    fn is_live(&self, c: CellId) -> bool {
        self.live(c.0)
    }

    fn cell_capacity(&self) -> usize {
        self.cells.len()
    }

    fn cells(&self) -> impl Iterator<Item = CellId> + '_ {
        self.cells
            .iter()
            .enumerate()
            .filter(|(_, r)| r.v[0] != FREE)
            .map(|(c, _)| CellId(c as u32))
    }

    /// The circumcentre, or for [`Regular3`] the orthocentre (equal power distance to the four
    /// weighted vertices).
    fn circumcenter(&self, c: CellId) -> Point3 {
        self.kernel.center(&self.points, self.cells[c.0 as usize].v)
    }

    fn weight(&self, v: VertexId) -> f64 {
        self.kernel.weight(v.0)
    }

    fn incident_cells(&self, v: VertexId, out: &mut Vec<CellId>) {
        out.clear();
        let start = if v.0 == INFINITE {
            self.cells()
                .find(|&c| self.is_infinite_cell(c))
                .map(|c| c.0)
        } else {
            self.vertex_cell
                .get(v.0 as usize)
                .copied()
                .filter(|&c| c != NO_CELL)
        };
        let Some(start) = start else {
            return;
        };
        // Scanning the first few cells found beats allocating a hash set for them.
        const SCAN: usize = 8;
        let mut seen: Option<rustc_hash::FxHashSet<u32>> = None;
        out.push(CellId(start));
        let mut k = 0;
        while k < out.len() {
            let r = &self.cells[out[k].0 as usize];
            k += 1;
            for (i, &nb) in r.n.iter().enumerate() {
                // Only facets containing v (i.e. not opposite it) lead to cells around v.
                if r.v[i] == v.0 {
                    continue;
                }
                let c = nb >> 2;
                let new = match &mut seen {
                    Some(set) => set.insert(c),
                    None => !out.iter().any(|x| x.0 == c),
                };
                if !new {
                    continue;
                }
                out.push(CellId(c));
                if seen.is_none() && out.len() > SCAN {
                    seen = Some(out.iter().map(|x| x.0).collect());
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::triangulation::validity::{ValidityError, check_delaunay3, check_regular3};

    fn lattice_with_jitter() -> Delaunay3 {
        let mut pts = Vec::new();
        for i in 0..125u32 {
            let (x, y, z) = (i % 5, i / 5 % 5, i / 25);
            let jitter = f64::from((i * 7919) % 13) * 1e-3;
            pts.push(Point3::new(
                f64::from(x) + jitter,
                f64::from(y),
                f64::from(z) - jitter,
            ));
        }
        Delaunay3::from_points(&pts).unwrap()
    }

    /// A point set with thin clusters: a vertex among them has a star of hundreds of cells.
    fn fan_of_close_segments() -> Delaunay3 {
        let mut pts = vec![Point3::ZERO];
        for k in 0..6u32 {
            let angle = f64::from(k) * 0.02;
            for j in 1..60u32 {
                let r = f64::from(j) / 60.0;
                pts.push(Point3::new(
                    r * angle.cos(),
                    r * angle.sin(),
                    0.01 * f64::from(k),
                ));
            }
        }
        for i in 0..40u32 {
            let t = f64::from(i);
            pts.push(Point3::new(
                (t * 0.37).sin(),
                (t * 0.73).cos(),
                (t * 0.11).sin(),
            ));
        }
        Delaunay3::from_points(&pts).unwrap()
    }

    #[test]
    fn edge_and_face_walks_agree_with_the_stars() {
        // A jittered lattice, an exact one (cospherical and coplanar everywhere), and a fan.
        let exact: Vec<Point3> = (0..64u32)
            .map(|i| Point3::new(f64::from(i % 4), f64::from(i / 4 % 4), f64::from(i / 16)))
            .collect();
        for dt in [
            lattice_with_jitter(),
            Delaunay3::from_points(&exact).unwrap(),
            fan_of_close_segments(),
        ] {
            let mut star = Vec::new();
            let mut faces = 0;
            for u in dt.vertices() {
                dt.incident_cells(u, &mut star);
                let around: std::collections::BTreeSet<VertexId> =
                    star.iter().flat_map(|&c| dt.cell(c)).collect();
                for v in dt.vertices() {
                    let found = dt.edge_cell(u, v);
                    assert_eq!(
                        found.is_some(),
                        u != v && around.contains(&v),
                        "{u:?} {v:?}"
                    );
                    if let Some(c) = found {
                        assert!(dt.cell(c).contains(&u) && dt.cell(c).contains(&v));
                    }
                }
                // Every face through u is found; a triangle of u's neighbours is a face only
                // when some cell holds it.
                for &c in &star {
                    let cell = dt.cell(c);
                    let others: Vec<VertexId> = cell.into_iter().filter(|&x| x != u).collect();
                    for (a, b) in [(0, 1), (1, 2), (0, 2)] {
                        let face = [u, others[a], others[b]];
                        let found = dt.face_cell(face).map(|c| dt.cell(c));
                        assert!(found.is_some_and(|f| face.iter().all(|x| f.contains(x))));
                        faces += 1;
                    }
                }
                let near: Vec<VertexId> = around.iter().copied().filter(|&x| x != u).collect();
                for w in near.windows(2) {
                    let face = [u, w[0], w[1]];
                    let held = star
                        .iter()
                        .any(|&c| face.iter().all(|x| dt.cell(c).contains(x)));
                    assert_eq!(dt.face_cell(face).is_some(), held);
                }
            }
            assert!(faces > 0);
        }
    }

    #[test]
    fn the_checker_accepts_a_valid_triangulation() {
        assert_eq!(check_delaunay3(&lattice_with_jitter()), Ok(()));
    }

    #[test]
    fn the_checker_detects_a_negatively_oriented_cell() {
        let mut dt = lattice_with_jitter();
        let c = dt.cells().find(|&c| !dt.is_infinite_cell(c)).unwrap();
        dt.cells[c.0 as usize].v.swap(0, 1);
        assert!(check_delaunay3(&dt).is_err());
    }

    #[test]
    fn the_checker_detects_broken_adjacency() {
        let mut dt = lattice_with_jitter();
        let c = dt.cells().next().unwrap();
        let other = dt.cells().nth(10).unwrap();
        dt.cells[c.0 as usize].n[2] = pack(other.0, 1);
        assert!(matches!(
            check_delaunay3(&dt),
            Err(ValidityError::Asymmetric { .. })
        ));
    }

    #[test]
    fn the_checker_detects_a_non_delaunay_facet() {
        // Four points in convex position where the Delaunay choice is forced, then the shared
        // facet flipped by hand (a 2-3 flip is not available, so build a bad pair directly).
        let mut dt = Delaunay3::from_points(&[
            Point3::new(0.0, 0.0, 0.0),
            Point3::new(1.0, 0.0, 0.0),
            Point3::new(0.0, 1.0, 0.0),
            Point3::new(0.0, 0.0, 1.0),
            Point3::new(0.9, 0.9, 0.9),
        ])
        .unwrap();
        assert_eq!(check_delaunay3(&dt), Ok(()));
        // Move a vertex deep inside a neighbouring circumsphere without changing combinatorics.
        dt.points[4] = Point3::new(0.3, 0.3, 0.3);
        assert!(check_delaunay3(&dt).is_err());
    }

    /// A regular triangulation of a jittered lattice with weights, some of them hidden.
    fn weighted_lattice() -> Regular3 {
        let pts: Vec<(Point3, f64)> = (0..125u32)
            .map(|i| {
                let (x, y, z) = (i % 5, i / 5 % 5, i / 25);
                let jitter = f64::from((i * 7919) % 13) * 1e-3;
                let p = Point3::new(f64::from(x) + jitter, f64::from(y), f64::from(z) - jitter);
                (p, f64::from((i * 104_729) % 17) * 0.3)
            })
            .collect();
        Regular3::from_weighted_points(&pts).unwrap().0
    }

    #[test]
    fn the_regular_checker_accepts_a_valid_triangulation() {
        let rt = weighted_lattice();
        assert!(rt.hidden_vertices().count() > 0);
        assert_eq!(check_regular3(&rt), Ok(()));
    }

    #[test]
    fn the_regular_checker_detects_a_wrong_weight() {
        let mut rt = weighted_lattice();
        let v = rt.vertices().find(|&v| !rt.is_hidden(v)).unwrap();
        rt.kernel.state_mut().0[v.0 as usize] += 10.0;
        assert!(matches!(
            check_regular3(&rt),
            Err(ValidityError::NotDelaunay { .. })
        ));
    }

    #[test]
    fn the_regular_checker_detects_a_vertex_that_should_not_be_hidden() {
        let mut rt = weighted_lattice();
        let h = rt.hidden_vertices().next().unwrap();
        rt.kernel.state_mut().0[h.0 as usize] += 10.0;
        assert!(matches!(
            check_regular3(&rt),
            Err(ValidityError::NotHidden { vertex, .. }) if vertex == h
        ));
    }

    #[test]
    fn the_regular_checker_detects_wrong_hidden_flags() {
        let mut rt = weighted_lattice();
        let h = rt.hidden_vertices().next().unwrap();
        rt.kernel.state_mut().1[h.0 as usize] = false;
        assert_eq!(check_regular3(&rt), Err(ValidityError::IsolatedVertex(h)));
        let mut rt = weighted_lattice();
        let v = rt.vertices().find(|&v| !rt.is_hidden(v)).unwrap();
        rt.kernel.state_mut().1[v.0 as usize] = true;
        assert_eq!(check_regular3(&rt), Err(ValidityError::HiddenInCell(v)));
    }

    #[test]
    fn the_checker_detects_a_stale_vertex_cell() {
        let mut dt = lattice_with_jitter();
        let c = dt
            .cells()
            .find(|&c| !dt.cell(c).contains(&VertexId(0)))
            .unwrap();
        dt.vertex_cell[0] = c.0;
        assert!(matches!(
            check_delaunay3(&dt),
            Err(ValidityError::VertexCell { .. })
        ));
    }
}
