//! The one error type of the facade. Each variant says what was being done and names the file,
//! option or plugin; the cause, if any, is its [`source`](std::error::Error::source).

use crate::settings::SettingsError;
use delamesh_core::plugin::PluginError;
use delamesh_core::refine::criteria::CriteriaError;
use delamesh_core::refine::{MeshError, RefineError};
use delamesh_core::triangulation::TriangulationError;
use delamesh_piecewise_smooth::PolylineError;

/// Why the pipeline produced no mesh.
#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// An option has a value it cannot take.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// A sizing field could not be read, holds a bad value, gave one while meshing, or does not
    /// cover the domain.
    #[error(transparent)]
    Sizing(#[from] crate::sizing::SizingFieldError),
    /// Reading the input or writing the output failed.
    #[error(transparent)]
    Format(#[from] delamesh_formats::Error),
    /// The feature polylines file is unreadable or malformed.
    #[error(transparent)]
    Polylines(#[from] PolylineError),
    /// The surface cannot bound a volume (open, self-intersecting, bad feature angle...).
    #[error("{name}: cannot mesh this surface: {problem}")]
    Unmeshable {
        /// The input, as given.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The image cannot be meshed (not labels, only background, too many labels...).
    #[error("{name}: cannot mesh this image: {problem}")]
    Image {
        /// The input, as given.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// The control mesh of a subdivision surface cannot be meshed (open, non-manifold...).
    #[error("{name}: cannot mesh the limit surface of this control mesh: {problem}")]
    Subdivision {
        /// The input, as given.
        name: String,
        /// What is wrong with it.
        problem: String,
    },
    /// Sharp features cannot be taken from the surface with the given feature polylines.
    #[error(
        "{name}: cannot mesh this surface with the feature polylines of {}: {problem}",
        polylines.display()
    )]
    FeaturePolylines {
        /// The input, as given.
        name: String,
        /// The polylines file.
        polylines: std::path::PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// A plugin could not be found, loaded or created, or faulted.
    #[error(transparent)]
    Plugin(#[from] PluginError),
    /// A plugin faulted while answering the mesher; its answers cannot be trusted.
    #[error("the plugin failed while meshing; nothing was written")]
    PluginFault(#[source] PluginError),
    /// A plugin name matches no file and no library of the search path.
    #[error(
        "plugin `{spec}` not found: not a file, and not in {} ({searched})",
        crate::plugins::PLUGIN_PATH_VAR
    )]
    PluginNotFound {
        /// The name or path given.
        spec: String,
        /// The directories searched, or "unset".
        searched: String,
    },
    /// A built-in plugin refused its configuration.
    #[error("plugin `{name}` (built in): {problem}")]
    BuiltInCreate {
        /// The plugin's name.
        name: &'static str,
        /// Why.
        problem: String,
    },
    /// The mesher could not start (no initial points, protection failed...).
    #[error("meshing {name}")]
    Mesh {
        /// The domain: the input file, or the plugin.
        name: String,
        /// Why.
        #[source]
        source: MeshError,
    },
    /// A guard (vertex limit...) stopped refinement and no partial mesh was asked for.
    #[error("meshing {name}")]
    Stopped {
        /// The domain: the input file, or the plugin.
        name: String,
        /// Which guard.
        #[source]
        source: RefineError,
    },
    /// The criteria cannot be met (see [`MeshCriteria::validate`](delamesh_core::refine::criteria::MeshCriteria::validate)).
    #[error("{name}: --{problem}")]
    Criteria {
        /// The domain: the input file, or the plugin.
        name: String,
        /// Which criterion, and why.
        problem: CriteriaError,
    },
    /// Refinement ended without a tetrahedron inside the domain.
    #[error("{name}: the mesh has no tetrahedron inside the {what}{}", empty_hint(*floor))]
    Empty {
        /// The domain: the input file, or the plugin.
        name: String,
        /// "surface" or "domain".
        what: &'static str,
        /// The refinement floor (`--edge-min-size`), when refinement had one.
        floor: Option<f64>,
    },
    /// A point of the set cannot be triangulated (not finite...).
    #[error("{name}: cannot triangulate")]
    Triangulation {
        /// The point set: its file, or "points".
        name: String,
        /// Why.
        #[source]
        source: TriangulationError,
    },
    /// The points span no volume: no tetrahedron.
    #[error(
        "{name}: the {distinct} distinct points are coplanar, collinear or fewer than 4: no tetrahedra"
    )]
    Flat {
        /// The point set: its file, or "points".
        name: String,
        /// How many distinct points there are.
        distinct: usize,
    },
}

/// Why a mesh can come out empty: parts (an image's specks, a thin plate) below the sizes the
/// criteria refine to.
fn empty_hint(floor: Option<f64>) -> String {
    match floor {
        Some(floor) => format!(
            ": its parts are thinner than the criteria resolve (nothing is refined below \
             {floor:.3e}); smaller --facet-size and --edge-min-size resolve them"
        ),
        None => " (criteria too coarse?)".to_string(),
    }
}
