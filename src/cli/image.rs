//! The flags of `delamesh mesh` that apply to 3D images (recognised by their extension), mapped to
//! the library's [`ImageSettings`].

use anyhow::{Result, bail};
use delamesh::ImageSettings;
use delamesh::image_label::{ImageOptions, Interpolation};
use std::collections::BTreeMap;

/// Options of segmented and gray-level images.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ImageArgs {
    /// Label of the outside of a segmented image.
    #[arg(long, value_name = "L", default_value_t = 0)]
    pub background: u32,
    /// Mesh a gray-level image as {value ≥ V} instead of reading labels.
    #[arg(long, value_name = "V")]
    pub isovalue: Option<f64>,
    /// Largest tetrahedron circumradius per label, e.g. `1=2,3=8` (others: --cell-size).
    #[arg(long, value_name = "L=SIZE,...")]
    pub cell_size_per_label: Option<String>,
    /// The label between voxel centres: the nearest voxel's, or the largest trilinearly
    /// interpolated label indicator (smoother interfaces, as CGAL).
    #[arg(long, value_enum, default_value = "trilinear")]
    pub label_interpolation: LabelInterpolation,
}

/// `--label-interpolation` values.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum LabelInterpolation {
    /// The nearest voxel's label.
    Nearest,
    /// The largest trilinearly interpolated label indicator.
    #[default]
    Trilinear,
}

impl ImageArgs {
    /// The library's image settings for these flags.
    pub fn settings(&self) -> Result<ImageSettings> {
        Ok(ImageSettings {
            options: ImageOptions {
                background: self.background,
                isovalue: self.isovalue,
                interpolation: match self.label_interpolation {
                    LabelInterpolation::Nearest => Interpolation::Nearest,
                    LabelInterpolation::Trilinear => Interpolation::Trilinear,
                },
                ..ImageOptions::default()
            },
            cell_size_per_label: match &self.cell_size_per_label {
                Some(spec) => per_label("cell-size-per-label", spec)?,
                None => BTreeMap::new(),
            },
        })
    }
}

/// Parses `1=2,3=8` given to `--option` into label → size (the sizes are validated with the
/// other settings).
pub fn per_label(option: &str, spec: &str) -> Result<BTreeMap<u32, f64>> {
    let mut values = BTreeMap::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let parsed = item.split_once('=').and_then(|(l, s)| {
            Some((l.trim().parse::<u32>().ok()?, s.trim().parse::<f64>().ok()?))
        });
        match parsed {
            Some((label, size)) => {
                values.insert(label, size);
            }
            None => bail!("--{option}: {item:?} is not LABEL=SIZE (e.g. 1=2,3=8)"),
        }
    }
    Ok(values)
}
