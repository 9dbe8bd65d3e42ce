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
//! Not yet: the curves where three or more labels meet (CGAL 6's `Detect_features_in_image`) are
//! not protected, so triple lines are approximated by the surface facets, not followed by edges.

mod grid;
mod initial;
mod labels;
mod oracle;
#[cfg(feature = "cdylib")]
mod plugin_export;
mod walk;

pub use grid::Interpolation;
pub use labels::MAX_LABELS;
pub use oracle::ImageLabelOracle;

/// How an image becomes a domain.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImageOptions {
    /// The label of the outside (0 unless given).
    pub background: u32,
    /// Mesh a gray-level image as `{value ≥ isovalue}` instead of reading labels.
    pub isovalue: Option<f64>,
    /// The label between voxel centres.
    pub interpolation: Interpolation,
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
