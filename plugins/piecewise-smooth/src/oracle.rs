//! `PiecewiseSmoothOracle`: the polyhedral oracle with the surface cut into patches by its sharp
//! features, and the features themselves.

use crate::features::{FeatureError, FeatureOptions, Features};
use crate::interface::separate_components;
use crate::polylines::Polyline;
use delamesh_core::mesh::SurfaceMesh;
use delamesh_core::oracle::{Aabb, FeatureCurve, Oracle, SubdomainId, SurfaceHit, SurfacePoint};
use delamesh_polyhedral::{PolyhedralError, PolyhedralOptions, PolyhedralOracle};
use glam::DVec3;

/// Why a piecewise-smooth domain cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum PiecewiseSmoothError {
    #[error(transparent)]
    Features(#[from] FeatureError),
    #[error(transparent)]
    Surface(#[from] PolyhedralError),
}

/// A domain bounded by closed triangle surfaces whose sharp edges and corners are features.
/// Surface queries are the polyhedral oracle's; their patch ids are [`Features::triangle_patches`].
pub struct PiecewiseSmoothOracle {
    surface: PolyhedralOracle,
    features: Features,
}

impl PiecewiseSmoothOracle {
    /// Extracts the features of `surface` and builds the oracle.
    pub fn from_surface(
        surface: &SurfaceMesh,
        options: &FeatureOptions,
        polylines: &[Polyline],
    ) -> Result<Self, PiecewiseSmoothError> {
        Ok(Self::new(Features::extract(surface, options, polylines)?)?)
    }

    /// The oracle of the surface the features were extracted from.
    pub fn new(features: Features) -> Result<Self, PolyhedralError> {
        Self::with_options(features, &PolyhedralOptions::default())
    }

    /// [`PiecewiseSmoothOracle::new`] with the polyhedral oracle's options (`strict`).
    pub fn with_options(
        features: Features,
        options: &PolyhedralOptions,
    ) -> Result<Self, PolyhedralError> {
        let (positions, triangles) = separate_components(&features);
        let surface = PolyhedralOracle::with_options(
            &positions,
            &triangles,
            Some(&features.triangle_patches),
            options,
        )?;
        Ok(PiecewiseSmoothOracle { surface, features })
    }

    /// The detected curves, corners and patches.
    pub fn features(&self) -> &Features {
        &self.features
    }

    /// The underlying smooth oracle (distance to the surface, volume, input triangles).
    pub fn polyhedral(&self) -> &PolyhedralOracle {
        &self.surface
    }
}

impl Oracle for PiecewiseSmoothOracle {
    fn bounding_box(&self) -> Aabb {
        self.surface.bounding_box()
    }

    fn subdomain(&self, p: DVec3) -> SubdomainId {
        self.surface.subdomain(p)
    }

    fn segment_hits(&self, a: DVec3, b: DVec3, out: &mut Vec<SurfaceHit>) {
        self.surface.segment_hits(a, b, out);
    }

    fn ray_hits(&self, origin: DVec3, dir: DVec3, out: &mut Vec<SurfaceHit>) {
        self.surface.ray_hits(origin, dir, out);
    }

    fn initial_points(&self) -> Vec<SurfacePoint> {
        self.surface.initial_points()
    }

    fn feature_curves(&self) -> Vec<FeatureCurve> {
        self.features.feature_curves()
    }

    fn corners(&self) -> Vec<DVec3> {
        self.features.corners.iter().map(|c| c.point).collect()
    }
}
