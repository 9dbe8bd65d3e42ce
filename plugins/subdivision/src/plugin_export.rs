//! The subdivision oracle as a plugin: built in (`--plugin subdivision`, through
//! [`PluginOracle::from_config`]) and, with the feature `cdylib`, exported through
//! `delamesh_plugin_v1`. Configuration: the path of the control mesh (OBJ, OFF, PLY) on the
//! first line, then optional `scheme=loop|catmull-clark`, `crease-angle=DEG`,
//! `group-creases=no` and `features=FILE` lines.

use crate::{SubdivisionOptions, SubdivisionOracle};
use delamesh_core::plugin::PluginOracle;
use std::path::Path;

impl PluginOracle for SubdivisionOracle {
    fn from_config(config: &str) -> Result<Self, String> {
        let mut lines = config.lines().map(str::trim).filter(|l| !l.is_empty());
        let path = Path::new(lines.next().unwrap_or_default());
        if path.as_os_str().is_empty() {
            return Err("the configuration must start with the path of a control mesh".into());
        }
        let mut options = SubdivisionOptions::default();
        let mut polylines = Vec::new();
        for line in lines {
            match line.split_once('=').map(|(k, v)| (k.trim(), v.trim())) {
                Some(("scheme", v)) => options.scheme = Some(v.parse()?),
                Some(("crease-angle", v)) => {
                    let deg = v
                        .parse::<f64>()
                        .ok()
                        .filter(|d| (0.0..=180.0).contains(d))
                        .ok_or_else(|| format!("{line:?}: not an angle in degrees (0 to 180)"))?;
                    options.crease_angle_deg = Some(deg);
                }
                Some(("group-creases", "no")) => options.group_creases = false,
                Some(("group-creases", "yes")) => options.group_creases = true,
                Some(("features", v)) => {
                    polylines = delamesh_piecewise_smooth::read_polylines(Path::new(v))
                        .map_err(|e| e.to_string())?;
                }
                _ => {
                    return Err(format!(
                        "unknown configuration line {line:?} (expected scheme=loop|catmull-clark, \
                         crease-angle=DEG, group-creases=yes|no or features=FILE)"
                    ));
                }
            }
        }
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
