//! Oracle plugins on the command line: `--plugin` / `--plugin-config` / `DELAMESH_PLUGIN_PATH`
//! resolution shared by the commands that mesh, and the `delamesh plugins` subcommand.

use crate::mesh::{MeshArgs, criteria, progress_bar};
use anyhow::{Context, Result, bail};
use delamesh_core::oracle::Oracle;
use delamesh_core::plugin::{DynOracle, PluginLibrary};
use delamesh_core::refine::{Limits, MeshError, MeshOptions, mesh_domain};
use delamesh_formats::{WriteOptions, write_tet_mesh};
use std::path::{Path, PathBuf};

/// Environment variable listing directories searched for plugins named without a path.
pub const PLUGIN_PATH_VAR: &str = "DELAMESH_PLUGIN_PATH";

/// Plugins linked into this binary: name, kind, what they mesh.
const BUILT_IN: &[(&str, &str, &str)] = &[(
    "polyhedral",
    "surface-mesh",
    "the inside of a closed triangle surface",
)];

/// Selecting an oracle plugin; flattened into every command that meshes.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct PluginArgs {
    /// Oracle plugin: a shared library path, or a name looked up in DELAMESH_PLUGIN_PATH
    /// (file `lib<name>.so` or a plugin whose table says `<name>`).
    #[arg(long, value_name = "PATH")]
    pub plugin: Option<String>,
    /// Configuration string handed to the plugin's `create` (syntax defined by the plugin).
    #[arg(long, value_name = "STR", default_value = "", requires = "plugin")]
    pub plugin_config: String,
}

/// `delamesh plugins`: list built-in and installed plugins, or check one.
#[derive(clap::Args, Debug)]
pub struct PluginsArgs {
    /// Instead of listing, load this plugin, create an oracle and exercise every query once.
    #[command(flatten)]
    pub check: PluginArgs,
}

/// Loads the plugin `spec` (path or name), creates its oracle from `config` and self-checks it, so
/// that a broken plugin fails here with an error naming it rather than in the middle of meshing.
/// The returned oracle records later faults: call [`DynOracle::check`] before using a result.
pub fn load_oracle(spec: &str, config: &str) -> Result<DynOracle> {
    let path = resolve(spec)?;
    let library = PluginLibrary::open(&path)?;
    let oracle = library.create(config)?;
    oracle.self_check()?;
    Ok(oracle)
}

/// `delamesh mesh --plugin SPEC`: the same refinement and output as for a surface file, with the
/// domain answered by the plugin. Nothing is written if the plugin faulted during meshing.
pub fn mesh(args: &MeshArgs, spec: &str) -> Result<()> {
    if args.report.is_some() {
        bail!(
            "--report compares the mesh with an input surface and is not available with --plugin"
        );
    }
    if args.optimize.report_plot.is_some() {
        bail!("--report-plot is drawn with --report and is not available with --plugin");
    }
    let oracle = load_oracle(spec, &args.plugin.plugin_config)?;
    let options = MeshOptions {
        criteria: criteria(args, &oracle)?,
        limits: Limits {
            max_vertices: args.max_vertices,
            ..Limits::default()
        },
        keep_partial: args.keep_partial,
        optimize: args.optimize.options()?,
    };
    let bar = progress_bar(args.quiet);
    let outcome = mesh_domain(&oracle, &options, &mut |p| {
        bar.set_message(format!("{} vertices", p.vertices));
        bar.tick();
    });
    bar.finish_and_clear();
    oracle
        .check()
        .context("the plugin failed while meshing; nothing was written")?;
    let (complex, partial_error) = match outcome {
        Ok(outcome) => (outcome.complex, None),
        Err(MeshError::Refinement {
            source,
            partial: Some(complex),
        }) => (*complex, Some(source)),
        Err(e) => {
            return Err(
                anyhow::Error::new(e).context(format!("meshing the domain of plugin `{spec}`"))
            );
        }
    };
    if complex.tets.is_empty() {
        bail!(
            "plugin `{spec}`: the mesh has no tetrahedron inside the domain (criteria too coarse?)"
        );
    }
    let write_options = WriteOptions {
        ascii: args.ascii,
        ..WriteOptions::default()
    };
    write_tet_mesh(&args.output, &complex.to_tet_mesh(), &write_options)?;
    match partial_error {
        Some(e) => Err(anyhow::Error::new(e).context(format!(
            "plugin `{spec}`: stopped early; the partial mesh was written to {}",
            args.output.display()
        ))),
        None => Ok(()),
    }
}

/// Directories of `DELAMESH_PLUGIN_PATH`, in order.
fn search_dirs() -> Vec<PathBuf> {
    std::env::var_os(PLUGIN_PATH_VAR)
        .map(|v| std::env::split_paths(&v).collect())
        .unwrap_or_default()
}

fn is_library(path: &Path) -> bool {
    let suffix = std::env::consts::DLL_SUFFIX.trim_start_matches('.');
    path.is_file() && path.extension().is_some_and(|e| e == suffix)
}

/// Shared libraries in the search directories, sorted within each directory for a stable order.
fn installed_libraries() -> Vec<PathBuf> {
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
fn resolve(spec: &str) -> Result<PathBuf> {
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
    if BUILT_IN.iter().any(|(name, _, _)| *name == spec) {
        bail!(
            "`{spec}` is built in: use it without --plugin (load its shared library by path to test the C ABI)"
        );
    }
    let dirs: Vec<String> = search_dirs()
        .iter()
        .map(|d| d.display().to_string())
        .collect();
    bail!(
        "plugin `{spec}` not found: not a file, and not in {PLUGIN_PATH_VAR} ({})",
        if dirs.is_empty() {
            "unset".to_string()
        } else {
            dirs.join(", ")
        }
    )
}

/// Runs `delamesh plugins`.
pub fn run(args: &PluginsArgs) -> Result<()> {
    match &args.check.plugin {
        Some(spec) => check(spec, &args.check.plugin_config),
        None => {
            list();
            Ok(())
        }
    }
}

fn check(spec: &str, config: &str) -> Result<()> {
    let oracle = load_oracle(spec, config).with_context(|| format!("checking plugin `{spec}`"))?;
    let bbox = oracle.bounding_box();
    let counts = [
        oracle.initial_points().len(),
        oracle.feature_curves().len(),
        oracle.corners().len(),
    ];
    oracle.check()?;
    println!("ok: plugin `{spec}` passed its self-check");
    println!("  bounding box   [{}, {}]", bbox.min, bbox.max);
    println!(
        "  initial points {}, feature curves {}, corners {}",
        counts[0], counts[1], counts[2]
    );
    Ok(())
}

fn list() {
    let version = env!("CARGO_PKG_VERSION");
    println!("built-in plugins (linked into this binary):");
    for (name, kind, what) in BUILT_IN {
        println!("  {name:<16} {version:<10} {kind:<16} {what}");
    }
    let dirs = search_dirs();
    if dirs.is_empty() {
        println!("{PLUGIN_PATH_VAR} is not set: no installed plugins searched");
        return;
    }
    println!("plugins in {PLUGIN_PATH_VAR}:");
    let libraries = installed_libraries();
    if libraries.is_empty() {
        println!("  (none)");
    }
    for path in libraries {
        match PluginLibrary::open(&path) {
            Ok(library) => {
                let info = library.info();
                println!(
                    "  {:<16} {:<10} {:<16} ABI v{}  {}",
                    info.name,
                    info.version,
                    info.kind,
                    info.abi_version,
                    path.display()
                );
            }
            Err(error) => println!("  (unusable) {error}"),
        }
    }
}
