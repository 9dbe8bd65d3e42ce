//! Oracle plugins on the command line: the `--plugin` / `--plugin-config` flags of the commands
//! that mesh, and the `delamesh plugins` subcommand (list, or check one). Finding and loading a
//! plugin is the library's ([`delamesh::plugins`]).

use super::output::outln;
use anyhow::{Context, Result};
use delamesh::plugins::{BUILT_IN, PLUGIN_PATH_VAR, installed_libraries, load_domain, search_dirs};
use delamesh_core::plugin::PluginLibrary;

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

/// Runs `delamesh plugins`.
pub fn run(args: &PluginsArgs) -> Result<()> {
    match &args.check.plugin {
        Some(spec) => check(spec, &args.check.plugin_config),
        None => Ok(list()?),
    }
}

fn check(spec: &str, config: &str) -> Result<()> {
    let domain = load_domain(spec, config).with_context(|| format!("checking plugin `{spec}`"))?;
    let oracle = domain.oracle();
    let bbox = oracle.bounding_box();
    let counts = [
        oracle.initial_points().len(),
        oracle.feature_curves().len(),
        oracle.corners().len(),
    ];
    domain.check()?;
    outln!("ok: plugin `{spec}` passed its self-check")?;
    outln!("  bounding box   [{}, {}]", bbox.min, bbox.max)?;
    outln!(
        "  initial points {}, feature curves {}, corners {}",
        counts[0],
        counts[1],
        counts[2]
    )?;
    Ok(())
}

fn list() -> std::io::Result<()> {
    let version = env!("CARGO_PKG_VERSION");
    outln!("built-in plugins (linked into this binary):")?;
    for b in BUILT_IN {
        outln!(
            "  {:<16} {version:<10} {:<16} {}",
            b.name,
            b.kind,
            b.description
        )?;
    }
    let dirs = search_dirs();
    if dirs.is_empty() {
        outln!("{PLUGIN_PATH_VAR} is not set: no installed plugins searched")?;
        return Ok(());
    }
    outln!("plugins in {PLUGIN_PATH_VAR}:")?;
    let libraries = installed_libraries();
    if libraries.is_empty() {
        outln!("  (none)")?;
    }
    for path in libraries {
        match PluginLibrary::open(&path) {
            Ok(library) => {
                let info = library.info();
                outln!(
                    "  {:<16} {:<10} {:<16} ABI v{}  {}",
                    info.name,
                    info.version,
                    info.kind,
                    info.abi_version,
                    path.display()
                )?;
            }
            Err(error) => outln!("  (unusable) {error}")?,
        }
    }
    Ok(())
}
