//! The piecewise-smooth oracle as a plugin: built in (`--plugin piecewise-smooth`, through
//! [`PluginOracle::from_config`]) and, with the feature `cdylib`, a C-ABI plugin library, so that
//! hosts loading plugins get the same features the CLI finds. Configuration: the path of the closed
//! surface file on the first line, then optional `feature-angle=DEG` and `features=POLYLINES_FILE`
//! lines.
//!
//! The C-ABI library: `cargo rustc -p delamesh-piecewise-smooth --lib --crate-type cdylib
//! --features cdylib`.

use crate::{FeatureOptions, PiecewiseSmoothOracle, read_polylines};
use delamesh_core::plugin::PluginOracle;
use std::path::Path;

impl PluginOracle for PiecewiseSmoothOracle {
    fn from_config(config: &str) -> Result<Self, String> {
        let mut lines = config.lines().map(str::trim).filter(|l| !l.is_empty());
        let path = Path::new(lines.next().unwrap_or_default());
        if path.as_os_str().is_empty() {
            return Err(
                "the configuration must start with the path of a closed surface file".into(),
            );
        }
        let mut options = FeatureOptions::default();
        let mut polylines = Vec::new();
        for line in lines {
            match line.split_once('=').map(|(k, v)| (k.trim(), v.trim())) {
                Some(("feature-angle", v)) => {
                    options.angle_deg = v
                        .parse()
                        .map_err(|_| format!("feature-angle: {v:?} is not a number"))?;
                }
                Some(("features", v)) => {
                    polylines = read_polylines(Path::new(v)).map_err(|e| e.to_string())?;
                }
                _ => {
                    return Err(format!(
                        "unknown configuration line {line:?} (expected feature-angle=DEG or features=FILE)"
                    ));
                }
            }
        }
        let surface = delamesh_formats::read_surface(path, None)
            .map_err(|e| e.to_string())?
            .mesh;
        PiecewiseSmoothOracle::from_surface(&surface, &options, &polylines)
            .map_err(|e| format!("{}: {e}", path.display()))
    }
}

#[cfg(feature = "cdylib")]
delamesh_core::export_oracle_plugin!(
    PiecewiseSmoothOracle,
    name = "piecewise-smooth",
    kind = "surface-mesh"
);
