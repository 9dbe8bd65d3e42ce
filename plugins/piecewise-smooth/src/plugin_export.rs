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
use std::str::FromStr;

/// Reads a plugin configuration: the path of `what` on its first non-blank line, then `key=value`
/// lines, each handed to `apply` with the whole line, which returns `Ok(false)` for a key it does
/// not know: an error naming the `expected` lines. Shared by the plugins built on this crate.
pub fn read_config<'a>(
    config: &'a str,
    what: &str,
    expected: &str,
    mut apply: impl FnMut(&str, (&'a str, &'a str)) -> Result<bool, String>,
) -> Result<&'a Path, String> {
    let mut lines = config.lines().map(str::trim).filter(|l| !l.is_empty());
    let path = Path::new(lines.next().unwrap_or_default());
    if path.as_os_str().is_empty() {
        return Err(format!(
            "the configuration must start with the path of {what}"
        ));
    }
    for line in lines {
        let known = match line.split_once('=') {
            Some((k, v)) => apply(line, (k.trim(), v.trim()))?,
            None => false,
        };
        if !known {
            return Err(format!(
                "unknown configuration line {line:?} (expected {expected})"
            ));
        }
    }
    Ok(path)
}

/// `value` of configuration `line` parsed, or an error quoting the line and saying it is not
/// `what`: one wording for the plugins' bad values.
pub fn parse_value<T: FromStr>(line: &str, value: &str, what: &str) -> Result<T, String> {
    value.parse().map_err(|_| format!("{line:?}: not {what}"))
}

/// What the first line names, and the `key=value` lines known.
const INPUT: &str = "a closed surface file";
const EXPECTED: &str = "feature-angle=DEG or features=FILE";

impl PluginOracle for PiecewiseSmoothOracle {
    fn from_config(config: &str) -> Result<Self, String> {
        let mut options = FeatureOptions::default();
        let mut polylines = Vec::new();
        let path = read_config(config, INPUT, EXPECTED, |line, kv| {
            match kv {
                ("feature-angle", v) => options.angle_deg = parse_value(line, v, "a number")?,
                ("features", v) => {
                    polylines = read_polylines(Path::new(v)).map_err(|e| e.to_string())?;
                }
                _ => return Ok(false),
            }
            Ok(true)
        })?;
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
