//! Boundary-conforming tetrahedralisation of a closed triangle surface (seed 001 in 3D): the input
//! vertices are inserted into a Delaunay triangulation, then Steiner points on the missing input
//! edges and triangles until every input triangle is exactly a union of triangulation faces; the
//! cells are then split into regions by those faces and each region takes the subdomain the
//! domain's oracle gives it.
//!
//! Conforming, not constrained: every cell stays Delaunay, so a constraint is recovered only by
//! making its pieces small enough that their diametral balls hold no other vertex (Cohen-Steiner,
//! de Verdière and Yvinec; Shewchuk's Delaunay refinement of PLCs without the cell level). Missing
//! sub-segments are split first — at the midpoint, or on a power-of-two shell around an input
//! vertex (Ruppert's concentric shells, so that segments meeting at small angles stop splitting
//! each other) — then missing sub-facets get the centre of their in-plane Delaunay circle, or split
//! the sub-segment of their triangle that centre encroaches. Every test is an exact predicate on
//! the points as stored; Steiner points are computed on their constraint as well as floating point
//! allows, and the constraint keeps them by combinatorics (the chain of an edge, the point list of
//! a triangle), never by re-measuring their position.

mod constraints;
mod facet;
mod quality;
mod regions;

#[cfg(test)]
mod tests;

use crate::complex::MeshComplex;
use crate::kernel::Point3;
use crate::oracle::{Oracle, PatchId};
use crate::refine::criteria::CellCriteria;
use crate::refine::{Cancel, Deadline, RefineError};
use crate::triangulation::{
    CellId, Delaunay3, InsertOutcome, InsertReport, Triangulation, TriangulationError, VertexId,
};
use constraints::Constraints;
use facet::{FacetStep, Plane, facet_step};
use std::cmp::Reverse;
use std::collections::BinaryHeap;

/// Options of [`preserve_surface`].
#[derive(Clone, Debug)]
pub struct PreserveOptions {
    /// Most vertices (input and Steiner) the triangulation may reach before recovery gives up.
    pub max_vertices: usize,
    /// Shortest sub-segment a split may create, relative to the diagonal of the input's bounding
    /// box: below it the input is taken to have a feature floating point cannot resolve.
    pub min_relative_length: f64,
    /// Quality refinement of the cells inside (radius-edge ratio and circumradius), with points
    /// inside the volume and, where their cavities would cross the surface, on it; `None`: the
    /// recovered tetrahedralisation with only its flat cells refined.
    pub cells: Option<CellCriteria>,
    /// Cells whose circumradius is below this, relative to the diagonal of the input's bounding
    /// box, are not refined: a floor under the cell level, whatever the criteria ask.
    pub min_relative_radius: f64,
    /// Wall-clock bound of the whole run: recovery past it fails with
    /// [`RefineError::TimeLimit`]; the cell level stops at its next round and the mesh reached
    /// is returned with [`Preserved::stopped`] set.
    pub time_limit: Option<std::time::Duration>,
    /// Raised from elsewhere, stops the run as the time limit does, with
    /// [`RefineError::Cancelled`].
    pub cancel: Option<Cancel>,
}

impl Default for PreserveOptions {
    fn default() -> Self {
        PreserveOptions {
            max_vertices: 5_000_000,
            min_relative_length: 1e-9,
            cells: None,
            min_relative_radius: 1e-3,
            time_limit: None,
            cancel: None,
        }
    }
}

/// Why the surface could not be kept.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum PreserveError {
    /// The surface has no triangles.
    #[error("the surface has no triangles")]
    Empty,
    /// A triangle names a vertex that does not exist.
    #[error("triangle {triangle} names vertex {index}, but there are {count} vertices")]
    IndexOutOfRange {
        /// The triangle.
        triangle: usize,
        /// The index it names.
        index: u32,
        /// How many vertices there are.
        count: usize,
    },
    /// The patch list does not have one entry per triangle.
    #[error("{0} patch ids for {1} triangles")]
    PatchCount(usize, usize),
    /// A triangle's corners are collinear (or two coincide): it has no plane to recover.
    #[error("triangle {0} is degenerate (collinear or coincident corners)")]
    DegenerateTriangle(usize),
    /// Two input vertices have the same position (the surface must be welded).
    #[error("input vertices {0} and {1} are at the same position")]
    DuplicateVertex(u32, u32),
    /// The triangulation refused a point.
    #[error("triangulation: {0}")]
    Triangulation(#[from] TriangulationError),
    /// The vertex cap was reached before every constraint appeared.
    #[error(
        "boundary recovery did not finish within {cap} vertices (max-vertices; {edges} input edges and {facets} input triangles still missing)"
    )]
    VertexCap {
        /// The cap.
        cap: usize,
        /// Input edges not yet a chain of triangulation edges.
        edges: usize,
        /// Input triangles not yet a union of triangulation faces.
        facets: usize,
    },
    /// A split would create a sub-segment shorter than the resolvable length.
    #[error(
        "recovering the input edge between vertices {} and {} would need a piece shorter than {length:e} (input features too close for floating point)", edge[0], edge[1]
    )]
    TooShort {
        /// The input edge, as its two input vertices.
        edge: [u32; 2],
        /// The shortest length allowed.
        length: f64,
    },
    /// A Steiner point for an input triangle fell on an existing vertex of another constraint
    /// (surfaces closer than floating point resolves).
    #[error("a Steiner point for input triangle {0} coincides with an existing vertex")]
    Coincident(usize),
    /// Input triangle has missing pieces but no point to insert for them was found.
    #[error(
        "recovery of input triangle {0} is stuck: no Steiner point found for its missing pieces"
    )]
    Stuck(usize),
    /// The time limit passed, or the run was cancelled, before the surface was recovered.
    #[error(transparent)]
    Stopped(RefineError),
}

/// A surface kept exactly in a tetrahedral mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Preserved {
    /// The mesh: every boundary facet lies in one input triangle, whose patch it carries.
    pub complex: MeshComplex,
    /// Steiner points inserted on input edges.
    pub edge_steiner: usize,
    /// Steiner points inserted inside input triangles.
    pub facet_steiner: usize,
    /// Passes over all constraints (the last one finds every constraint present).
    pub rounds: usize,
    /// Points inserted inside the volume by quality refinement (cell circumcentres).
    pub cell_steiner: usize,
    /// Why the cell level stopped before every cell met its criteria (time limit, cancel); the
    /// surface is kept all the same.
    pub stopped: Option<RefineError>,
}

impl Preserved {
    /// Every Steiner point.
    pub fn steiner_points(&self) -> usize {
        self.edge_steiner + self.facet_steiner
    }
}

/// Tetrahedralises the inside of the closed, non-self-intersecting surface `triangles` over
/// `points`, keeping every input triangle as a union of boundary facets (with `patches[t]` as
/// their patch) and every input vertex as a mesh vertex. `oracle` names the subdomain of each
/// region bounded by the surface (asked once per region, at the centroid of its largest cell).
///
/// The surface's closedness and the absence of self-intersections are the caller's to check
/// (the polyhedral plugin's validation does); this function refuses what it cannot recover.
pub fn preserve_surface(
    points: &[Point3],
    triangles: &[[u32; 3]],
    patches: &[PatchId],
    oracle: &dyn Oracle,
    options: &PreserveOptions,
) -> Result<Preserved, PreserveError> {
    let clock = Deadline::new(options.time_limit, options.cancel.clone());
    let constraints = Constraints::new(points, triangles, patches)?;
    let mut recovery = Recovery::new(points, constraints, options, clock)?;
    let mut faces = Vec::new();
    recovery.run(&mut faces)?;
    let min_radius = options.min_relative_radius * recovery.diagonal;
    let (cell_steiner, stopped) = quality::refine(
        &mut recovery,
        &mut faces,
        oracle,
        options.cells.as_ref(),
        min_radius,
    )?;
    let complex = regions::complex(
        &recovery.dt,
        &faces,
        &recovery.constraints,
        oracle,
        &recovery.inside,
    );
    Ok(Preserved {
        complex,
        edge_steiner: recovery.edge_steiner,
        facet_steiner: recovery.facet_steiner,
        rounds: recovery.rounds,
        cell_steiner,
        stopped,
    })
}

/// The triangulation being made to conform, and the constraints' bookkeeping.
struct Recovery {
    dt: Delaunay3,
    constraints: Constraints,
    max_vertices: usize,
    min_length: f64,
    /// Diagonal of the input's bounding box.
    diagonal: f64,
    /// Vertices placed inside the volume (not on the surface), in increasing order.
    inside: Vec<VertexId>,
    /// The time limit and cancel flag of the run.
    clock: Deadline,
    report: InsertReport,
    /// When set, every cell an insertion creates is added (the cell level's log of the cells
    /// whose subdomains and shapes it must look at again).
    created: Option<Vec<CellId>>,
    incident: Vec<CellId>,
    edge_steiner: usize,
    facet_steiner: usize,
    rounds: usize,
    /// Per vertex, the constraints (input edges, then input triangles numbered after the edges)
    /// whose presence depends on it: an edge on its chain, a triangle on its corners, its
    /// interior and its edges' chains.
    members: Vec<Vec<u32>>,
    /// Per input edge, the input triangles it bounds.
    edge_facets: Vec<Vec<u32>>,
    /// The constraints not found present since an insertion changed a cell around one of their
    /// vertices (a face is destroyed only with a cell around each of its vertices, all of which
    /// the new cells then touch): the only ones a pass visits.
    stale: Vec<bool>,
    /// Stale constraints the current pass has still to visit (at or after `cursor`), smallest
    /// first.
    ahead: BinaryHeap<Reverse<u32>>,
    /// Stale constraints for the next pass.
    behind: Vec<u32>,
    /// Where the current pass is (0 between passes).
    cursor: u32,
    /// Insertions so far: the clock of `touched`, `checked` and the kept planes.
    epoch: u64,
    /// Per vertex, the last insertion that changed a cell around it.
    touched: Vec<u64>,
    /// Per input edge, when a pass last began to check its chain (all of whose sub-segments were
    /// edges by its end): a sub-segment whose ends no insertion has touched since is still one.
    checked: Vec<Option<u64>>,
    /// Per input triangle, its kept in-plane triangulation, once it has many vertices.
    planes: Vec<Option<Box<Plane>>>,
}

impl Recovery {
    fn new(
        points: &[Point3],
        mut constraints: Constraints,
        options: &PreserveOptions,
        clock: Deadline,
    ) -> Result<Self, PreserveError> {
        let used = constraints.used_points(points);
        let mut dt = Delaunay3::new();
        let vertices = dt.insert_points(&used)?;
        if let Some((a, b)) = constraints.first_duplicate(&vertices) {
            return Err(PreserveError::DuplicateVertex(a, b));
        }
        constraints.attach(&vertices);
        let edges = constraints.edges.len() as u32;
        let mut members: Vec<Vec<u32>> = vec![Vec::new(); dt.num_vertices()];
        let mut edge_facets = vec![Vec::new(); constraints.edges.len()];
        for (e, edge) in constraints.edges.iter().enumerate() {
            for &(_, v) in &edge.chain {
                members[v.0 as usize].push(e as u32);
            }
        }
        for (f, facet) in constraints.facets.iter().enumerate() {
            let k = edges + f as u32;
            for v in facet.corners {
                members[v.0 as usize].push(k);
            }
            for e in facet.edges {
                edge_facets[e as usize].push(k);
            }
        }
        let count = edges + constraints.facets.len() as u32;
        let constraints_facets = constraints.facets.len();
        let diagonal = crate::mesh::Aabb::of(&used).map_or(0.0, |b| (b.max - b.min).length());
        Ok(Recovery {
            dt,
            constraints,
            max_vertices: options.max_vertices,
            min_length: options.min_relative_length * diagonal,
            diagonal,
            inside: Vec::new(),
            clock,
            report: InsertReport::default(),
            created: None,
            incident: Vec::new(),
            edge_steiner: 0,
            facet_steiner: 0,
            rounds: 0,
            members,
            edge_facets,
            stale: vec![true; count as usize],
            ahead: (0..count).map(Reverse).collect(),
            behind: Vec::new(),
            cursor: 0,
            epoch: 0,
            touched: vec![0; vertices.len()],
            checked: vec![None; edges as usize],
            planes: (0..constraints_facets).map(|_| None).collect(),
        })
    }

    /// Passes over the stale constraints, in order, until one inserts nothing; `faces` (one list
    /// per input triangle, kept from the last call: a triangle not stale since is not searched
    /// again) then holds the faces making up each input triangle.
    fn run(&mut self, faces: &mut Vec<Vec<[VertexId; 3]>>) -> Result<(), PreserveError> {
        faces.resize(self.constraints.facets.len(), Vec::new());
        let edges = self.constraints.edges.len() as u32;
        loop {
            self.rounds += 1;
            let mut changed = false;
            // Constraints made stale behind the pass wait for the next one.
            while let Some(Reverse(k)) = self.ahead.pop() {
                self.cursor = k + 1;
                if k < edges {
                    let e = k as usize;
                    let since = self.checked[e].replace(self.epoch);
                    let mut i = 0;
                    while i + 1 < self.constraints.edges[e].chain.len() {
                        let (u, v) = {
                            let chain = &self.constraints.edges[e].chain;
                            (chain[i].1, chain[i + 1].1)
                        };
                        let kept = since.is_some_and(|t| {
                            self.touched[u.0 as usize] <= t && self.touched[v.0 as usize] <= t
                        });
                        if kept || self.has_edge(u, v) {
                            i += 1;
                        } else {
                            self.split(e, [u, v])?;
                            changed = true;
                        }
                    }
                    self.stale[e] = false;
                    continue;
                }
                let f = (k - edges) as usize;
                // One step per facet and pass: the edges' pass in between is far cheaper than
                // another in-plane triangulation of a facet whose edges are still being split.
                match facet_step(self, f)? {
                    FacetStep::Recovered(found) => {
                        faces[f] = found;
                        self.stale[k as usize] = false;
                    }
                    FacetStep::Refined => {
                        changed = true;
                        self.behind.push(k);
                    }
                }
            }
            self.cursor = 0;
            self.ahead.extend(self.behind.drain(..).map(Reverse));
            if !changed {
                return Ok(());
            }
        }
    }

    /// Marks constraint `k` stale, for this pass if it is still ahead, else for the next.
    fn mark(&mut self, k: u32) {
        if !std::mem::replace(&mut self.stale[k as usize], true) {
            if k >= self.cursor {
                self.ahead.push(Reverse(k));
            } else {
                self.behind.push(k);
            }
        }
    }

    /// Records that vertex `v` (just inserted) is on constraint `k`, which is then stale.
    fn join(&mut self, v: VertexId, k: u32) {
        if let Some(list) = self.members.get_mut(v.0 as usize) {
            list.push(k);
        }
        self.mark(k);
    }

    /// Records that vertex `v` (just inserted) splits input edge `e`: the edge and the triangles
    /// it bounds depend on it.
    fn join_edge(&mut self, v: VertexId, e: usize) {
        self.join(v, e as u32);
        for i in 0..self.edge_facets[e].len() {
            let k = self.edge_facets[e][i];
            self.join(v, k);
        }
    }

    /// Records that vertex `v` (just inserted) lies inside input triangle `f`.
    fn join_facet(&mut self, v: VertexId, f: usize) {
        self.join(v, (self.constraints.edges.len() + f) as u32);
    }

    /// Whether `u` and `v` are joined by an edge of the triangulation.
    fn has_edge(&self, u: VertexId, v: VertexId) -> bool {
        self.dt.edge_cell(u, v).is_some()
    }

    /// Whether `face` is a face of the triangulation.
    fn has_face(&self, face: [VertexId; 3]) -> bool {
        self.dt.face_cell(face).is_some()
    }

    /// Inserts a Steiner point near vertex `near`; `None` when it falls on an existing vertex.
    /// Fails past the vertex cap, the time limit, or once cancelled: every step of recovery and
    /// of the cell level inserts, so this bounds them all.
    fn insert(&mut self, p: Point3, near: VertexId) -> Result<Option<VertexId>, PreserveError> {
        if self.dt.num_vertices() >= self.max_vertices {
            return Err(self.cap_error());
        }
        if let Some(stop) = self.clock.stop() {
            return Err(PreserveError::Stopped(stop));
        }
        let hint = self.dt.vertex_cell(near);
        match self.dt.insert_reporting(p, hint, &mut self.report)? {
            InsertOutcome::Inserted(v) => {
                if self.members.len() <= v.0 as usize {
                    self.members.resize(v.0 as usize + 1, Vec::new());
                }
                self.epoch += 1;
                if let Some(log) = &mut self.created {
                    log.extend_from_slice(&self.report.created);
                }
                if self.touched.len() <= v.0 as usize {
                    self.touched.resize(v.0 as usize + 1, self.epoch);
                }
                for i in 0..self.report.created.len() {
                    for u in self.dt.cell(self.report.created[i]) {
                        if let Some(t) = self.touched.get_mut(u.0 as usize) {
                            *t = self.epoch;
                        }
                        for j in 0..self.members.get(u.0 as usize).map_or(0, Vec::len) {
                            let k = self.members[u.0 as usize][j];
                            self.mark(k);
                        }
                    }
                }
                Ok(Some(v))
            }
            InsertOutcome::Duplicate(_) | InsertOutcome::Hidden(_) => Ok(None),
        }
    }

    /// Splits the sub-segment of input edge `e` between the chain vertices `pair` (nothing when
    /// they are no longer consecutive).
    fn split(&mut self, e: usize, pair: [VertexId; 2]) -> Result<(), PreserveError> {
        let edge = &self.constraints.edges[e];
        let Some(i) = edge.chain.windows(2).position(|w| {
            (w[0].1 == pair[0] && w[1].1 == pair[1]) || (w[0].1 == pair[1] && w[1].1 == pair[0])
        }) else {
            return Ok(());
        };
        let (from, to) = (edge.chain[i].1, edge.chain[i + 1].1);
        // A piece at one end of its edge splits on a shell around that end, wherever encroached.
        let encroacher = if (i == 0) == (i + 2 == edge.chain.len()) {
            self.encroacher(from, to)
        } else {
            None
        };
        let edge = &self.constraints.edges[e];
        let (t, p) =
            edge.split_point(i, encroacher, self.min_length)
                .ok_or(PreserveError::TooShort {
                    edge: edge.ends,
                    length: self.min_length,
                })?;
        let ends = edge.ends;
        match self.insert(p, from)? {
            Some(v) => {
                self.constraints.edges[e].chain.insert(i + 1, (t, v));
                self.join_edge(v, e);
                self.edge_steiner += 1;
                Ok(())
            }
            None => Err(PreserveError::TooShort {
                edge: ends,
                length: self.min_length,
            }),
        }
    }

    /// The vertex around `u` or `v` that sees them under the widest angle above 90°: the one
    /// that most encroaches the segment `uv`, if any does.
    fn encroacher(&mut self, u: VertexId, v: VertexId) -> Option<Point3> {
        let (pu, pv) = (self.dt.point(u), self.dt.point(v));
        let mut best: Option<(f64, Point3)> = None;
        for w in [u, v] {
            self.dt.incident_cells(w, &mut self.incident);
            for &c in &self.incident {
                for x in self.dt.cell(c) {
                    if x == u || x == v || self.dt.is_infinite_vertex(x) {
                        continue;
                    }
                    let px = self.dt.point(x);
                    let (a, b) = (pu - px, pv - px);
                    let cosine = a.dot(b) / (a.length() * b.length());
                    if cosine < 0.0 && best.is_none_or(|(c, _)| cosine < c) {
                        best = Some((cosine, px));
                    }
                }
            }
        }
        best.map(|(_, p)| p)
    }

    /// The error of the vertex cap, counting what is still missing.
    fn cap_error(&mut self) -> PreserveError {
        let mut edges = 0;
        for e in 0..self.constraints.edges.len() {
            let chain = self.constraints.edges[e].chain.clone();
            if chain.windows(2).any(|w| !self.has_edge(w[0].1, w[1].1)) {
                edges += 1;
            }
        }
        let facets = (0..self.constraints.facets.len())
            .filter(|&f| !facet::is_recovered(self, f))
            .count();
        PreserveError::VertexCap {
            cap: self.max_vertices,
            edges,
            facets,
        }
    }
}
