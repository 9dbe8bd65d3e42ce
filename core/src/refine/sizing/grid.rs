//! Sizes on a regular grid: a size image, or the grid gradation runs on.

use super::{SizingError, SizingField, check_value};
use crate::kernel::Point3;
use glam::DAffine3;

/// Values at the nodes of a regular grid, trilinear between them; a point outside the grid takes
/// the value of the nearest point on its border (the index is clamped). Node `(i, j, k)` holds
/// `values[i + nx (j + ny k)]` and lies at `index_to_world((i, j, k))`, as voxel centres of an
/// image.
#[derive(Clone, Debug)]
pub struct SizeGrid {
    dims: [usize; 3],
    index_to_world: DAffine3,
    world_to_index: DAffine3,
    values: Vec<f64>,
    smallest: f64,
}

impl SizeGrid {
    /// A grid of `dims` nodes placed by `index_to_world`; refuses a value that is not finite and
    /// positive (naming its node), a count that does not match, and a singular map.
    pub fn new(
        dims: [usize; 3],
        index_to_world: DAffine3,
        values: Vec<f64>,
    ) -> Result<SizeGrid, SizingError> {
        let count = dims
            .iter()
            .try_fold(1usize, |n, &d| n.checked_mul(d))
            .filter(|&n| n > 0);
        if count != Some(values.len()) {
            return Err(SizingError(format!(
                "{} values for a grid of {:?} nodes",
                values.len(),
                dims
            )));
        }
        let det = index_to_world.matrix3.determinant();
        if !(det.is_finite() && det != 0.0 && index_to_world.translation.is_finite()) {
            return Err(SizingError(
                "the grid's spacing or orientation is not finite and non-zero".into(),
            ));
        }
        let [nx, ny, _] = dims;
        for (n, &v) in values.iter().enumerate() {
            check_value(v, || {
                format!("node ({}, {}, {})", n % nx, (n / nx) % ny, n / (nx * ny))
            })?;
        }
        let smallest = values.iter().copied().fold(f64::INFINITY, f64::min);
        Ok(SizeGrid {
            dims,
            index_to_world,
            world_to_index: index_to_world.inverse(),
            values,
            smallest,
        })
    }

    /// The node counts along the three axes.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Node `n`'s position and value (nodes numbered x fastest, then y, then z).
    pub fn node(&self, n: usize) -> Option<(Point3, f64)> {
        let [nx, ny, _] = self.dims;
        let ijk = Point3::new(
            (n % nx) as f64,
            ((n / nx) % ny) as f64,
            (n / (nx * ny)) as f64,
        );
        let v = *self.values.get(n)?;
        Some((self.index_to_world.transform_point3(ijk), v))
    }

    /// The number of nodes.
    pub fn len(&self) -> usize {
        self.values.len()
    }

    /// Always false: a grid has at least one node.
    pub fn is_empty(&self) -> bool {
        self.values.is_empty()
    }

    /// The trilinear value at `p`.
    pub fn at(&self, p: Point3) -> f64 {
        let q = self.world_to_index.transform_point3(p);
        // Per axis: the cell's first node and the weight of the next one, clamped to the grid.
        let axis = |x: f64, n: usize| -> (usize, usize, f64) {
            let last = (n - 1) as f64;
            let x = if x.is_nan() { 0.0 } else { x.clamp(0.0, last) };
            let i = (x.floor() as usize).min(n - 1);
            let next = (i + 1).min(n - 1);
            (i, next, x - i as f64)
        };
        let (i0, i1, fx) = axis(q.x, self.dims[0]);
        let (j0, j1, fy) = axis(q.y, self.dims[1]);
        let (k0, k1, fz) = axis(q.z, self.dims[2]);
        let [nx, ny, _] = self.dims;
        let v = |i: usize, j: usize, k: usize| self.values[i + nx * (j + ny * k)];
        let lerp = |a: f64, b: f64, t: f64| a + (b - a) * t;
        let x00 = lerp(v(i0, j0, k0), v(i1, j0, k0), fx);
        let x10 = lerp(v(i0, j1, k0), v(i1, j1, k0), fx);
        let x01 = lerp(v(i0, j0, k1), v(i1, j0, k1), fx);
        let x11 = lerp(v(i0, j1, k1), v(i1, j1, k1), fx);
        lerp(lerp(x00, x10, fy), lerp(x01, x11, fy), fz)
    }
}

impl SizingField for SizeGrid {
    fn size_at(&self, p: Point3, _label: u32) -> f64 {
        self.at(p)
    }
    fn smallest(&self) -> Option<f64> {
        Some(self.smallest)
    }
}
