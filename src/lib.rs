//! delamesh: quality tetrahedral meshes by Delaunay refinement.
//!
//! This crate re-exports the public API of the workspace crates.

pub use delamesh_core as core;
pub use delamesh_formats as formats;
pub use delamesh_polyhedral as polyhedral;
