//! The domain `delamesh mesh` meshes: piecewise-smooth when the surface has sharp features (so a
//! CAD part keeps its edges and corners), else the smooth polyhedral oracle, exactly as with
//! `--no-features`.

use anyhow::{Context, Result, anyhow};
use delamesh_core::mesh::SurfaceMesh;
use delamesh_core::oracle::{Oracle, PatchId};
use delamesh_piecewise_smooth::{
    FeatureOptions, Features, PiecewiseSmoothOracle, Polyline, read_polylines,
};
use delamesh_polyhedral::{PolyhedralOptions, PolyhedralOracle};
use std::path::Path;

/// How `mesh` looks for features.
pub(crate) struct FeatureArgs<'a> {
    pub enabled: bool,
    pub angle_deg: f64,
    pub polylines: Option<&'a Path>,
}

/// How `mesh` treats a surface that does not bound a volume as given.
pub(crate) struct SurfaceArgs {
    /// Refuse it with its first defect (else it is repaired and read by its winding number).
    pub strict: bool,
}

pub(crate) enum Domain {
    Smooth(PolyhedralOracle),
    PiecewiseSmooth(PiecewiseSmoothOracle),
}

impl Domain {
    pub fn new(
        input: &Path,
        surface: &SurfaceMesh,
        features: &FeatureArgs,
        surface_args: &SurfaceArgs,
    ) -> Result<Domain> {
        let options = PolyhedralOptions {
            strict: surface_args.strict,
        };
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
            let feature_options = FeatureOptions {
                angle_deg: features.angle_deg,
            };
            let found = Features::extract(surface, &feature_options, &polylines)
                .map_err(|e| unmeshable(&e))
                .with_context(|| match features.polylines {
                    Some(p) => format!("features of {} with {}", input.display(), p.display()),
                    None => format!("features of {}", input.display()),
                })?;
            if !found.is_smooth() {
                let oracle = PiecewiseSmoothOracle::with_options(found, &options)
                    .map_err(|e| unmeshable(&e))?;
                // Curves along crossings and non-manifold edges may lie inside the volume, where
                // protecting them never ends: such a surface is meshed as smooth.
                let r = oracle.polyhedral().repairs();
                if r.crossing_triangles == 0 && r.non_manifold_edges == 0 {
                    return Ok(Domain::PiecewiseSmooth(oracle));
                }
                eprintln!(
                    "warning: {}: self-intersecting or non-manifold: meshed without sharp features",
                    input.display()
                );
            }
        }
        // The oracle numbers patches from 1 (0 marks facets of no patch in the output).
        let patches: Vec<PatchId> = surface.patches.iter().map(|p| p.0 + 1).collect();
        PolyhedralOracle::with_options(
            &surface.positions,
            &surface.triangles,
            Some(&patches),
            &options,
        )
        .map(Domain::Smooth)
            .map_err(|e| unmeshable(&e))
    }

    pub fn oracle(&self) -> &dyn Oracle {
        match self {
            Domain::Smooth(o) => o,
            Domain::PiecewiseSmooth(o) => o,
        }
    }

    /// What was repaired in the input, one phrase each (empty for a surface that bounds a volume
    /// as given).
    pub fn repairs(&self) -> Vec<String> {
        self.polyhedral().repairs().describe()
    }

    /// The polyhedral oracle underneath, for distances and volumes in the report.
    pub fn polyhedral(&self) -> &PolyhedralOracle {
        match self {
            Domain::Smooth(o) => o,
            Domain::PiecewiseSmooth(o) => o.polyhedral(),
        }
    }
}
