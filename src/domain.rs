//! The domain `delamesh mesh` meshes: piecewise-smooth when the surface has sharp features (so a
//! CAD part keeps its edges and corners), else the smooth polyhedral oracle, exactly as with
//! `--no-features`; or the oracle of a plugin.

use crate::error::Error;
use crate::settings::FeatureSettings;
use delamesh_core::mesh::SurfaceMesh;
use delamesh_core::oracle::Oracle;
use delamesh_core::plugin::DynOracle;
use delamesh_formats::image::Image;
use delamesh_image_label::{ImageLabelOracle, ImageOptions};
use delamesh_piecewise_smooth::{
    FeatureOptions, Features, PiecewiseSmoothOracle, Polyline, read_polylines,
};
use delamesh_polyhedral::{PolyhedralOptions, PolyhedralOracle};
use delamesh_subdivision::{SubdivisionOptions, SubdivisionOracle};

/// A domain ready to mesh, with the oracle that answers for it.
pub enum Domain {
    /// The inside of a closed surface without sharp features (or with feature detection off).
    Smooth(PolyhedralOracle),
    /// The inside of a closed surface whose sharp edges and corners the mesh keeps.
    PiecewiseSmooth(PiecewiseSmoothOracle),
    /// The domain of an oracle plugin loaded through the C ABI.
    Plugin(DynOracle),
    /// The labels of a segmented 3D image (or a gray-level image's side of an isovalue).
    Image(ImageLabelOracle),
    /// The inside of the limit surface of a subdivision control mesh.
    Subdivision(SubdivisionOracle),
    /// Any other oracle: a domain written in Rust and linked in.
    Custom(Box<dyn Oracle>),
}

impl Domain {
    /// The domain bounded by `surface` (`name` says which input it is, in errors): piecewise
    /// smooth when `features` finds sharp features on it, else smooth. A surface that does not
    /// bound a volume as given is repaired and read by its winding number, or refused when
    /// `strict`; a self-intersecting or non-manifold one is meshed as smooth, since curves along
    /// its crossings may lie inside the volume.
    pub fn from_surface(
        name: &str,
        surface: &SurfaceMesh,
        features: &FeatureSettings,
        strict: bool,
    ) -> Result<Domain, Error> {
        let surface_options = PolyhedralOptions { strict };
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
                let oracle = PiecewiseSmoothOracle::with_options(found, &surface_options)
                    .map_err(|e| unmeshable(&e))?;
                let r = oracle.polyhedral().repairs();
                if r.crossing_triangles == 0 && r.non_manifold_edges == 0 {
                    return Ok(Domain::PiecewiseSmooth(oracle));
                }
            }
        }
        let patches = surface.oracle_patches();
        PolyhedralOracle::with_options(
            &surface.positions,
            &surface.triangles,
            Some(&patches),
            &surface_options,
        )
        .map(Domain::Smooth)
        .map_err(|e| unmeshable(&e))
    }

    /// The domain of a 3D image (`name` says which input it is, in errors).
    pub fn from_image(name: &str, image: &Image, options: &ImageOptions) -> Result<Domain, Error> {
        ImageLabelOracle::new(image, options)
            .map(Domain::Image)
            .map_err(|e| Error::Image {
                name: name.to_string(),
                problem: e.to_string(),
            })
    }

    /// The domain inside the limit surface of the control mesh `mesh` (`name` says which input
    /// it is, in errors), with more creases along the control edges of `polylines` (a CGAL
    /// `.polylines.txt` file).
    pub fn from_control_mesh(
        name: &str,
        mesh: &delamesh_formats::PolygonMesh,
        options: &SubdivisionOptions,
        polylines: Option<&std::path::Path>,
    ) -> Result<Domain, Error> {
        let polylines: Vec<Polyline> = match polylines {
            Some(path) => read_polylines(path)?,
            None => Vec::new(),
        };
        SubdivisionOracle::new(mesh, options, &polylines)
            .map(Domain::Subdivision)
            .map_err(|e| Error::Subdivision {
                name: name.to_string(),
                problem: e.to_string(),
            })
    }

    /// The oracle the mesher asks.
    pub fn oracle(&self) -> &dyn Oracle {
        match self {
            Domain::Smooth(o) => o,
            Domain::PiecewiseSmooth(o) => o,
            Domain::Plugin(o) => o,
            Domain::Image(o) => o,
            Domain::Subdivision(o) => o,
            Domain::Custom(o) => o.as_ref(),
        }
    }

    /// The polyhedral oracle underneath a surface domain, for distances and volumes in the
    /// report; `None` for a plugin.
    pub fn polyhedral(&self) -> Option<&PolyhedralOracle> {
        match self {
            Domain::Smooth(o) => Some(o),
            Domain::PiecewiseSmooth(o) => Some(o.polyhedral()),
            Domain::Plugin(_) | Domain::Image(_) | Domain::Subdivision(_) | Domain::Custom(_) => {
                None
            }
        }
    }

    /// What was repaired or reinterpreted in the input surface, one phrase each (empty when it
    /// bounded a volume as given, and for a plugin).
    pub fn repairs(&self) -> Vec<String> {
        self.polyhedral()
            .map_or_else(Vec::new, |o| o.repairs().describe())
    }

    /// A fault a plugin recorded while answering: its answers since then cannot be trusted.
    pub fn check(&self) -> Result<(), Error> {
        match self {
            Domain::Plugin(o) => o.check().map_err(Error::PluginFault),
            _ => Ok(()),
        }
    }
}
