//! Finding oracle plugins: a library path as given, or a name looked up in the directories of
//! [`PLUGIN_PATH_VAR`].

use crate::domain::Domain;
use crate::error::Error;
use delamesh_core::plugin::{DynOracle, PluginLibrary, PluginOracle};
use delamesh_image_label::ImageLabelOracle;
use delamesh_piecewise_smooth::PiecewiseSmoothOracle;
use delamesh_polyhedral::PolyhedralOracle;
use delamesh_subdivision::SubdivisionOracle;
use std::path::{Path, PathBuf};

/// Environment variable listing directories searched for plugins named without a path.
pub const PLUGIN_PATH_VAR: &str = "DELAMESH_PLUGIN_PATH";

/// A plugin linked into this library: its name, kind and what it meshes.
#[derive(Clone, Copy, Debug)]
pub struct BuiltIn {
    /// The name `--plugin` takes (the same as in its C-ABI table).
    pub name: &'static str,
    /// The kind of input it reads.
    pub kind: &'static str,
    /// What it meshes.
    pub description: &'static str,
    /// Creates the domain from the plugin's configuration string.
    create: fn(&str) -> Result<Domain, String>,
}

/// A [`BuiltIn`] whose `create` is `$oracle::from_config` wrapped in `Domain::$variant`.
macro_rules! built_in {
    ($name:literal, $kind:literal, $oracle:ident => $variant:ident, $description:literal) => {
        BuiltIn {
            name: $name,
            kind: $kind,
            description: $description,
            create: |config| $oracle::from_config(config).map(Domain::$variant),
        }
    };
}

/// The plugins linked into this library; their configuration strings are those of their C-ABI
/// libraries.
pub const BUILT_IN: &[BuiltIn] = &[
    built_in!("polyhedral", "surface-mesh", PolyhedralOracle => Smooth,
        "the inside of a closed triangle surface (config: its path)"),
    built_in!("piecewise-smooth", "surface-mesh", PiecewiseSmoothOracle => PiecewiseSmooth,
        "the same, keeping sharp edges and corners (config: path, feature-angle=, features=)"),
    built_in!("subdivision", "subdivision-surface", SubdivisionOracle => Subdivision,
        "the inside of the limit surface of a Loop or Catmull-Clark control mesh (config: path, scheme=, crease-angle=, group-creases=, features=)"),
    built_in!("image-label", "image", ImageLabelOracle => Image,
        "the labels of a segmented 3D image (config: path, background=, isovalue=, interpolation=, features=)"),
];

/// Loads the plugin `spec` (path or name), creates its oracle from `config` and self-checks it, so
/// that a broken plugin fails here with an error naming it rather than in the middle of meshing.
/// The returned oracle records later faults: call [`DynOracle::check`] before using a result.
pub fn load_oracle(spec: &str, config: &str) -> Result<DynOracle, Error> {
    let path = resolve(spec)?;
    let library = PluginLibrary::open(&path)?;
    let oracle = library.create(config)?;
    oracle.self_check()?;
    Ok(oracle)
}

/// The domain of plugin `spec`: a library found by [`load_oracle`]'s rules, or else the built-in
/// plugin of that name, created in process.
pub fn load_domain(spec: &str, config: &str) -> Result<Domain, Error> {
    match (load_oracle(spec, config), built_in(spec)) {
        (Err(Error::PluginNotFound { .. }), Some(b)) => {
            (b.create)(config).map_err(|problem| Error::BuiltInCreate {
                name: b.name,
                problem,
            })
        }
        (found, _) => found.map(Domain::Plugin),
    }
}

/// The built-in plugin called `name`.
pub fn built_in(name: &str) -> Option<&'static BuiltIn> {
    BUILT_IN.iter().find(|b| b.name == name)
}

/// Directories of `DELAMESH_PLUGIN_PATH`, in order.
pub fn search_dirs() -> Vec<PathBuf> {
    std::env::var_os(PLUGIN_PATH_VAR)
        .map(|v| std::env::split_paths(&v).collect())
        .unwrap_or_default()
}

fn is_library(path: &Path) -> bool {
    let suffix = std::env::consts::DLL_SUFFIX.trim_start_matches('.');
    path.is_file() && path.extension().is_some_and(|e| e == suffix)
}

/// Shared libraries in the search directories, sorted within each directory for a stable order.
pub fn installed_libraries() -> Vec<PathBuf> {
    let mut found = Vec::new();
    for dir in search_dirs() {
        let Ok(entries) = std::fs::read_dir(&dir) else {
            continue;
        };
        let mut libraries: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| is_library(p))
            .collect();
        libraries.sort();
        found.extend(libraries);
    }
    found
}

/// A path is taken as given; a bare name is looked up in `DELAMESH_PLUGIN_PATH`, first by file
/// name (`lib<name>.so`, `<name>.so`), then by the name in the plugin's table.
fn resolve(spec: &str) -> Result<PathBuf, Error> {
    let as_path = Path::new(spec);
    if as_path.components().count() > 1 || as_path.exists() {
        return Ok(as_path.to_path_buf());
    }
    let (prefix, suffix) = (std::env::consts::DLL_PREFIX, std::env::consts::DLL_SUFFIX);
    let file_names = [format!("{prefix}{spec}{suffix}"), format!("{spec}{suffix}")];
    let libraries = installed_libraries();
    if let Some(path) = libraries.iter().find(|p| {
        p.file_name()
            .is_some_and(|n| file_names.iter().any(|f| n == f.as_str()))
    }) {
        return Ok(path.clone());
    }
    if let Some(path) = libraries
        .iter()
        .find(|p| PluginLibrary::open(p).is_ok_and(|l| l.info().name == spec))
    {
        return Ok(path.clone());
    }
    let dirs: Vec<String> = search_dirs()
        .iter()
        .map(|d| d.display().to_string())
        .collect();
    Err(Error::PluginNotFound {
        spec: spec.to_string(),
        searched: if dirs.is_empty() {
            "unset".to_string()
        } else {
            dirs.join(", ")
        },
    })
}
