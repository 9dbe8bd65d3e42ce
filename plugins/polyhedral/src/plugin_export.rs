//! The polyhedral oracle as a plugin: built in (`--plugin polyhedral`, through
//! [`PluginOracle::from_config`]) and, with the feature `cdylib`, exported through
//! `delamesh_plugin_v1` so that both paths can be compared and third-party hosts can load it. Its
//! configuration string is the path of the closed surface file.
//!
//! The C-ABI library: `cargo rustc -p delamesh-polyhedral --lib --crate-type cdylib --features
//! cdylib`; the feature is off in normal builds because two crates exporting the entry point cannot
//! be linked into one binary.

use crate::PolyhedralOracle;
use delamesh_core::plugin::PluginOracle;
use std::path::Path;

impl PluginOracle for PolyhedralOracle {
    fn from_config(config: &str) -> Result<Self, String> {
        let path = Path::new(config.trim());
        if path.as_os_str().is_empty() {
            return Err("the configuration must be the path of a closed surface file".into());
        }
        let surface = delamesh_formats::read_surface(path, None)
            .map_err(|e| e.to_string())?
            .mesh;
        let patches = surface.oracle_patches();
        PolyhedralOracle::new(&surface.positions, &surface.triangles, Some(&patches))
            .map_err(|e| format!("{}: {e}", path.display()))
    }
}

#[cfg(feature = "cdylib")]
delamesh_core::export_oracle_plugin!(PolyhedralOracle, name = "polyhedral", kind = "surface-mesh");
