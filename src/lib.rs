//! delamesh: quality tetrahedral meshes by Delaunay refinement.
//!
//! The pipeline of `delamesh mesh` as a library: [`MeshSettings`] (with a validating
//! [`builder`](MeshSettings::builder)), a [`Domain`] chosen as the command line does (a surface
//! with sharp features → piecewise smooth, else smooth polyhedral; or a plugin), and [`Mesher`],
//! which reads, refines, collects the complex and hands back a [`Meshed`] that writes itself and
//! computes its [`Report`].
//!
//! ```no_run
//! use delamesh::{Mesher, MeshSettings};
//!
//! let settings = MeshSettings::builder().facet_size(0.05).build()?;
//! let mut meshed = Mesher::new(settings).mesh_file("part.stl".as_ref())?;
//! if let Some(guard) = &meshed.stopped {
//!     eprintln!("stopped early: {guard}");
//! }
//! meshed.write("part.vtu".as_ref(), &Default::default())?;
//! # Ok::<(), delamesh::Error>(())
//! ```
//!
//! The workspace crates stay reachable one level down: [`core`], [`formats`], [`polyhedral`],
//! [`piecewise_smooth`]. The command line (`src/main.rs`, `src/cli/`) is behind the default `cli`
//! feature; `default-features = false` leaves only the library.

mod domain;
mod error;
mod pipeline;
pub mod plugins;
pub mod report;
mod settings;

pub use delamesh_core as core;
pub use delamesh_formats as formats;
pub use delamesh_piecewise_smooth as piecewise_smooth;
pub use delamesh_polyhedral as polyhedral;

pub use delamesh_formats::WriteOptions;
pub use domain::Domain;
pub use error::Error;
pub use pipeline::{Meshed, Mesher, mesh_file};
pub use report::{Report, Times};
pub use settings::{
    DEFAULT_MAX_VERTICES, FeatureSettings, MeshSettings, MeshSettingsBuilder, SettingsError,
};
