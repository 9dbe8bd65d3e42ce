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
use std::path::Path;

impl PluginOracle for ImageLabelOracle {
    fn from_config(config: &str) -> Result<Self, String> {
        let mut lines = config.lines().map(str::trim).filter(|l| !l.is_empty());
        let path = Path::new(lines.next().unwrap_or_default());
        if path.as_os_str().is_empty() {
            return Err("the configuration must start with the path of a 3D image".into());
        }
        let mut options = ImageOptions::default();
        for line in lines {
            let number = |v: &str| {
                v.parse::<f64>()
                    .map_err(|_| format!("{line:?}: not a number"))
            };
            match line.split_once('=').map(|(k, v)| (k.trim(), v.trim())) {
                Some(("background", v)) => {
                    options.background = v
                        .parse()
                        .map_err(|_| format!("{line:?}: not a label (non-negative integer)"))?;
                }
                Some(("isovalue", v)) => options.isovalue = Some(number(v)?),
                Some(("interpolation", "nearest")) => {
                    options.interpolation = Interpolation::Nearest
                }
                Some(("interpolation", "trilinear")) => {
                    options.interpolation = Interpolation::Trilinear;
                }
                Some(("features", "on")) => options.features = true,
                Some(("features", "off")) => options.features = false,
                _ => {
                    return Err(format!(
                        "unknown configuration line {line:?} (expected background=L, isovalue=V, \
                         interpolation=nearest|trilinear or features=on|off)"
                    ));
                }
            }
        }
        let image = delamesh_formats::image::read_image(path).map_err(|e| e.to_string())?;
        ImageLabelOracle::new(&image, &options).map_err(|e| format!("{}: {e}", path.display()))
    }
}

#[cfg(feature = "cdylib")]
delamesh_core::export_oracle_plugin!(ImageLabelOracle, name = "image-label", kind = "image");
