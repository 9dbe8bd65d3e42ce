//! A test domain with every point inside: for tests whose labels or surface come from elsewhere.

use super::{Aabb, Oracle, SubdomainId, SurfaceHit, SurfacePoint};
use crate::kernel::Point3;

/// Every point in subdomain 1 and no surface; `0` is the box it reports.
pub(crate) struct Everywhere(pub(crate) Aabb);

impl Oracle for Everywhere {
    fn bounding_box(&self) -> Aabb {
        self.0
    }
    fn subdomain(&self, _p: Point3) -> SubdomainId {
        SubdomainId(1)
    }
    fn segment_hits(&self, _a: Point3, _b: Point3, out: &mut Vec<SurfaceHit>) {
        out.clear();
    }
    fn ray_hits(&self, _o: Point3, _d: Point3, out: &mut Vec<SurfaceHit>) {
        out.clear();
    }
    fn initial_points(&self) -> Vec<SurfacePoint> {
        Vec::new()
    }
}
