//! Sizing fields users bring: a size (or a facet distance) that varies in space, evaluated at a
//! point by the edge-, facet- and cell-size criteria through [`Sizing::Field`](super::criteria::Sizing).
//!
//! Sources, each checked on construction (every value finite and positive):
//! - [`SizeGrid`]: values on a regular grid (a size image, or the gradation grid), trilinear;
//! - [`BackgroundMesh`]: values at the nodes of a tetrahedral mesh, linear in the containing tet,
//!   the nearest node's value outside every tet;
//! - [`PointSizes`]: values at scattered points, inverse-distance weighted over the nearest ones;
//! - any closure `Fn(Point3, u32) -> f64`, wrapped in [`Checked`] so that a bad value met during
//!   refinement is reported instead of looping.
//!
//! [`graded`] limits how fast a field grows (|∇h| ≤ G), from the field's small values and from
//! the sharp features' protecting balls ([`feature_sizes`]). Reading files is the formats crate's
//! job: this module takes arrays.

mod background;
mod cloud;
mod features;
mod gradation;
mod grid;

pub use background::BackgroundMesh;
pub use cloud::{IDW_NEIGHBOURS, PointSizes};
pub use features::feature_sizes;
pub use gradation::{DEFAULT_GRADATION_NODES, Graded, graded};
pub use grid::SizeGrid;

use crate::kernel::Point3;
use std::sync::{Arc, OnceLock};

/// A size (or distance bound) that varies in space. `label` is the subdomain for cell criteria,
/// the surface patch for facet criteria and the curve for edge sizes; most fields ignore it.
pub trait SizingField: Send + Sync {
    /// The value at `p`.
    fn size_at(&self, p: Point3, label: u32) -> f64;
    /// A lower bound of the values, when known: the criteria check estimates vertex counts
    /// from it before meshing.
    fn smallest(&self) -> Option<f64> {
        None
    }
}

impl<F: Fn(Point3, u32) -> f64 + Send + Sync> SizingField for F {
    fn size_at(&self, p: Point3, label: u32) -> f64 {
        self(p, label)
    }
}

/// Why a sizing field was refused: one sentence naming the value and where it is.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct SizingError(pub String);

/// Checks one sample: finite and positive.
pub(crate) fn check_value(v: f64, at: impl FnOnce() -> String) -> Result<(), SizingError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(SizingError(format!(
            "{} holds {v}, not a positive size",
            at()
        )))
    }
}

/// Checks that there is one value per node or point (`n` of them, called `what`).
pub(crate) fn check_count(values: usize, n: usize, what: &str) -> Result<(), SizingError> {
    if values == n {
        Ok(())
    } else {
        Err(SizingError(format!("{values} values for {n} {what}")))
    }
}

/// A field whose values cannot be checked in advance (a closure, an expression): a value that is
/// not finite and positive counts as no bound, and the first one met is kept for
/// [`Checked::first_bad`], so the caller can refuse the mesh with the point and the value.
/// Refinement is sequential, so the point kept is the same on every run.
pub struct Checked {
    inner: Arc<dyn SizingField>,
    bad: OnceLock<(Point3, f64)>,
}

impl Checked {
    /// Wraps `inner`.
    pub fn new(inner: Arc<dyn SizingField>) -> Self {
        Checked {
            inner,
            bad: OnceLock::new(),
        }
    }

    /// The first point where the field gave a value that is not a positive number, and the
    /// value.
    pub fn first_bad(&self) -> Option<(Point3, f64)> {
        self.bad.get().copied()
    }
}

impl SizingField for Checked {
    fn size_at(&self, p: Point3, label: u32) -> f64 {
        let v = self.inner.size_at(p, label);
        if v.is_finite() && v > 0.0 {
            v
        } else {
            let _ = self.bad.set((p, v));
            f64::INFINITY
        }
    }
    fn smallest(&self) -> Option<f64> {
        self.inner.smallest()
    }
}

/// Formats a point for error messages.
pub(crate) fn show(p: Point3) -> String {
    format!("({}, {}, {})", p.x, p.y, p.z)
}

#[cfg(test)]
mod tests;
