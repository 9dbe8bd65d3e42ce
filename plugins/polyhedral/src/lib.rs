//! Oracle over closed triangle surfaces: AABB tree, segment hits, inside test.
//!
//! The domain is the set of points with a non-zero winding number with respect to the input
//! surface. Several closed components give several subdomains: a point belongs to the subdomain
//! of the innermost component around it, so two nested spheres give a core and a shell, and an
//! inner sphere oriented inwards makes a hollow (its inside has winding number zero).

mod occupancy;
mod oracle;
mod plugin_export;
mod predicates;
mod tree;
mod validate;

pub use oracle::{PolyhedralError, PolyhedralOracle};
pub use tree::{TriangleTree, closest_point_on_triangle};
pub use validate::{SurfaceDefects, surface_defects};
