//! delamesh-core: robust geometric kernel, Delaunay triangulations and the Delaunay-refinement
//! engine. No file formats and no command line live here (see `delamesh-formats` and the root
//! crate `delamesh`).

pub mod complex;
pub mod kernel;
pub mod mesh;
pub mod mesh2d;
pub mod optimize;
pub mod oracle;
pub mod plugin;
pub mod quality;
pub mod refine;
pub mod triangulation;
