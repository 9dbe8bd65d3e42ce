//! Planar meshing: planar straight-line graphs (PSLG), Pébay's a-priori subdivision of a constraint
//! so that it becomes Delaunay-admissible, and the Ruppert/Shewchuk quality mesher.

pub mod admissible;
pub mod conform;
mod grid;
pub mod mesher;
pub mod pslg;
pub mod quality;

#[cfg(test)]
mod tests;

pub use admissible::{Theta2, classify, is_strongly_admissible};
pub use conform::{Algorithm, ConformError, ConformOptions, Conformed, conform};
pub use glam::DVec2 as Point2;
pub use pslg::{Pslg, PslgError, Region};
