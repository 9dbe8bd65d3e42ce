//! The subdivision oracle as a plugin: built in (`--plugin subdivision`, through
//! [`PluginOracle::from_config`]) and, with the feature `cdylib`, exported through
//! `delamesh_plugin_v1`. Configuration: the path of the control mesh (OBJ, OFF, PLY) on the
//! first line, then optional `scheme=loop|catmull-clark`, `crease-angle=DEG`,
//! `group-creases=no` and `features=FILE` lines.

use crate::{SubdivisionOptions, SubdivisionOracle};
use delamesh_core::plugin::PluginOracle;
use delamesh_piecewise_smooth::{read_config, read_polylines};
use std::path::Path;

/// What the first line names, and the `key=value` lines known.
const INPUT: &str = "a control mesh";
const EXPECTED: &str =
    "scheme=loop|catmull-clark, crease-angle=DEG, group-creases=yes|no or features=FILE";

impl PluginOracle for SubdivisionOracle {
    fn from_config(config: &str) -> Result<Self, String> {
        let mut options = SubdivisionOptions::default();
        let mut polylines = Vec::new();
        let path = read_config(config, INPUT, EXPECTED, |line, kv| {
            match kv {
                ("scheme", v) => options.scheme = Some(v.parse()?),
                ("crease-angle", v) => {
                    let deg = v
                        .parse::<f64>()
                        .ok()
                        .filter(|d| (0.0..=180.0).contains(d))
                        .ok_or_else(|| format!("{line:?}: not an angle in degrees (0 to 180)"))?;
                    options.crease_angle_deg = Some(deg);
                }
                ("group-creases", "no") => options.group_creases = false,
                ("group-creases", "yes") => options.group_creases = true,
                ("features", v) => {
                    polylines = read_polylines(Path::new(v)).map_err(|e| e.to_string())?;
                }
                _ => return Ok(false),
            }
            Ok(true)
        })?;
        let (mesh, _warnings) =
            delamesh_formats::read_polygons(path, None).map_err(|e| e.to_string())?;
        SubdivisionOracle::new(&mesh, &options, &polylines)
            .map_err(|e| format!("{}: {e}", path.display()))
    }
}

#[cfg(feature = "cdylib")]
delamesh_core::export_oracle_plugin!(
    SubdivisionOracle,
    name = "subdivision",
    kind = "subdivision-surface"
);
