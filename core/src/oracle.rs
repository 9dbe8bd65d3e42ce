//! The `Oracle` trait: everything a mesher may ask of a domain.
//!
//! Rineau's meshers need exactly two questions answered about a smooth domain (thesis, ch. 3): is a
//! point inside, and where does a segment (or a ray) cross the boundary. A plugin answers them for
//! its own representation (triangle soup, subdivision surface, labelled image...). Piecewise-smooth
//! domains add 1D features (curves and corners); they have default empty answers here so that a
//! smooth-only plugin does not have to mention them.

use crate::kernel::Point3;

mod ball;
#[cfg(test)]
mod everywhere;

pub use crate::mesh::Aabb;
pub use ball::{UnitBall, UnitBallWithEquator};
#[cfg(test)]
pub(crate) use everywhere::Everywhere;

// The label types of the whole workspace; the C ABI carries them as raw `u32` and converts at
// the boundary (core/src/plugin).
pub use crate::mesh::{CurveId, PatchId, SubdomainId};

/// The subdomain label of every point outside the domain.
pub const OUTSIDE: SubdomainId = SubdomainId(0);

impl Aabb {
    /// Length of the main diagonal: the scale default criteria are derived from.
    pub fn diagonal(&self) -> f64 {
        (self.max - self.min).length()
    }

    /// The centre of the box.
    pub fn center(&self) -> Point3 {
        0.5 * (self.min + self.max)
    }

    /// Whether `p` is in the closed box.
    pub fn contains(&self, p: Point3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }
}

/// One crossing of a segment or a ray with a boundary surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfaceHit {
    /// Where the query crosses the surface.
    pub point: Point3,
    /// Parameter along the query: `a + t (b - a)` for a segment (t ∈ [0, 1]), `o + t d` for a ray.
    pub t: f64,
    /// The patch crossed.
    pub patch: PatchId,
}

/// A point on a boundary surface, with the patch it lies on (patches are numbered from 1).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SurfacePoint {
    /// The point.
    pub point: Point3,
    /// The patch it lies on.
    pub patch: PatchId,
}

/// A 1D feature (sharp edge, patch border) as a polyline. Used by piecewise-smooth domains.
/// Curves are numbered from 1.
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureCurve {
    /// The curve's label, numbered from 1.
    pub id: CurveId,
    /// The polyline's points in order, ends included.
    pub points: Vec<Point3>,
    /// The last point joins the first.
    pub closed: bool,
}

/// What a mesher may ask of a domain. Object safe: the engine and the C ABI hold `&dyn Oracle`.
pub trait Oracle: Send + Sync {
    /// A box containing the whole domain.
    fn bounding_box(&self) -> Aabb;

    /// The subdomain containing `p`, or [`OUTSIDE`].
    fn subdomain(&self, p: Point3) -> SubdomainId;

    /// Every crossing of the closed segment `[a, b]` with the boundary surfaces, sorted by `t`.
    /// Appends to `out` (which the caller clears) so that hot loops reuse one buffer.
    fn segment_hits(&self, a: Point3, b: Point3, out: &mut Vec<SurfaceHit>);

    /// Every crossing of the ray `origin + t dir` (t ≥ 0) with the boundary surfaces, sorted by `t`.
    fn ray_hits(&self, origin: Point3, dir: Point3, out: &mut Vec<SurfaceHit>);

    /// Points on the boundary, several on every connected component, so that the restricted
    /// Delaunay triangulation of these points has facets on every component (P0 in the thesis).
    fn initial_points(&self) -> Vec<SurfacePoint>;

    /// 1D features the mesh must follow. Smooth domains have none.
    fn feature_curves(&self) -> Vec<FeatureCurve> {
        Vec::new()
    }

    /// The point of feature curve `curve` nearest to `p`, a point of its polyline or near it:
    /// where the mesher puts a vertex on a curve (protecting ball centres, the optimiser's moves
    /// along it), so a domain whose polylines sample a smooth curve (a subdivision crease) gets
    /// its vertices on the curve itself. The default keeps `p`: for polyhedral and image domains
    /// the polyline is the curve. Plugins loaded through the C ABI answer with the default
    /// (version 1 of the table has no entry for it; see PLUGINS.md).
    fn project_to_curve(&self, curve: CurveId, p: Point3) -> Point3 {
        let _ = curve;
        p
    }

    /// 0D features (corners) the mesh must contain as vertices. Smooth domains have none.
    fn corners(&self) -> Vec<Point3> {
        Vec::new()
    }

    /// The first crossing of `[a, b]` with the boundary, if any.
    fn first_segment_hit(&self, a: Point3, b: Point3) -> Option<SurfaceHit> {
        let mut hits = Vec::new();
        self.segment_hits(a, b, &mut hits);
        hits.first().copied()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aabb_of_points_contains_them() {
        let pts = [
            Point3::new(1.0, -2.0, 3.0),
            Point3::new(-1.0, 4.0, 0.5),
            Point3::ZERO,
        ];
        let b = Aabb::of(&pts).expect("non-empty");
        assert!(pts.iter().all(|&p| b.contains(p)));
        assert_eq!(b.min, Point3::new(-1.0, -2.0, 0.0));
        assert_eq!(b.max, Point3::new(1.0, 4.0, 3.0));
        assert!(Aabb::of(&[]).is_none());
    }

    #[test]
    fn oracle_is_object_safe_and_shareable() {
        fn assert_send_sync<T: Send + Sync + ?Sized>() {}
        assert_send_sync::<dyn Oracle>();
    }
}
