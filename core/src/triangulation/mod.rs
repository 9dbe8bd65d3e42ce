//! Triangulations: the `Triangulation` trait, Delaunay 3D and 2D, validity checking.
pub mod delaunay2;
