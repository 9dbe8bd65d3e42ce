//! The domain `delamesh mesh` meshes: piecewise-smooth when the surface has sharp features (so a
//! CAD part keeps its edges and corners), else the smooth polyhedral oracle, exactly as with
//! `--no-features`.

use anyhow::{Context, Result, anyhow};
use delamesh_core::mesh::SurfaceMesh;
use delamesh_core::oracle::{Oracle, PatchId};
use delamesh_piecewise_smooth::{
    FeatureOptions, Features, PiecewiseSmoothOracle, Polyline, read_polylines,
};
use delamesh_polyhedral::PolyhedralOracle;
use std::path::Path;

/// How `mesh` looks for features.
pub(crate) struct FeatureArgs<'a> {
    pub enabled: bool,
    pub angle_deg: f64,
    pub polylines: Option<&'a Path>,
}

pub(crate) enum Domain {
    Smooth(PolyhedralOracle),
    PiecewiseSmooth(PiecewiseSmoothOracle),
}

impl Domain {
    pub fn new(input: &Path, surface: &SurfaceMesh, features: &FeatureArgs) -> Result<Domain> {
        let unmeshable = |e: &dyn std::fmt::Display| {
            anyhow!(
                "{}: cannot mesh this surface: {e}\n(run `delamesh info {}` for a full diagnosis)",
                input.display(),
                input.display()
            )
        };
        if features.enabled {
            let polylines: Vec<Polyline> = match features.polylines {
                Some(path) => read_polylines(path)?,
                None => Vec::new(),
            };
            let options = FeatureOptions {
                angle_deg: features.angle_deg,
            };
            let found = Features::extract(surface, &options, &polylines)
                .map_err(|e| unmeshable(&e))
                .with_context(|| match features.polylines {
                    Some(p) => format!("features of {} with {}", input.display(), p.display()),
                    None => format!("features of {}", input.display()),
                })?;
            if !found.is_smooth() {
                let oracle = PiecewiseSmoothOracle::new(found).map_err(|e| unmeshable(&e))?;
                return Ok(Domain::PiecewiseSmooth(oracle));
            }
        }
        // The oracle numbers patches from 1 (0 marks facets of no patch in the output).
        let patches: Vec<PatchId> = surface.patches.iter().map(|p| p.0 + 1).collect();
        PolyhedralOracle::new(&surface.positions, &surface.triangles, Some(&patches))
            .map(Domain::Smooth)
            .map_err(|e| unmeshable(&e))
    }

    pub fn oracle(&self) -> &dyn Oracle {
        match self {
            Domain::Smooth(o) => o,
            Domain::PiecewiseSmooth(o) => o,
        }
    }

    /// The polyhedral oracle underneath, for distances and volumes in the report.
    pub fn polyhedral(&self) -> &PolyhedralOracle {
        match self {
            Domain::Smooth(o) => o,
            Domain::PiecewiseSmooth(o) => o.polyhedral(),
        }
    }
}
