//! The sizing flags of `delamesh mesh`, mapped to the library's [`SizingSettings`].

use anyhow::Result;
use delamesh::{SizeSource, SizingSettings};
use std::collections::BTreeMap;
use std::path::PathBuf;

/// Sizes that vary in space.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct SizingArgs {
    /// Size of facets and cells (and the edge size along features) from a file: a background
    /// tet mesh with a point field (.vtu .vtk), a 3D image of sizes (.inr .nii .vti .nrrd .nhdr),
    /// or `x y z h` lines (.xyz .pts .txt). Replaces the default sizes; --facet-size,
    /// --cell-size, --edge-size given as well cap it.
    #[arg(long, value_name = "FILE", conflicts_with = "sizing_expr")]
    pub sizing: Option<PathBuf>,
    /// The point field of the --sizing background mesh (default: its only scalar point field).
    #[arg(long, value_name = "NAME", requires = "sizing")]
    pub sizing_field: Option<String>,
    /// Size of facets and cells (and edges along features) as an expression of x, y, z, e.g.
    /// "0.02 + 0.1 * abs(z)" (operators + - * / ^, functions abs sqrt min max exp ln sin cos...).
    #[arg(long, value_name = "EXPR")]
    pub sizing_expr: Option<String>,
    /// Largest tetrahedron circumradius per subdomain, e.g. `1=0.05,2=0.2` (others: the cell
    /// size or the field).
    #[arg(long, value_name = "S=SIZE,...")]
    pub size_per_subdomain: Option<String>,
    /// Largest surface Delaunay ball radius per surface patch (the output's `patch` ids), e.g.
    /// `1=0.02,3=0.1`.
    #[arg(long, value_name = "P=SIZE,...")]
    pub size_per_patch: Option<String>,
    /// Largest growth of the size per unit length (|grad h| <= G, e.g. 0.3): transitions away
    /// from small sizes stay smooth. Graded on a 64^3 grid over the domain.
    #[arg(long, value_name = "G", allow_negative_numbers = true)]
    pub size_gradation: Option<f64>,
    /// Facet distance bound from a file (the formats of --sizing).
    #[arg(long, value_name = "FILE", conflicts_with = "distance_expr")]
    pub distance_field: Option<PathBuf>,
    /// Facet distance bound as an expression of x, y, z.
    #[arg(long, value_name = "EXPR")]
    pub distance_expr: Option<String>,
}

impl SizingArgs {
    /// The library's sizing settings for these flags.
    pub fn settings(&self) -> Result<SizingSettings> {
        let labels = |option: &str, spec: &Option<String>| match spec {
            Some(spec) => crate::cli::image::per_label(option, spec),
            None => Ok(BTreeMap::new()),
        };
        let source = |file: &Option<PathBuf>, field: &Option<String>, expr: &Option<String>| match (
            file, expr,
        ) {
            (Some(path), _) => Some(SizeSource::File {
                path: path.clone(),
                field: field.clone(),
            }),
            (None, Some(e)) => Some(SizeSource::Expression(e.clone())),
            (None, None) => None,
        };
        Ok(SizingSettings {
            field: source(&self.sizing, &self.sizing_field, &self.sizing_expr),
            per_subdomain: labels("size-per-subdomain", &self.size_per_subdomain)?,
            per_patch: labels("size-per-patch", &self.size_per_patch)?,
            gradation: self.size_gradation,
            distance: source(&self.distance_field, &None, &self.distance_expr),
        })
    }
}
