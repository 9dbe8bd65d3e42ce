//! Points and robust geometric predicates.

pub use glam::DVec3 as Point3;
