//! Oracle over a piecewise-smooth surface: a closed triangle surface whose sharp edges, borders,
//! non-manifold edges and patch borders are 1D features (CGAL Mesh_3's `detect_features`), chained
//! into curves between corners, which cut the surface into patches.
//!
//! Surface queries (inside test, segment and ray hits) are those of `delamesh-polyhedral`, with
//! the patches found here as patch ids.
//!
//! Several subdomains: each is a closed, outward-oriented component, nested or side by side. Two
//! subdomains sharing a face must each contain a copy of it: two triangles with the same vertices
//! (welded or only at equal coordinates) in opposite orientations, with the same triangulation on
//! both sides. The two copies make one interface patch; a segment through it gets one hit.
//!
//! User polylines (`--features`) must follow surface edges: their points snap to surface vertices
//! within [`SNAP_TOLERANCE`] × the bounding-box diagonal, and a segment may run along several
//! collinear edges; anything else is an error naming the polyline's line.

mod chain;
mod edges;
mod features;
mod interface;
pub mod models;
mod oracle;
mod plugin_export;
mod polylines;

pub use chain::{Chain, Chains, chain};
pub use features::{
    Corner, Curve, DEFAULT_FEATURE_ANGLE_DEG, FeatureError, FeatureOptions, Features,
    SNAP_TOLERANCE,
};
pub use oracle::{PiecewiseSmoothError, PiecewiseSmoothOracle};
pub use plugin_export::{parse_value, read_config};
pub use polylines::{Polyline, PolylineError, parse_polylines, read_polylines};
