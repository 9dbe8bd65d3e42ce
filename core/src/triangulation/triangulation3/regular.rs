//! The weighted-point API of [`Regular3`].

use super::{MAX_COORDINATE, Regular3, validate_point};
use crate::kernel::{Point3, WeightedPoint3};
use crate::triangulation::{CellId, InsertOutcome, InsertReport, TriangulationError, VertexId};

/// Largest accepted weight: the square of the largest accepted coordinate, so the lifted
/// coordinate `|p|² − w` stays in the range the exact power test was sized for.
pub const MAX_WEIGHT: f64 = MAX_COORDINATE * MAX_COORDINATE;

/// Rejects weights the power test cannot handle, and negative ones (a ball has a real radius).
pub(super) fn validate_weight(w: f64, index: usize) -> Result<(), TriangulationError> {
    if (0.0..=MAX_WEIGHT).contains(&w) {
        Ok(())
    } else {
        Err(TriangulationError::InvalidWeight {
            index,
            weight: w,
            limit: MAX_WEIGHT,
        })
    }
}

impl Regular3 {
    /// The regular triangulation of `points` (pairs of position and weight), inserted in BRIO
    /// order (the result does not depend on the order). Returns the vertex of every input point,
    /// in input order: equal pairs share a vertex, and a hidden point still gets its own vertex.
    /// Fails without building anything if a point or weight is invalid.
    pub fn from_weighted_points(
        points: &[(Point3, f64)],
    ) -> Result<(Self, Vec<VertexId>), TriangulationError> {
        for (i, &(_, w)) in points.iter().enumerate() {
            validate_weight(w, i)?;
        }
        let positions: Vec<Point3> = points.iter().map(|&(p, _)| p).collect();
        let mut rt = Self::new();
        let vertex_of = rt.insert_many(&positions, |i| points[i].1)?;
        Ok((rt, vertex_of))
    }

    /// Inserts `p` with weight `w`, starting the location walk at `hint` if given, and fills
    /// `report` (cleared first) with the cells created and destroyed and the vertices hidden.
    pub fn insert_weighted(
        &mut self,
        p: Point3,
        w: f64,
        hint: Option<CellId>,
        report: &mut InsertReport,
    ) -> Result<InsertOutcome, TriangulationError> {
        report.clear();
        let index = self.points.len();
        validate_point(p, index)?;
        validate_weight(w, index)?;
        self.insert_validated(p, w, hint, Some(report))
    }

    /// Power distance `|p − point(v)|² − weight(v)` of `p` to finite vertex `v`.
    pub fn power_distance(&self, v: VertexId, p: Point3) -> f64 {
        (p - self.pt(v.0)).length_squared() - self.kernel_weight(v.0)
    }

    /// Whether the weighted point `(p, w)` conflicts with the live cell `c` (negative power
    /// distance to its perturbed orthogonal sphere; for an infinite cell, beyond its hull facet).
    /// `p` must not be the position of a vertex of `c` with the same weight.
    pub fn is_in_conflict_weighted(&self, c: CellId, p: Point3, w: f64) -> bool {
        self.query_conflict(c, p, w)
    }

    /// The weighted point of finite vertex `v`.
    pub fn weighted_point(&self, v: VertexId) -> WeightedPoint3 {
        WeightedPoint3::new(self.pt(v.0), self.kernel_weight(v.0))
    }

    fn kernel_weight(&self, v: u32) -> f64 {
        use super::ConflictKernel;
        self.kernel.weight(v)
    }
}
