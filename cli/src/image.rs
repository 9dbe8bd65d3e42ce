//! `delamesh mesh IMAGE`: a segmented (or, with `--isovalue`, gray-level) 3D image, recognised by
//! its extension, meshed through the image-label oracle: one subdomain per label, numbered by the
//! label value.

use crate::mesh::{MeshArgs, override_criteria, progress_bar};
use anyhow::{Context, Result, anyhow, bail};
use delamesh_core::refine::criteria::Sizing;
use delamesh_core::refine::{Limits, MeshError, MeshOptions, mesh_domain};
use delamesh_formats::image::read_image;
use delamesh_formats::{WriteOptions, write_tet_mesh};
use delamesh_image_label::{ImageLabelOracle, ImageOptions, Interpolation};
use std::collections::BTreeMap;
use std::path::Path;

/// Options of `delamesh mesh` that apply to images only.
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
    /// The label between voxel centres: nearest voxel, or the largest trilinearly interpolated
    /// label indicator (smoother interfaces, as CGAL).
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
    fn options(&self) -> ImageOptions {
        ImageOptions {
            background: self.background,
            isovalue: self.isovalue,
            interpolation: match self.label_interpolation {
                LabelInterpolation::Nearest => Interpolation::Nearest,
                LabelInterpolation::Trilinear => Interpolation::Trilinear,
            },
        }
    }
}

/// Parses `1=2,3=8` into label → size, sizes positive.
fn per_label(spec: &str) -> Result<BTreeMap<u32, f64>> {
    let mut values = BTreeMap::new();
    for item in spec.split(',').map(str::trim).filter(|s| !s.is_empty()) {
        let parsed = item.split_once('=').and_then(|(l, s)| {
            let size = s.trim().parse::<f64>().ok()?;
            Some((l.trim().parse::<u32>().ok()?, size))
        });
        match parsed {
            Some((label, size)) if size.is_finite() && size > 0.0 => {
                values.insert(label, size);
            }
            _ => bail!(
                "--cell-size-per-label: {item:?} is not LABEL=SIZE with a positive size (e.g. 1=2,3=8)"
            ),
        }
    }
    Ok(values)
}

/// Meshes the image at `input` and writes the mesh; nothing is written on failure.
pub(crate) fn mesh(args: &MeshArgs, input: &Path) -> Result<()> {
    if args.report.is_some() {
        bail!("--report compares the mesh with an input surface and is not available for images");
    }
    let per_label_sizes = args
        .image
        .cell_size_per_label
        .as_deref()
        .map(per_label)
        .transpose()?;
    let image = read_image(input)?;
    let oracle = ImageLabelOracle::new(&image, &args.image.options())
        .map_err(|e| anyhow!("{}: {e}", input.display()))?;
    drop(image);
    let mut criteria = override_criteria(args, oracle.default_criteria())?;
    if let Some(values) = per_label_sizes {
        let default = criteria.cell.size.at(glam::DVec3::ZERO, 0);
        criteria.cell.size = Sizing::PerLabel { default, values };
    }
    let options = MeshOptions {
        criteria,
        limits: Limits {
            max_vertices: args.max_vertices,
            ..Limits::default()
        },
        keep_partial: args.keep_partial,
    };
    let bar = progress_bar(args.quiet);
    let outcome = mesh_domain(&oracle, &options, &mut |p| {
        bar.set_message(format!("{} vertices", p.vertices));
        bar.tick();
    });
    bar.finish_and_clear();
    let (complex, partial_error) = match outcome {
        Ok(outcome) => (outcome.complex, None),
        Err(MeshError::Refinement {
            source,
            partial: Some(complex),
        }) => (*complex, Some(source)),
        Err(e) => {
            return Err(anyhow::Error::new(e)).context(format!("meshing {}", input.display()));
        }
    };
    if complex.tets.is_empty() {
        bail!(
            "{}: the mesh has no tetrahedron inside the labels (criteria too coarse?)",
            input.display()
        );
    }
    let write_options = WriteOptions {
        ascii: args.ascii,
        ..WriteOptions::default()
    };
    write_tet_mesh(&args.output, &complex.to_tet_mesh(), &write_options)?;
    match partial_error {
        Some(e) => Err(anyhow::Error::new(e).context(format!(
            "{}: stopped early; the partial mesh was written to {}",
            input.display(),
            args.output.display()
        ))),
        None => Ok(()),
    }
}
