//! The domain `delamesh mesh` meshes: piecewise-smooth when the surface has sharp features (so a
//! CAD part keeps its edges and corners), else the smooth polyhedral oracle, exactly as with
//! `--no-features`; or the oracle of a plugin.

use crate::error::Error;
use crate::settings::FeatureSettings;
use delamesh_core::mesh::SurfaceMesh;
use delamesh_core::oracle::{Oracle, PatchId};
use delamesh_core::plugin::DynOracle;
use delamesh_piecewise_smooth::{
    FeatureOptions, Features, PiecewiseSmoothOracle, Polyline, read_polylines,
};
use delamesh_polyhedral::PolyhedralOracle;

/// A domain ready to mesh, with the oracle that answers for it.
pub enum Domain {
    /// The inside of a closed surface without sharp features (or with feature detection off).
    Smooth(PolyhedralOracle),
    /// The inside of a closed surface whose sharp edges and corners the mesh keeps.
    PiecewiseSmooth(PiecewiseSmoothOracle),
    /// The domain of an oracle plugin loaded through the C ABI.
    Plugin(DynOracle),
}

impl Domain {
    /// The domain bounded by `surface` (`name` says which input it is, in errors): piecewise
    /// smooth when `features` finds sharp features on it, else smooth.
    pub fn from_surface(
        name: &str,
        surface: &SurfaceMesh,
        features: &FeatureSettings,
    ) -> Result<Domain, Error> {
        let unmeshable = |e: &dyn std::fmt::Display| Error::Unmeshable {
            name: name.to_string(),
            problem: e.to_string(),
        };
        if features.enabled {
            let polylines: Vec<Polyline> = match &features.polylines {
                Some(path) => read_polylines(path)?,
                None => Vec::new(),
            };
            let options = FeatureOptions {
                angle_deg: features.angle_deg,
            };
            let found = Features::extract(surface, &options, &polylines).map_err(|e| {
                match &features.polylines {
                    Some(path) => Error::FeaturePolylines {
                        name: name.to_string(),
                        polylines: path.clone(),
                        problem: e.to_string(),
                    },
                    None => unmeshable(&e),
                }
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

    /// The domain of the plugin `spec` (a library path, or a name looked up in
    /// [`PLUGIN_PATH_VAR`](crate::plugins::PLUGIN_PATH_VAR)), created from `config` and
    /// self-checked.
    pub fn from_plugin(spec: &str, config: &str) -> Result<Domain, Error> {
        crate::plugins::load_oracle(spec, config).map(Domain::Plugin)
    }

    /// The oracle the mesher asks.
    pub fn oracle(&self) -> &dyn Oracle {
        match self {
            Domain::Smooth(o) => o,
            Domain::PiecewiseSmooth(o) => o,
            Domain::Plugin(o) => o,
        }
    }

    /// The polyhedral oracle underneath a surface domain, for distances and volumes in the
    /// report; `None` for a plugin.
    pub fn polyhedral(&self) -> Option<&PolyhedralOracle> {
        match self {
            Domain::Smooth(o) => Some(o),
            Domain::PiecewiseSmooth(o) => Some(o.polyhedral()),
            Domain::Plugin(_) => None,
        }
    }

    /// A fault a plugin recorded while answering: its answers since then cannot be trusted.
    pub fn check(&self) -> Result<(), Error> {
        match self {
            Domain::Plugin(o) => o.check().map_err(Error::PluginFault),
            _ => Ok(()),
        }
    }
}
