//! Oracle over a segmented 3D image (CGAL Mesh_3's labelled image domain): the subdomain of a
//! point is the label of its voxel, every interface between two labels is its own surface patch,
//! and the background label is the outside.
//!
//! The label between voxel centres is chosen by [`Interpolation`]: the nearest voxel, or (the
//! default, as CGAL) the label whose trilinearly interpolated indicator function is largest,
//! which gives smoother interfaces. Segment queries walk the voxels along the segment (skipping
//! blocks of one label) and bisect each change of label to a thousandth of a voxel.
//!
//! Gray-level images are meshed as `{value ≥ isovalue}` (subdomain 1).
//!
//! Feature curves (CGAL 6's `Detect_features_in_image` and `Detect_features_on_image_bbox`): the
//! curves where three or more labels meet and where labels meet the image border are the
//! oracle's feature curves, protected by the mesher like the sharp edges of a CAD part, so that
//! they come out as chains of mesh edges.

mod features;
mod grid;
mod initial;
mod labels;
mod oracle;
mod plugin_export;
mod walk;

pub use grid::Interpolation;
pub use labels::{MAX_LABELS, label_value};
pub use oracle::ImageLabelOracle;

/// How an image becomes a domain.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageOptions {
    /// The label of the outside (0 unless given).
    pub background: u32,
    /// Mesh a gray-level image as `{value ≥ isovalue}` instead of reading labels.
    pub isovalue: Option<f64>,
    /// The label between voxel centres.
    pub interpolation: Interpolation,
    /// Protect the curves where three labels meet and where labels meet the image border, so
    /// that they come out as mesh edges (trilinear interpolation only).
    pub features: bool,
}

impl Default for ImageOptions {
    fn default() -> Self {
        ImageOptions {
            background: 0,
            isovalue: None,
            interpolation: Interpolation::default(),
            features: true,
        }
    }
}

/// Why an image cannot be meshed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum ImageLabelError {
    /// A voxel value that is not a label.
    #[error(
        "voxel {voxel} holds {value}, not a label (a non-negative integer): for a gray-level image give an isovalue"
    )]
    NotALabel {
        /// The value found.
        value: f64,
        /// Its x-fastest voxel index.
        voxel: usize,
    },
    /// More labels than patch numbers can pair.
    #[error("the image has {0} labels; at most {MAX_LABELS} are supported")]
    TooManyLabels(usize),
    /// Nothing but background.
    #[error("the image has no voxel outside the background label {0}: nothing to mesh")]
    Empty(u32),
    /// The isovalue is not a number.
    #[error("the isovalue {0} is not a finite number")]
    BadIsovalue(f64),
    /// The image itself is inconsistent.
    #[error("invalid image: {0}")]
    Image(String),
}
