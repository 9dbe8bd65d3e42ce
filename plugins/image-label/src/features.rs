//! Feature curves of a labelled image: where three or more labels meet, and where labels meet
//! the image border.

use crate::grid::{Class, ClassGrid};
use glam::DVec3;

/// Polylines in index space, each with whether it is closed.
pub(crate) fn feature_lines<C: Class>(_g: &ClassGrid<C>) -> Vec<(Vec<DVec3>, bool)> {
    Vec::new()
}
