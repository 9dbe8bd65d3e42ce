//! The image oracle as a plugin: built in (`--plugin image-label`, through
//! [`PluginOracle::from_config`]) and, with the feature `cdylib`, exported through
//! `delamesh_plugin_v1`, so that hosts loading plugins mesh images as the CLI does.
//! Configuration: the path of the image on the first line, then optional `background=L`,
//! `isovalue=V`, `interpolation=nearest|trilinear` and `features=on|off` lines.
//!
//! The C-ABI library: `cargo rustc -p delamesh-image-label --lib --crate-type cdylib --features
//! cdylib`.

use crate::{ImageLabelOracle, ImageOptions, Interpolation};
use delamesh_core::plugin::PluginOracle;
use delamesh_piecewise_smooth::{parse_value, read_config};

/// What the first line names, and the `key=value` lines known.
const INPUT: &str = "a 3D image";
const EXPECTED: &str =
    "background=L, isovalue=V, interpolation=nearest|trilinear or features=on|off";

impl PluginOracle for ImageLabelOracle {
    fn from_config(config: &str) -> Result<Self, String> {
        let mut options = ImageOptions::default();
        let path = read_config(config, INPUT, EXPECTED, |line, kv| {
            match kv {
                ("background", v) => {
                    options.background = parse_value(line, v, "a label (non-negative integer)")?;
                }
                ("isovalue", v) => options.isovalue = Some(parse_value(line, v, "a number")?),
                ("interpolation", "nearest") => options.interpolation = Interpolation::Nearest,
                ("interpolation", "trilinear") => {
                    options.interpolation = Interpolation::Trilinear;
                }
                ("features", "on") => options.features = true,
                ("features", "off") => options.features = false,
                _ => return Ok(false),
            }
            Ok(true)
        })?;
        let image = delamesh_formats::image::read_image(path).map_err(|e| e.to_string())?;
        ImageLabelOracle::new(&image, &options).map_err(|e| format!("{}: {e}", path.display()))
    }
}

#[cfg(feature = "cdylib")]
delamesh_core::export_oracle_plugin!(ImageLabelOracle, name = "image-label", kind = "image");
