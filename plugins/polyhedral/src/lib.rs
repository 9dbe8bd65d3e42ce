//! Oracle over closed triangle surfaces: AABB tree, segment hits, inside test.
//!
//! The domain is the set of points with a non-zero winding number with respect to the input
//! surface. Several closed components give several subdomains: a point belongs to the subdomain
//! of the innermost component around it, so two nested spheres give a core and a shell, and an
//! inner sphere oriented inwards makes a hollow (its inside has winding number zero).
//!
//! A surface that does not bound a volume as given (open, non-manifold, self-intersecting or
//! overlapping, see [`Repairs`]) is closed as a chain and read by its total winding number
//! instead: the domain is the one subdomain where it is at least one, bounded only by the
//! triangles that separate winding number one from zero.

mod occupancy;
mod oracle;
mod plugin_export;
mod predicates;
mod repair;
mod tree;
mod validate;

pub use occupancy::Occupancy;
pub use oracle::{
    ArrangementError, PolyhedralError, PolyhedralOptions, PolyhedralOracle, WindingBoundary,
    diagnose, refuse_defects,
};
pub use repair::Repairs;
pub use tree::{TriangleTree, closest_point_on_triangle};
pub use validate::{SurfaceDefects, surface_defects};
