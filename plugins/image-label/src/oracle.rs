//! `ImageLabelOracle`: the `Oracle` answers of a labelled image, in world coordinates.

use crate::labels::{Classified, Field, classify_isovalue, classify_labels};
use crate::walk::{Change, changes};
use crate::{ImageLabelError, ImageOptions, features, initial};
use delamesh_core::oracle::{
    Aabb, CurveId, FeatureCurve, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use delamesh_core::refine::criteria::{MeshCriteria, Sizing};
use delamesh_formats::image::Image;
use glam::{DAffine3, DVec3};

/// Runs `$body` with `$g` bound to the class grid, whatever its class type.
macro_rules! with_grid {
    ($field:expr, $g:ident => $body:expr) => {
        match $field {
            Field::U8($g) => $body,
            Field::U16($g) => $body,
        }
    };
}

/// A domain whose subdomains are the labels of a 3D image.
pub struct ImageLabelOracle {
    field: Field,
    /// Subdomain of each class; class 0 (background) is `OUTSIDE`.
    subdomains: Vec<SubdomainId>,
    to_world: DAffine3,
    to_index: DAffine3,
    bbox: Aabb,
    initial: Vec<SurfacePoint>,
    /// Triple lines and curves on the image border, in world coordinates.
    curves: Vec<FeatureCurve>,
    corners: Vec<DVec3>,
}

impl ImageLabelOracle {
    /// The domain of `image`: its labels (or the isovalue of its gray levels) as `options` say.
    pub fn new(image: &Image, options: &ImageOptions) -> Result<Self, ImageLabelError> {
        image
            .validate()
            .map_err(|e| ImageLabelError::Image(e.to_string()))?;
        let Classified {
            field,
            subdomains,
            offset,
        } = match options.isovalue {
            Some(v) if !v.is_finite() => return Err(ImageLabelError::BadIsovalue(v)),
            Some(v) => classify_isovalue(image, v, options.interpolation),
            None => classify_labels(image, options.background, options.interpolation)?,
        };
        let to_world = image.index_to_world
            * DAffine3::from_translation(DVec3::from_array(offset.map(|o| o as f64)));
        let to_index = to_world.inverse();
        let index_box = with_grid!(&field, g => initial::occupied_box(g))
            .ok_or(ImageLabelError::Empty(options.background))?;
        let bbox = world_box(&to_world, index_box);
        let mut oracle = ImageLabelOracle {
            field,
            subdomains,
            to_world,
            to_index,
            bbox,
            initial: Vec::new(),
            curves: Vec::new(),
            corners: Vec::new(),
        };
        let initial = with_grid!(&oracle.field, g => initial::initial_points(g));
        oracle.initial = initial
            .into_iter()
            .map(|(q, c0, c1)| SurfacePoint {
                point: oracle.world(q),
                patch: patch(c0, c1),
            })
            .collect();
        if oracle.initial.is_empty() {
            return Err(ImageLabelError::Empty(options.background));
        }
        if options.features {
            let found = with_grid!(&oracle.field, g => features::detect(g));
            oracle.set_features(found);
        }
        Ok(oracle)
    }

    /// The detected curves in world coordinates, simplified to within half a voxel: their
    /// points are crossings of the voxel grid, and every bend of a feature curve is a protecting
    /// ball's centre, so a bend per voxel would make balls (and the mesh) as fine as the voxels.
    fn set_features(&mut self, found: features::Features) {
        let m = self.to_world.matrix3;
        let voxel = m
            .x_axis
            .length()
            .max(m.y_axis.length())
            .max(m.z_axis.length());
        let tolerance = 0.5 * voxel;
        for (points, closed) in found.curves {
            let mut points: Vec<DVec3> = points.iter().map(|&q| self.world(q)).collect();
            points.dedup();
            if closed && points.len() > 1 && points.first() == points.last() {
                points.pop();
            }
            let points = features::simplify(&points, closed, tolerance);
            // A loop smaller than the tolerance is no curve to follow.
            if points.len() < 2 + usize::from(closed) {
                continue;
            }
            self.curves.push(FeatureCurve {
                id: CurveId(self.curves.len() as u32 + 1),
                points,
                closed,
            });
        }
        self.corners = found.corners.iter().map(|&q| self.world(q)).collect();
    }

    fn world(&self, q: DVec3) -> DVec3 {
        self.to_world.transform_point3(q)
    }

    /// The two subdomains (labels) an interface patch separates, the smaller first.
    pub fn patch_subdomains(&self, patch: PatchId) -> Option<[SubdomainId; 2]> {
        let [c0, c1] = classes_of_patch(patch)?;
        let s = |c: u32| self.subdomains.get(c as usize).copied();
        let (a, b) = (s(c0)?, s(c1)?);
        Some([a.min(b), a.max(b)])
    }

    /// The subdomains of the image (its labels other than the background), sorted.
    pub fn subdomains(&self) -> Vec<SubdomainId> {
        let mut s: Vec<SubdomainId> = self.subdomains[1..].to_vec();
        s.sort_unstable();
        s
    }

    /// Criteria for a medium-resolution mesh of the image: the bounding-box defaults, with a
    /// facet distance no finer than the voxels (finer would chase the voxel staircase) and no
    /// protecting ball below two voxels (closer than that, feature curves are the segmentation's
    /// noise, and balls that small would refine the mesh down to it; less in a tiny image).
    pub fn default_criteria(&self) -> MeshCriteria {
        let mut c = MeshCriteria::default_for(&self.bbox);
        let m = self.to_world.matrix3;
        let lengths = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
        let voxel = lengths.iter().fold(f64::INFINITY, |a, &b| a.min(b));
        let distance = c.facet.distance.at(self.bbox.center(), 1).max(voxel);
        c.facet.distance = Sizing::Constant(distance);
        let largest = lengths.iter().fold(0.0, |a: f64, &b| a.max(b));
        let dims = with_grid!(&self.field, g => g.dims);
        c.edge_min_size = features::short(dims) * largest;
        c
    }

    /// The changes of class along the world segment `[a, b]`.
    fn changes(&self, a: DVec3, b: DVec3, out: &mut Vec<Change>) {
        let (qa, qb) = (
            self.to_index.transform_point3(a),
            self.to_index.transform_point3(b),
        );
        with_grid!(&self.field, g => changes(g, qa, qb, out));
    }

    /// The class changes along `[a, b]` as surface hits, where `b = a + scale * d`: at parameter
    /// `t` in units of `d` (`scale` 1 for a segment, its length along the ray for a ray).
    fn hits(&self, a: DVec3, b: DVec3, d: DVec3, scale: f64, out: &mut Vec<SurfaceHit>) {
        let mut found = Vec::new();
        self.changes(a, b, &mut found);
        out.extend(found.into_iter().map(|c| SurfaceHit {
            point: a + (c.t * scale) * d,
            t: c.t * scale,
            patch: patch(c.from, c.to),
        }));
    }
}

/// The patch of the interface between classes `c0` and `c1` (unordered): pairs numbered from 1.
pub(crate) fn patch(c0: u32, c1: u32) -> PatchId {
    let (i, j) = (u64::from(c0.min(c1)), u64::from(c0.max(c1)));
    // At most MAX_LABELS + 1 classes, so the pair number fits a u32.
    PatchId((j * (j - 1) / 2 + i + 1) as u32)
}

/// The classes `[i, j]` (i < j) of a patch.
fn classes_of_patch(patch: PatchId) -> Option<[u32; 2]> {
    let p = u64::from(patch.0.checked_sub(1)?);
    // The largest j with j (j - 1) / 2 ≤ p.
    let mut j = ((1.0 + (1.0 + 8.0 * p as f64).sqrt()) / 2.0) as u64;
    while j * (j.saturating_sub(1)) / 2 > p {
        j -= 1;
    }
    while (j + 1) * j / 2 <= p {
        j += 1;
    }
    let i = p - j * (j - 1) / 2;
    Some([i as u32, j as u32])
}

/// The world box of an index-space box (the image may be oblique: all eight corners).
fn world_box(to_world: &DAffine3, (lo, hi): (DVec3, DVec3)) -> Aabb {
    let corners: Vec<DVec3> = (0..8)
        .map(|k| {
            let pick = |bit: usize, a: f64, b: f64| if k & bit == 0 { a } else { b };
            to_world.transform_point3(DVec3::new(
                pick(1, lo.x, hi.x),
                pick(2, lo.y, hi.y),
                pick(4, lo.z, hi.z),
            ))
        })
        .collect();
    let min = corners.iter().fold(DVec3::INFINITY, |m, &c| m.min(c));
    let max = corners.iter().fold(DVec3::NEG_INFINITY, |m, &c| m.max(c));
    Aabb { min, max }
}

impl Oracle for ImageLabelOracle {
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    fn subdomain(&self, p: DVec3) -> SubdomainId {
        let q = self.to_index.transform_point3(p);
        let class = with_grid!(&self.field, g => g.class_at(q));
        self.subdomains[class as usize]
    }

    fn segment_hits(&self, a: DVec3, b: DVec3, out: &mut Vec<SurfaceHit>) {
        self.hits(a, b, b - a, 1.0, out);
    }

    fn ray_hits(&self, origin: DVec3, dir: DVec3, out: &mut Vec<SurfaceHit>) {
        // Nothing lies beyond the bounding box: the ray is the segment to its far side.
        let far = ((self.bbox.max - self.bbox.min).length()
            + (origin - self.bbox.center()).length())
            / dir.length();
        if !far.is_finite() || far <= 0.0 {
            return;
        }
        self.hits(origin, origin + far * dir, dir, far, out);
    }

    fn initial_points(&self) -> Vec<SurfacePoint> {
        self.initial.clone()
    }

    fn feature_curves(&self) -> Vec<FeatureCurve> {
        self.curves.clone()
    }

    fn corners(&self) -> Vec<DVec3> {
        self.corners.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn patches_number_the_pairs_of_classes_one_to_one() {
        let mut seen = std::collections::BTreeSet::new();
        for j in 1..60u32 {
            for i in 0..j {
                let p = patch(i, j);
                assert_eq!(patch(j, i), p);
                assert!(p.0 >= 1 && seen.insert(p));
                assert_eq!(classes_of_patch(p), Some([i, j]));
            }
        }
        assert_eq!(classes_of_patch(PatchId(0)), None);
        let big = crate::MAX_LABELS as u32;
        assert_eq!(classes_of_patch(patch(big - 1, big)), Some([big - 1, big]));
    }
}
