//! delamesh-core: robust geometric kernel, Delaunay triangulations and the Delaunay-refinement
//! engine. No file formats and no command line live here (see `delamesh-formats` and the root
//! crate `delamesh`).

pub mod complex;
pub mod conform3;
pub mod kernel;
pub mod mesh;
pub mod mesh2d;
pub mod optimize;
pub mod oracle;
pub mod plugin;
pub mod quality;
pub mod random;
pub mod refine;
pub mod triangulation;
pub mod union_find;

pub use complex::MeshComplex;
pub use kernel::Point3;
pub use mesh::{CurveId, PatchId, SubdomainId, SurfaceMesh, TetMesh};
pub use oracle::{Aabb, FeatureCurve, OUTSIDE, Oracle, SurfaceHit, SurfacePoint};
pub use refine::criteria::{MeshCriteria, Sizing};
pub use refine::{
    Cancel, MeshOptions, MeshOutcome, Progress, RefineError, RefineStats, mesh_domain,
};
pub use triangulation::{Delaunay2, Delaunay3, Regular3, Triangulation};
pub use union_find::UnionFind;
