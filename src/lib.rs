//! delamesh: quality tetrahedral meshes by Delaunay refinement.
//!
//! The pipeline of `delamesh mesh` as a library: [`MeshSettings`] (with a validating
//! [`builder`](MeshSettings::builder)), a [`Domain`] chosen as the command line does (a surface
//! with sharp features → piecewise smooth, else smooth polyhedral; a plugin; or an [`Oracle`] of
//! your own), and [`Mesher`], which reads, refines, collects the complex and hands back a
//! [`Meshed`] that writes itself and computes its [`Report`]. A guard that stops refinement early
//! is [`Meshed::stopped`] with [`MeshSettings::keep_partial`], an [`Error`] otherwise.
//!
//! # Mesh a file
//! ```
//! use delamesh::{MeshSettings, Mesher};
//!
//! let settings = MeshSettings::builder().facet_size(0.3).cell_size(0.3).build()?;
//! let mut meshed = Mesher::new(settings).mesh_file("models/sphere.off".as_ref())?;
//! let dir = tempfile::tempdir().expect("a temporary directory");
//! meshed.write(&dir.path().join("sphere.vtu"), &Default::default())?;
//! let report = meshed.report();
//! let b = &report.boundary;
//! assert!(b.closed && b.manifold && Some(b.euler_characteristic) == b.input_euler_characteristic);
//! assert_eq!(report.quality.inverted_tets, 0);
//! # Ok::<(), delamesh::Error>(())
//! ```
//!
//! # Mesh triangles held in memory
//! ```
//! use delamesh::{MeshSettings, Mesher, Point3, SurfaceMesh};
//!
//! // A unit cube: 8 corners, 12 outward triangles. Its edges are sharp, so they are kept.
//! let corner = |i: u32| Point3::new(f64::from(i & 1), f64::from((i >> 1) & 1), f64::from(i >> 2));
//! let quads = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]];
//! let triangles = quads.iter().flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]]).collect();
//! let cube = SurfaceMesh::from_triangles((0..8).map(corner).collect(), triangles);
//! let settings = MeshSettings::builder().edge_size(0.5).facet_size(0.5).build()?;
//! let meshed = Mesher::new(settings).mesh_surface("cube", cube)?;
//! let tets = meshed.tet_mesh();
//! let volume: f64 = (0..tets.tets.len()).map(|t| tets.tet_volume(t)).sum();
//! assert!((volume - 1.0).abs() < 1e-6, "a polyhedron is meshed exactly: {volume}");
//! # Ok::<(), delamesh::Error>(())
//! ```
//!
//! # Write a domain (a plugin linked in)
//! An [`Oracle`] answers the mesher's questions about a domain: is a point inside, where does a
//! segment cross the boundary, and a few points on the boundary to start from. The same trait,
//! exported through `delamesh_core::plugin`, makes a plugin loadable by the command line.
//! ```
//! use delamesh::{
//!     Aabb, MeshSettings, Mesher, OUTSIDE, Oracle, PatchId, Point3, SubdomainId, SurfaceHit,
//!     SurfacePoint,
//! };
//!
//! /// The unit ball.
//! struct Ball;
//!
//! impl Oracle for Ball {
//!     fn bounding_box(&self) -> Aabb {
//!         Aabb { min: Point3::splat(-1.0), max: Point3::splat(1.0) }
//!     }
//!     fn subdomain(&self, p: Point3) -> SubdomainId {
//!         if p.length() < 1.0 { SubdomainId(1) } else { OUTSIDE }
//!     }
//!     fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>) {
//!         // |a + t (b - a)| = 1: a quadratic in t, roots kept in [0, 1].
//!         let d = b - a;
//!         let (qa, qb, qc) = (d.dot(d), 2.0 * a.dot(d), a.dot(a) - 1.0);
//!         let disc = qb * qb - 4.0 * qa * qc;
//!         if qa == 0.0 || disc < 0.0 {
//!             return;
//!         }
//!         for t in [(-qb - disc.sqrt()) / (2.0 * qa), (-qb + disc.sqrt()) / (2.0 * qa)] {
//!             if (0.0..=1.0).contains(&t) {
//!                 out.push(SurfaceHit { point: a + t * d, t, patch: PatchId(1) });
//!             }
//!         }
//!     }
//!     fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>) {
//!         // Far enough along the ray to leave the ball, then the segment query.
//!         let far = origin + dir * (4.0 + origin.length()) / dir.length();
//!         self.segment_hits(origin, far, out);
//!         let scale = (far - origin).length() / dir.length();
//!         out.iter_mut().for_each(|h| h.t *= scale);
//!     }
//!     fn initial_points(&self) -> Vec<SurfacePoint> {
//!         let axes = [Point3::X, Point3::Y, Point3::Z];
//!         axes.iter().flat_map(|&a| [a, -a]).map(|point| SurfacePoint { point, patch: PatchId(1) }).collect()
//!     }
//! }
//!
//! let settings = MeshSettings::builder().facet_size(0.3).cell_size(0.3).build()?;
//! let meshed = Mesher::new(settings).mesh_oracle("ball", Ball)?;
//! let boundary = delamesh::core::quality::surface_topology(&meshed.complex.facets);
//! assert!(boundary.is_closed_manifold() && boundary.euler_characteristic == 2, "a sphere");
//! # Ok::<(), delamesh::Error>(())
//! ```
//!
//! The workspace crates stay reachable one level down: [`core`], [`formats`], [`polyhedral`],
//! [`piecewise_smooth`], [`image_label`], [`subdivision`]. The command line (`src/main.rs`,
//! `src/cli/`) is behind the default `cli` feature; `default-features = false` leaves only the
//! library.

mod delaunay;
mod domain;
mod error;
#[cfg(feature = "json")]
pub mod info;
mod pipeline;
pub mod plugins;
pub mod report;
mod settings;
mod sizing;

pub use delamesh_core as core;
pub use delamesh_formats as formats;
pub use delamesh_image_label as image_label;
pub use delamesh_piecewise_smooth as piecewise_smooth;
pub use delamesh_polyhedral as polyhedral;
pub use delamesh_subdivision as subdivision;

pub use delamesh_core::{
    Aabb, Cancel, CurveId, MeshComplex, OUTSIDE, Oracle, PatchId, Point3, Progress, RefineError,
    SubdomainId, SurfaceHit, SurfaceMesh, SurfacePoint, TetMesh,
};
pub use delamesh_formats::WriteOptions;
pub use delaunay::{Tetrahedralization, delaunay};
pub use domain::Domain;
pub use error::Error;
pub use pipeline::{Meshed, Mesher, ProgressFn, mesh_file};
pub use report::{Report, SubdomainReport, Times};
pub use settings::{
    FeatureSettings, ImageSettings, MeshSettings, MeshSettingsBuilder, SettingsError,
};
pub use sizing::{COVER_TOLERANCE, SizeSource, SizingFieldError, SizingSettings};
