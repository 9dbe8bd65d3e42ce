//! Triangulations: the `Triangulation` trait, Delaunay 3D and 2D, regular (weighted) 3D, validity
//! checking.
//!
//! # Identifiers
//! Vertices and cells are named by the typed indices [`VertexId`] and [`CellId`]. Vertex ids are
//! stable for the life of the triangulation. **Cell ids are recycled**: a cell destroyed by an
//! insertion frees its slot, and a later insertion (usually the same one) reuses it for a new cell.
//! Code that keeps cells across insertions (e.g. refinement queues) should store the pair
//! `(CellId, Cell)` and treat it as stale when `!is_live(c) || cell(c) != stored`.
//!
//! # The infinite vertex
//! Every triangulation has one infinite vertex ([`Triangulation::infinite_vertex`]) joined to every
//! hull facet, so the cells form a closed sphere without boundary special cases. Cells containing it
//! are *infinite*; the others are *finite*. The infinite vertex has no point.
//!
//! # Lower-dimensional input
//! Until the input contains `d + 1` affinely independent points the triangulation has no cells; the
//! points are still vertices (duplicates are still detected), and the first independent point builds
//! all cells at once.

pub mod delaunay2;
pub mod spatial_sort;
pub mod triangulation3;
pub mod validity;

pub use delaunay2::Delaunay2;
pub use triangulation3::{Delaunay3, MoveReport, Regular3, Triangulation3};

/// A vertex of a triangulation. Stable once assigned; finite vertices are numbered densely from 0
/// (one-by-one insertions in insertion order; a bulk build numbers its points along a space-filling
/// curve for memory locality, and returns the vertex of every input point).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct VertexId(pub u32);

/// A cell slot of a triangulation. Slots are recycled (see the module documentation).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct CellId(pub u32);

/// What an insertion did.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum InsertOutcome {
    /// The point became this new vertex.
    Inserted(VertexId),
    /// The point equals the point of this existing vertex (with the same weight); nothing changed.
    Duplicate(VertexId),
    /// The weighted point lies inside the union of its heavier neighbours' power cells: it got
    /// this vertex id (so `point()` still works) but is in no cell. Delaunay triangulations never
    /// return it.
    Hidden(VertexId),
}

impl InsertOutcome {
    /// The vertex at the point, new or existing.
    pub fn vertex(self) -> VertexId {
        match self {
            InsertOutcome::Inserted(v) | InsertOutcome::Duplicate(v) | InsertOutcome::Hidden(v) => {
                v
            }
        }
    }
}

/// Cells created and destroyed by one insertion. Reused across calls: each insertion clears it.
/// Ids in `removed` may reappear in `created` (slots are recycled).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InsertReport {
    /// Cells the insertion created.
    pub created: Vec<CellId>,
    /// Cells the insertion destroyed (its conflict zone).
    pub removed: Vec<CellId>,
    /// Vertices that this insertion hid (they are in no cell any more; regular triangulations).
    pub hidden: Vec<VertexId>,
}

impl InsertReport {
    /// Empties the report for reuse, keeping its allocations.
    pub fn clear(&mut self) {
        self.created.clear();
        self.removed.clear();
        self.hidden.clear();
    }
}

/// The cells a point would destroy if inserted, and the boundary of their union.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ConflictZone {
    /// Cells whose (perturbed) circumsphere strictly contains the point. Infinite cells are in
    /// conflict when the point lies beyond their hull facet (or on its plane, inside its circle).
    pub cells: Vec<CellId>,
    /// Facets of the cavity boundary as `(cell in the zone, index of the facet)`; facet `i` of a
    /// cell is the one opposite its `i`-th vertex.
    pub boundary_facets: Vec<(CellId, usize)>,
}

impl ConflictZone {
    /// Empties the zone for reuse, keeping its allocations.
    pub fn clear(&mut self) {
        self.cells.clear();
        self.boundary_facets.clear();
    }
}

/// Why a point was refused.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum TriangulationError {
    #[error("point {index} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFinite {
        index: usize,
        x: f64,
        y: f64,
        z: f64,
    },
    #[error(
        "point {index} has a coordinate of magnitude above {limit:e}, beyond the range where the exact predicates cannot overflow"
    )]
    TooLarge { index: usize, limit: f64 },
    #[error("too many vertices or cells for 32-bit indices")]
    TooManyElements,
    #[error(
        "point {index} has weight {weight}; weights must be finite, non-negative and at most {limit:e}"
    )]
    InvalidWeight {
        index: usize,
        weight: f64,
        limit: f64,
    },
}

/// A simplicial complex covering the convex hull of its vertices, closed by an infinite vertex.
///
/// Facet `i` of a cell is the facet opposite its `i`-th vertex; `neighbor(c, i)` is the cell across
/// it and `mirror_index(c, i)` the index of that same facet in the neighbour.
pub trait Triangulation {
    /// A point of the ambient space.
    type Point: Copy;
    /// The vertices of a cell (`[VertexId; 4]` in 3D), in positive orientation for finite cells.
    type Cell: Copy + AsRef<[VertexId]> + PartialEq;

    /// Inserts a point (no location hint, report discarded).
    fn insert(&mut self, p: Self::Point) -> Result<InsertOutcome, TriangulationError>;

    /// Inserts a point, starting the location walk at `hint` if given, and fills `report` with the
    /// cells created and destroyed (cleared first).
    fn insert_reporting(
        &mut self,
        p: Self::Point,
        hint: Option<CellId>,
        report: &mut InsertReport,
    ) -> Result<InsertOutcome, TriangulationError>;

    /// A cell whose closure contains `p` (a finite cell), or an infinite cell whose hull facet `p`
    /// lies strictly beyond when `p` is outside the convex hull. `None` while there are no cells.
    fn locate(&self, p: Self::Point, hint: Option<CellId>) -> Option<CellId>;

    /// The cells `p` conflicts with and their boundary, without inserting `p`. Empty when `p` is
    /// already a vertex or when there are no cells yet.
    fn conflict_zone(&self, p: Self::Point, hint: Option<CellId>, out: &mut ConflictZone);

    /// Number of finite vertices (in a regular triangulation, hidden ones included).
    fn num_vertices(&self) -> usize;
    /// Number of live finite cells.
    fn num_finite_cells(&self) -> usize;
    /// Number of live cells, finite and infinite.
    fn num_cells(&self) -> usize;
    /// The point of a finite vertex. Panics on the infinite vertex, which has none.
    fn point(&self, v: VertexId) -> Self::Point;
    /// The finite vertices (in a regular triangulation, hidden ones included).
    fn vertices(&self) -> impl Iterator<Item = VertexId> + '_;
    /// The infinite vertex.
    fn infinite_vertex(&self) -> VertexId;
    /// Whether `v` is the infinite vertex.
    fn is_infinite_vertex(&self, v: VertexId) -> bool {
        v == self.infinite_vertex()
    }

    /// The vertices of a live cell.
    fn cell(&self, c: CellId) -> Self::Cell;
    /// The cell across facet `i` of `c`.
    fn neighbor(&self, c: CellId, i: usize) -> CellId;
    /// The index of facet `(c, i)` in `neighbor(c, i)`.
    fn mirror_index(&self, c: CellId, i: usize) -> usize;
    /// Whether `c` has the infinite vertex.
    fn is_infinite_cell(&self, c: CellId) -> bool {
        let inf = self.infinite_vertex();
        self.cell(c).as_ref().contains(&inf)
    }
    /// Whether slot `c` holds a cell (and is not free for recycling).
    fn is_live(&self, c: CellId) -> bool;
    /// An upper bound on every `CellId`, for side arrays indexed by cell.
    fn cell_capacity(&self) -> usize;
    /// The live cells, finite and infinite, in increasing id order.
    fn cells(&self) -> impl Iterator<Item = CellId> + '_;
    /// The live finite cells, in increasing id order.
    fn finite_cells(&self) -> impl Iterator<Item = CellId> + '_ {
        self.cells().filter(move |&c| !self.is_infinite_cell(c))
    }
    /// Every facet once, as `(cell, index)` seen from the cell with the smaller id.
    fn facets(&self) -> impl Iterator<Item = (CellId, usize)> + '_ {
        self.cells().flat_map(move |c| {
            let n = self.cell(c).as_ref().len();
            (0..n)
                .filter(move |&i| c < self.neighbor(c, i))
                .map(move |i| (c, i))
        })
    }
    /// Every edge once, as a sorted vertex pair, in increasing order (including edges to the
    /// infinite vertex).
    fn edges(&self) -> Vec<(VertexId, VertexId)> {
        let mut edges = Vec::new();
        for c in self.cells() {
            let cell = self.cell(c);
            let v = cell.as_ref();
            for i in 0..v.len() {
                for j in i + 1..v.len() {
                    edges.push((v[i].min(v[j]), v[i].max(v[j])));
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        edges
    }
    /// Centre of the circumsphere of a finite cell (floating point construction); in a regular
    /// triangulation, its orthocentre (equal power distance to the four weighted vertices).
    fn circumcenter(&self, c: CellId) -> Self::Point;
    /// Weight of `v` (the squared radius of its ball); 0 in a Delaunay triangulation.
    fn weight(&self, _v: VertexId) -> f64 {
        0.0
    }
    /// All cells (finite and infinite) incident to `v`, written to `out` (cleared first).
    fn incident_cells(&self, v: VertexId, out: &mut Vec<CellId>);
}
