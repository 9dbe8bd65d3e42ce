//! Delaunay refinement: the `MesherLevel` trait, the engine that stacks levels, criteria, and the
//! levels of the 3D mesher (surface facets, cells).
//!
//! The design follows Rineau's thesis, chapter 5: every rule of a Delaunay-refinement algorithm is
//! a *level* owning a queue of elements to refine. Levels are ordered by priority; a point proposed
//! by a level is checked by every level of higher priority and by itself, and is inserted only if
//! all accept it. The engine is generic over [`Triangulation`](crate::triangulation::Triangulation)
//! so that 2D meshers (Ruppert: segments, triangles) reuse it unchanged.

pub(crate) mod cells;
pub mod criteria;
pub mod curves;
mod engine;
pub mod facets;
mod feature_grid;
mod geometry;
pub(crate) mod guard;
pub mod manifold;
mod mesh3;
pub(crate) mod protect;
mod queue;
pub mod repair;
pub mod sizing;

pub(crate) use engine::Deadline;
pub use engine::{
    Cancel, Candidate, Check, Engine, Limits, MesherLevel, Progress, RefineError, RefineStats,
};
pub(crate) use geometry::{
    CHECKER_FLAT_VOLUME, FLAT_CANDIDATES, cell_vertices, facet_vertices,
    flat_cell_refinement_point, is_flat, is_flat_within, is_same_cell, shortest_edge,
    triangle_circumcenter, triangle_min_angle_deg,
};
pub use manifold::Relabelling;
pub use mesh3::{
    InsertBall, MeshError, MeshOptions, MeshOutcome, PhaseTimes, mesh_domain, mesh_with_features,
};
pub use repair::{Validity, ValidityOptions};
