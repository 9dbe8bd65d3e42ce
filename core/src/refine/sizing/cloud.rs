//! Sizes at scattered points.

use super::{SizingError, SizingField, check_count, check_value, show};
use crate::kernel::Point3;
use rstar::RTree;
use rstar::primitives::GeomWithData;

/// How many nearest samples [`PointSizes`] weighs.
pub const IDW_NEIGHBOURS: usize = 8;

/// Sizes at scattered points, interpolated by Shepard's inverse-distance rule over the
/// [`IDW_NEIGHBOURS`] nearest samples: h(x) = Σ wᵢ hᵢ / Σ wᵢ with wᵢ = 1 / |x − xᵢ|², the sample's
/// own value at a sample. The result stays between the smallest and largest sample, so it is
/// positive everywhere, and it is continuous except where the set of nearest samples changes
/// (where the far ones weigh little).
pub struct PointSizes {
    tree: RTree<GeomWithData<[f64; 3], f64>>,
    smallest: f64,
}

impl PointSizes {
    /// Sizes `values[i]` at `points[i]`; refuses no point, mismatched counts, a non-finite point
    /// and a value that is not finite and positive (naming the sample).
    pub fn new(points: &[Point3], values: &[f64]) -> Result<PointSizes, SizingError> {
        check_count(values.len(), points.len(), "points")?;
        if points.is_empty() {
            return Err(SizingError("no sample point".into()));
        }
        let mut samples = Vec::with_capacity(points.len());
        for (i, (&p, &v)) in points.iter().zip(values).enumerate() {
            if !p.is_finite() {
                return Err(SizingError(format!("sample {i} is at {}", show(p))));
            }
            check_value(v, || format!("sample {i} {}", show(p)))?;
            samples.push(GeomWithData::new(p.to_array(), v));
        }
        let smallest = values.iter().copied().fold(f64::INFINITY, f64::min);
        Ok(PointSizes {
            tree: RTree::bulk_load(samples),
            smallest,
        })
    }

    /// The interpolated value at `p`.
    pub fn at(&self, p: Point3) -> f64 {
        let (mut sum, mut weights) = (0.0, 0.0);
        for s in self
            .tree
            .nearest_neighbor_iter(p.to_array())
            .take(IDW_NEIGHBOURS)
        {
            let d2 = p.distance_squared(Point3::from_array(*s.geom()));
            if d2 == 0.0 {
                return s.data;
            }
            sum += s.data / d2;
            weights += 1.0 / d2;
        }
        if weights > 0.0 && (sum / weights).is_finite() {
            sum / weights
        } else {
            self.smallest
        }
    }
}

impl SizingField for PointSizes {
    fn size_at(&self, p: Point3, _label: u32) -> f64 {
        self.at(p)
    }
    fn smallest(&self) -> Option<f64> {
        Some(self.smallest)
    }
}
