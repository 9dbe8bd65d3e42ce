//! `Delaunay2`: the Delaunay triangulation of a planar point set, the 2D twin of `Delaunay3`.
//!
//! Incremental Bowyer–Watson insertion with an infinite vertex (every hull edge has an infinite
//! triangle behind it, so insertion outside the hull is no special case), a remembering visibility
//! walk, flat typed storage with a free list, and the lifting-map symbolic perturbation of
//! [`predicates::incircle_perturbed`] so that cocircular input has one order-independent answer.
//! Until three non-collinear points exist the vertices wait on a sorted line (no triangle exists).

mod sort;
mod validity;

#[cfg(test)]
mod tests;

pub use super::{
    CellId, ConflictZone, InsertOutcome, InsertReport, Triangulation, TriangulationError, VertexId,
};
pub use crate::kernel::predicates2d as predicates;
pub use validity::ValidityError;

use crate::random::XorShift;
use glam::DVec2;
use predicates::{incircle_perturbed, lex_cmp, orient2d};
use std::cell::{Cell, RefCell};
use std::cmp::Ordering;
use std::collections::{BTreeMap, HashMap};

const NO_CELL: CellId = CellId(u32::MAX);
const FREE: VertexId = VertexId(u32::MAX - 1);
/// The infinite vertex: every hull edge `(a, b)` has the triangle `(b, a, INFINITE)` behind it.
pub const INFINITE: VertexId = VertexId(u32::MAX);

/// Largest coordinate magnitude accepted: beyond it the exact predicates could overflow.
pub const MAX_COORDINATE: f64 = 1e50;

/// Rejects points the exact predicates cannot handle.
fn validate_point(p: DVec2, index: usize) -> Result<(), TriangulationError> {
    if !p.is_finite() {
        return Err(TriangulationError::NonFinite {
            index,
            x: p.x,
            y: p.y,
            z: 0.0,
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

/// Key ordering points lexicographically, for the collinear phase.
#[derive(Copy, Clone, Debug)]
struct LexKey(DVec2);

impl PartialEq for LexKey {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for LexKey {}
impl PartialOrd for LexKey {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for LexKey {
    fn cmp(&self, o: &Self) -> Ordering {
        lex_cmp(self.0, o.0)
    }
}

/// Delaunay triangulation of points in the plane (see the module documentation).
#[derive(Debug)]
pub struct Delaunay2 {
    /// Coordinates of the finite vertices, numbered from 0 in insertion order.
    points: Vec<DVec2>,
    /// One live cell incident to each finite vertex (`NO_CELL` while no triangle exists).
    vertex_cell: Vec<CellId>,
    /// One live cell incident to the infinite vertex.
    infinite_cell: CellId,
    /// Cell vertices, counter-clockwise; a free slot has `FREE` as first vertex.
    cells: Vec<[VertexId; 3]>,
    /// `neighbors[c][i]` is the cell across the edge opposite vertex `i` of `c`.
    neighbors: Vec<[CellId; 3]>,
    free: Vec<CellId>,
    num_finite_cells: usize,
    /// Vertices on one line, sorted, while the triangulation has dimension < 2.
    chain: BTreeMap<LexKey, VertexId>,
    /// Last cell found by a walk: the next walk starts there.
    hint: Cell<CellId>,
    walk_rng: Cell<XorShift>,
    /// Visit stamps of the conflict search, one per cell.
    marks: RefCell<(Vec<u32>, u32)>,
    /// The last zone computed by `conflict_zone` and its point: a mesher usually asks for the zone
    /// of a point (to check it) and then inserts that very point, which reuses the zone. Cleared by
    /// every change of the triangulation (the point is reset; the buffers are kept for reuse).
    last_zone: RefCell<(Option<DVec2>, ConflictZone)>,
    /// Reused buffers of `insert_impl` and `star` (no allocation per insertion).
    scratch: Scratch,
}

#[derive(Debug, Default)]
struct Scratch {
    zone: ConflictZone,
    boundary: Vec<(VertexId, VertexId, CellId, usize)>,
    created: Vec<CellId>,
}

impl Default for Delaunay2 {
    fn default() -> Self {
        Self::new()
    }
}

impl Delaunay2 {
    /// An empty triangulation.
    pub fn new() -> Self {
        Self {
            points: Vec::new(),
            vertex_cell: Vec::new(),
            infinite_cell: NO_CELL,
            cells: Vec::new(),
            neighbors: Vec::new(),
            free: Vec::new(),
            num_finite_cells: 0,
            chain: BTreeMap::new(),
            hint: Cell::new(NO_CELL),
            walk_rng: Cell::new(XorShift::new(0x2545_F491_4F6C_DD1D)),
            marks: RefCell::new((Vec::new(), 0)),
            last_zone: RefCell::new((None, ConflictZone::default())),
            scratch: Scratch::default(),
        }
    }

    /// Triangulates `points`, inserted in spatially sorted BRIO order; the outcomes are returned in
    /// input order (duplicates name the vertex they coincide with).
    pub fn from_points(points: &[DVec2]) -> Result<(Self, Vec<InsertOutcome>), TriangulationError> {
        let mut t = Self::new();
        let outcomes = t.insert_points(points)?;
        Ok((t, outcomes))
    }

    /// Inserts many points in spatially sorted BRIO order; outcomes in input order.
    pub fn insert_points(
        &mut self,
        points: &[DVec2],
    ) -> Result<Vec<InsertOutcome>, TriangulationError> {
        for (index, &p) in points.iter().enumerate() {
            validate_point(p, index)?;
        }
        let mut outcomes = vec![InsertOutcome::Duplicate(INFINITE); points.len()];
        for i in sort::brio_order(points) {
            outcomes[i] = self.insert(points[i])?;
        }
        Ok(outcomes)
    }

    /// Every finite edge once, as `(cell, index of the opposite vertex)` with the cell finite.
    pub fn finite_edges(&self) -> impl Iterator<Item = (CellId, usize)> + '_ {
        self.finite_cells().flat_map(move |c| {
            (0..3).filter_map(move |i| {
                let n = self.neighbor(c, i);
                (self.is_infinite_cell(n) || c < n).then_some((c, i))
            })
        })
    }

    /// The cell with the edge `a → b` counter-clockwise and the index of its third vertex: a turn
    /// around `a` that stops at the edge, without collecting `a`'s star.
    pub fn edge_cell(&self, a: VertexId, b: VertexId) -> Option<(CellId, usize)> {
        let start = self.vertex_cell_of(a);
        if start == NO_CELL {
            return None;
        }
        let mut c = start;
        for _ in 0..self.cells.len() {
            let i = self.index_of(c, a);
            let v = self.cells[c.0 as usize];
            if v[(i + 1) % 3] == b {
                return Some((c, (i + 2) % 3));
            }
            c = self.neighbors[c.0 as usize][(i + 1) % 3];
            if c == start {
                break;
            }
        }
        None
    }

    /// Whether `p` is strictly inside the (perturbed) circumdisk of `c`, or beyond the hull edge of
    /// the infinite cell `c`.
    pub fn in_conflict(&self, c: CellId, p: DVec2) -> bool {
        let v = self.cells[c.0 as usize];
        match v.iter().position(|&x| x == INFINITE) {
            None => {
                incircle_perturbed(self.point(v[0]), self.point(v[1]), self.point(v[2]), p)
                    == Ordering::Greater
            }
            Some(i) => {
                let a = self.point(v[(i + 1) % 3]);
                let b = self.point(v[(i + 2) % 3]);
                match orient2d(a, b, p) {
                    Ordering::Greater => true,
                    Ordering::Less => false,
                    // On the hull line: in conflict exactly when strictly inside the hull edge.
                    Ordering::Equal => lex_cmp(a, p) == lex_cmp(p, b) && lex_cmp(a, p).is_ne(),
                }
            }
        }
    }

    fn vertex_cell_of(&self, v: VertexId) -> CellId {
        if v == INFINITE {
            self.infinite_cell
        } else {
            self.vertex_cell[v.0 as usize]
        }
    }

    fn set_vertex_cell(&mut self, v: VertexId, c: CellId) {
        if v == INFINITE {
            self.infinite_cell = c;
        } else {
            self.vertex_cell[v.0 as usize] = c;
        }
    }

    fn index_of(&self, c: CellId, v: VertexId) -> usize {
        self.cells[c.0 as usize]
            .iter()
            .position(|&x| x == v)
            .unwrap_or(0)
    }

    fn duplicate_in(&self, c: CellId, p: DVec2) -> Option<VertexId> {
        self.cells[c.0 as usize]
            .iter()
            .copied()
            .find(|&v| v != INFINITE && self.point(v) == p)
    }

    fn next_random(&self) -> u64 {
        let mut rng = self.walk_rng.get();
        let x = rng.next_u64();
        self.walk_rng.set(rng);
        x
    }

    /// Visibility walk with a random choice among the edges to test first (which guarantees
    /// termination in any triangulation) from `start` towards `p`.
    fn walk(&self, p: DVec2, start: CellId) -> CellId {
        let mut c = start;
        if let Some(i) = self.cells[c.0 as usize].iter().position(|&x| x == INFINITE) {
            c = self.neighbor(c, i);
        }
        let mut prev = NO_CELL;
        'walk: loop {
            if self.is_infinite_cell(c) {
                return c;
            }
            let v = self.cells[c.0 as usize];
            let r = (self.next_random() % 3) as usize;
            for k in 0..3 {
                let i = (r + k) % 3;
                let n = self.neighbors[c.0 as usize][i];
                if n == prev {
                    continue;
                }
                let a = self.point(v[(i + 1) % 3]);
                let b = self.point(v[(i + 2) % 3]);
                if orient2d(a, b, p) == Ordering::Less {
                    prev = c;
                    c = n;
                    continue 'walk;
                }
            }
            return c;
        }
    }

    /// Breadth-first search of the conflict zone from a cell known to be in conflict.
    fn find_conflicts(&self, p: DVec2, start: CellId, zone: &mut ConflictZone) {
        let mut marks = self.marks.borrow_mut();
        let (stamps, stamp) = &mut *marks;
        if stamps.len() < self.cells.len() {
            stamps.resize(self.cells.len(), 0);
        }
        *stamp = stamp.wrapping_add(1);
        if *stamp == 0 {
            stamps.fill(0);
            *stamp = 1;
        }
        let stamp = *stamp;
        stamps[start.0 as usize] = stamp;
        zone.cells.push(start);
        let mut k = 0;
        while k < zone.cells.len() {
            let c = zone.cells[k];
            k += 1;
            for i in 0..3 {
                let n = self.neighbors[c.0 as usize][i];
                if stamps[n.0 as usize] == stamp {
                    continue;
                }
                if self.in_conflict(n, p) {
                    stamps[n.0 as usize] = stamp;
                    zone.cells.push(n);
                } else {
                    zone.boundary_facets.push((c, i));
                }
            }
        }
    }

    fn insert_impl(
        &mut self,
        p: DVec2,
        hint: Option<CellId>,
        report: Option<&mut InsertReport>,
    ) -> Result<InsertOutcome, TriangulationError> {
        validate_point(p, self.points.len())?;
        let mut zone = std::mem::take(&mut self.scratch.zone);
        zone.clear();
        let (cached_point, cached) = self.last_zone.get_mut();
        match cached_point.take() {
            // The zone of this very point, computed on the current triangulation (every change
            // clears the cache): no need to locate it again. A cached zone is never that of a
            // vertex, so the point is no duplicate. Swapping buffers spares a copy.
            Some(q) if q == p && !cached.cells.is_empty() => std::mem::swap(&mut zone, cached),
            _ => {
                let Some(start) = self.locate(p, hint) else {
                    self.scratch.zone = zone;
                    return self.insert_on_line(p, report);
                };
                if let Some(v) = self.duplicate_in(start, p) {
                    self.scratch.zone = zone;
                    return Ok(InsertOutcome::Duplicate(v));
                }
                self.find_conflicts(p, start, &mut zone);
            }
        }
        let result = self
            .push_vertex(p)
            .and_then(|v| self.star(v, &zone, report).map(|()| v));
        self.scratch.zone = zone;
        Ok(InsertOutcome::Inserted(result?))
    }

    fn push_vertex(&mut self, p: DVec2) -> Result<VertexId, TriangulationError> {
        let id =
            u32::try_from(self.points.len()).map_err(|_| TriangulationError::TooManyElements)?;
        if id >= FREE.0 {
            return Err(TriangulationError::TooManyElements);
        }
        self.points.push(p);
        self.vertex_cell.push(NO_CELL);
        Ok(VertexId(id))
    }

    fn alloc_cell(&mut self, v: [VertexId; 3]) -> Result<CellId, TriangulationError> {
        if !v.contains(&INFINITE) {
            self.num_finite_cells += 1;
        }
        if let Some(c) = self.free.pop() {
            self.cells[c.0 as usize] = v;
            return Ok(c);
        }
        let id =
            u32::try_from(self.cells.len()).map_err(|_| TriangulationError::TooManyElements)?;
        if id == NO_CELL.0 {
            return Err(TriangulationError::TooManyElements);
        }
        self.cells.push(v);
        self.neighbors.push([NO_CELL; 3]);
        Ok(CellId(id))
    }

    /// Replaces the conflict zone by the star of the new vertex `v` over its boundary.
    fn star(
        &mut self,
        v: VertexId,
        zone: &ConflictZone,
        report: Option<&mut InsertReport>,
    ) -> Result<(), TriangulationError> {
        // Read the boundary before freeing the zone's cells.
        let mut boundary = std::mem::take(&mut self.scratch.boundary);
        boundary.clear();
        boundary.extend(zone.boundary_facets.iter().map(|&(c, i)| {
            let cv = self.cells[c.0 as usize];
            (
                cv[(i + 1) % 3],
                cv[(i + 2) % 3],
                self.neighbor(c, i),
                self.mirror_index(c, i),
            )
        }));
        for &c in &zone.cells {
            if !self.is_infinite_cell(c) {
                self.num_finite_cells -= 1;
            }
            self.cells[c.0 as usize][0] = FREE;
            self.free.push(c);
        }
        let mut created = std::mem::take(&mut self.scratch.created);
        created.clear();
        for &(x, y, n, j) in &boundary {
            let c = match self.alloc_cell([v, x, y]) {
                Ok(c) => c,
                Err(e) => {
                    self.scratch.boundary = boundary;
                    self.scratch.created = created;
                    return Err(e);
                }
            };
            self.neighbors[c.0 as usize][0] = n;
            self.neighbors[n.0 as usize][j] = c;
            // The cavity boundary is one cycle: each vertex starts exactly one new cell.
            self.set_vertex_cell(x, c);
            created.push(c);
        }
        for &c in &created {
            let y = self.cells[c.0 as usize][2];
            let next = self.vertex_cell_of(y);
            self.neighbors[c.0 as usize][1] = next;
            self.neighbors[next.0 as usize][2] = c;
        }
        if let Some(&c) = created.first() {
            self.set_vertex_cell(v, c);
            self.hint.set(c);
        }
        if let Some(report) = report {
            report.removed.extend_from_slice(&zone.cells);
            report.created.extend_from_slice(&created);
        }
        self.scratch.boundary = boundary;
        self.scratch.created = created;
        Ok(())
    }

    /// Insertion while all vertices are collinear: keep them sorted on their line until a point off
    /// the line arrives, then build the (unique) fan triangulation.
    fn insert_on_line(
        &mut self,
        p: DVec2,
        report: Option<&mut InsertReport>,
    ) -> Result<InsertOutcome, TriangulationError> {
        if let Some(&v) = self.chain.get(&LexKey(p)) {
            return Ok(InsertOutcome::Duplicate(v));
        }
        let mut ends = self.chain.keys();
        let line = match (ends.next(), ends.next_back()) {
            (Some(a), Some(b)) => Some((a.0, b.0)),
            _ => None,
        };
        let v = self.push_vertex(p)?;
        match line {
            Some((a, b)) if orient2d(a, b, p) != Ordering::Equal => {
                self.build_fan(v, report)?;
            }
            _ => {
                self.chain.insert(LexKey(p), v);
            }
        }
        Ok(InsertOutcome::Inserted(v))
    }

    /// Triangulates the sorted collinear chain plus the apex `v` off its line.
    fn build_fan(
        &mut self,
        apex: VertexId,
        report: Option<&mut InsertReport>,
    ) -> Result<(), TriangulationError> {
        let chain: Vec<VertexId> = std::mem::take(&mut self.chain).into_values().collect();
        let (first, last) = (chain[0], chain[chain.len() - 1]);
        let ccw =
            orient2d(self.point(first), self.point(last), self.point(apex)) == Ordering::Greater;
        let mut tris: Vec<[VertexId; 3]> = chain
            .windows(2)
            .map(|w| {
                if ccw {
                    [w[0], w[1], apex]
                } else {
                    [w[1], w[0], apex]
                }
            })
            .collect();
        // Every directed edge without a twin is a hull edge: put an infinite triangle behind it.
        let mut edges: HashMap<(VertexId, VertexId), (usize, usize)> = HashMap::new();
        for (t, v) in tris.iter().enumerate() {
            for i in 0..3 {
                edges.insert((v[(i + 1) % 3], v[(i + 2) % 3]), (t, i));
            }
        }
        let finite = tris.len();
        for t in 0..finite {
            for i in 0..3 {
                let (x, y) = (tris[t][(i + 1) % 3], tris[t][(i + 2) % 3]);
                if !edges.contains_key(&(y, x)) {
                    tris.push([y, x, INFINITE]);
                }
            }
        }
        for (t, v) in tris.iter().enumerate().skip(finite) {
            for i in 0..3 {
                edges.insert((v[(i + 1) % 3], v[(i + 2) % 3]), (t, i));
            }
        }
        let ids: Vec<CellId> = tris
            .iter()
            .map(|&v| self.alloc_cell(v))
            .collect::<Result<_, _>>()?;
        for (t, v) in tris.iter().enumerate() {
            for i in 0..3 {
                let (x, y) = (v[(i + 1) % 3], v[(i + 2) % 3]);
                if let Some(&(n, _)) = edges.get(&(y, x)) {
                    self.neighbors[ids[t].0 as usize][i] = ids[n];
                }
                self.set_vertex_cell(v[i], ids[t]);
            }
        }
        self.hint.set(ids[0]);
        if let Some(report) = report {
            report.created.extend_from_slice(&ids);
        }
        Ok(())
    }
}

impl Triangulation for Delaunay2 {
    type Point = DVec2;
    type Cell = [VertexId; 3];

    /// Inserts one point.
    fn insert(&mut self, p: DVec2) -> Result<InsertOutcome, TriangulationError> {
        self.insert_impl(p, None, None)
    }

    /// Inserts one point, walking from `hint` if given, and fills `report` (cleared first) with
    /// the cells destroyed and created.
    fn insert_reporting(
        &mut self,
        p: DVec2,
        hint: Option<CellId>,
        report: &mut InsertReport,
    ) -> Result<InsertOutcome, TriangulationError> {
        report.clear();
        self.insert_impl(p, hint, Some(report))
    }

    /// Number of finite vertices.
    fn num_vertices(&self) -> usize {
        self.points.len()
    }

    /// Number of finite triangles.
    fn num_finite_cells(&self) -> usize {
        self.num_finite_cells
    }

    /// Coordinates of a finite vertex.
    fn point(&self, v: VertexId) -> DVec2 {
        self.points[v.0 as usize]
    }

    /// The three vertices of a cell, counter-clockwise.
    fn cell(&self, c: CellId) -> [VertexId; 3] {
        self.cells[c.0 as usize]
    }

    /// Number of live cells, finite and infinite.
    fn num_cells(&self) -> usize {
        self.cells.len() - self.free.len()
    }

    /// The infinite vertex.
    fn infinite_vertex(&self) -> VertexId {
        INFINITE
    }

    /// The cell across the edge opposite vertex `i` of `c`.
    fn neighbor(&self, c: CellId, i: usize) -> CellId {
        self.neighbors[c.0 as usize][i]
    }

    /// The index `j` such that `neighbor(neighbor(c, i), j) == c`.
    fn mirror_index(&self, c: CellId, i: usize) -> usize {
        let n = self.neighbor(c, i);
        let ns = &self.neighbors[n.0 as usize];
        (0..3).find(|&j| ns[j] == c).unwrap_or(0)
    }

    fn is_infinite_vertex(&self, v: VertexId) -> bool {
        v == INFINITE
    }

    fn is_infinite_cell(&self, c: CellId) -> bool {
        self.cells[c.0 as usize].contains(&INFINITE)
    }

    /// Whether `c` is a cell of the current triangulation (not freed for reuse).
    fn is_live(&self, c: CellId) -> bool {
        self.cells.get(c.0 as usize).is_some_and(|v| v[0] != FREE)
    }

    /// Size of the cell arrays (live and free); cell ids are below this.
    fn cell_capacity(&self) -> usize {
        self.cells.len()
    }

    /// All live cells, infinite ones included, in id order.
    fn cells(&self) -> impl Iterator<Item = CellId> + '_ {
        (0..self.cells.len() as u32)
            .map(CellId)
            .filter(|&c| self.is_live(c))
    }

    /// Live finite triangles in id order.
    fn finite_cells(&self) -> impl Iterator<Item = CellId> + '_ {
        self.cells().filter(|&c| !self.is_infinite_cell(c))
    }

    /// Finite vertices in id order.
    fn vertices(&self) -> impl Iterator<Item = VertexId> + '_ {
        (0..self.points.len() as u32).map(VertexId)
    }

    /// Circumcentre of a finite triangle.
    fn circumcenter(&self, c: CellId) -> DVec2 {
        let [a, b, d] = self.cells[c.0 as usize];
        predicates::circumcenter(self.point(a), self.point(b), self.point(d))
    }

    /// Live cells around vertex `v` (infinite ones included), empty while no triangle exists.
    fn incident_cells(&self, v: VertexId, out: &mut Vec<CellId>) {
        out.clear();
        let start = self.vertex_cell_of(v);
        if start == NO_CELL {
            return;
        }
        let mut c = start;
        loop {
            out.push(c);
            let i = self.index_of(c, v);
            c = self.neighbor(c, (i + 1) % 3);
            if c == start || out.len() > self.cells.len() {
                return;
            }
        }
    }

    /// A cell containing `p` in its closure, or an infinite cell whose hull edge sees `p` strictly
    /// outside; `None` while no triangle exists.
    fn locate(&self, p: DVec2, hint: Option<CellId>) -> Option<CellId> {
        let mut start = hint.unwrap_or(self.hint.get());
        if !self.is_live(start) {
            start = self.hint.get();
        }
        if !self.is_live(start) {
            start = self.cells().next()?;
        }
        let found = self.walk(p, start);
        self.hint.set(found);
        Some(found)
    }

    /// The cells in conflict with `p` (circumdisk containing `p` under the perturbation) without
    /// inserting it; empty when `p` is a vertex or no triangle exists.
    fn conflict_zone(&self, p: DVec2, hint: Option<CellId>, out: &mut ConflictZone) {
        out.clear();
        if !p.is_finite() {
            return;
        }
        if let Some(c) = self.locate(p, hint) {
            if self.duplicate_in(c, p).is_none() {
                self.find_conflicts(p, c, out);
                let mut last = self.last_zone.borrow_mut();
                let (q, cached) = &mut *last;
                *q = Some(p);
                cached.clear();
                cached.cells.extend_from_slice(&out.cells);
                cached
                    .boundary_facets
                    .extend_from_slice(&out.boundary_facets);
            }
        }
    }
}
