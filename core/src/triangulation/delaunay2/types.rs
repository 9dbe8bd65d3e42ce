//! Typed indices and insertion reports shared by the triangulations.

/// A vertex of a triangulation (index into its flat vertex arrays).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct VertexId(pub u32);

/// A cell (triangle in 2D) of a triangulation (index into its flat cell arrays).
#[derive(Copy, Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct CellId(pub u32);

/// What happened to a point given to `insert`.
#[derive(Copy, Clone, Debug, PartialEq, Eq)]
pub enum InsertOutcome {
    /// The point became this new vertex.
    Inserted(VertexId),
    /// The point equals this existing vertex and was not inserted again.
    Duplicate(VertexId),
}

/// The cells an insertion destroyed and created, so refinement levels can update their queues.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct InsertReport {
    pub created: Vec<CellId>,
    pub removed: Vec<CellId>,
}

/// The cells whose circumdisk contains a point, and the boundary facets of their union
/// (each as the cell inside the zone and the index of the vertex opposite the facet).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ConflictZone {
    pub cells: Vec<CellId>,
    pub boundary_facets: Vec<(CellId, usize)>,
}

/// Why a point was refused.
#[derive(Debug, thiserror::Error, Clone, PartialEq)]
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
}

impl InsertOutcome {
    /// The vertex at the point, new or existing.
    pub fn vertex(self) -> VertexId {
        match self {
            InsertOutcome::Inserted(v) | InsertOutcome::Duplicate(v) => v,
        }
    }
}

impl InsertReport {
    pub fn clear(&mut self) {
        self.created.clear();
        self.removed.clear();
    }
}

impl ConflictZone {
    pub fn clear(&mut self) {
        self.cells.clear();
        self.boundary_facets.clear();
    }
}
