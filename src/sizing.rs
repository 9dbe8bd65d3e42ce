//! Sizing fields users bring to `delamesh mesh`: where a field comes from (a file, an expression,
//! a closure, arrays), how it is loaded and checked, and how the fields, per-subdomain and
//! per-patch sizes and the gradation combine into the criteria's sizes.
//!
//! Combination rule: a field replaces the default sizes; a size given as a number as well
//! (`--cell-size`, `--facet-size`, `--edge-size`, `--facet-distance`) caps it. Per-subdomain sizes
//! replace the cell size in their subdomains, per-patch sizes the facet size on their patches
//! (a field still caps both). With a gradation, the cell size is graded on a grid over the domain
//! (see [`delamesh_core::refine::sizing::graded`]), seeded with the protecting balls of the
//! sharp features as well, and every size is kept under the graded one, so edges and facets
//! follow the same smooth transitions.

use delamesh_core::Oracle;
use delamesh_core::kernel::Point3;
use delamesh_core::oracle::{Aabb, OUTSIDE};
use delamesh_core::refine::criteria::Sizing;
use delamesh_core::refine::sizing::{
    BackgroundMesh, Checked, DEFAULT_GRADATION_NODES, Graded, PointSizes, SizeGrid, SizingField,
    feature_sizes, graded,
};
use delamesh_formats::image::{is_image_path, read_image};
use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// Where a sizing field comes from.
#[derive(Clone)]
pub enum SizeSource {
    /// A file: a background tetrahedral mesh with a point field (`.vtu`, `.vtk`; `field` names
    /// it, default the only one), a 3D image of sizes (`.inr`, `.nii`, `.vti`, `.nrrd`, `.nhdr`,
    /// trilinear between voxel centres) or sizes at points (`.xyz`, `.pts`, `.txt` lines
    /// `x y z h`, inverse-distance weighted over the nearest).
    File {
        /// The file.
        path: PathBuf,
        /// The point field of a background mesh.
        field: Option<String>,
    },
    /// An expression of `x`, `y` and `z` (the `exmex` crate's syntax: `+ - * / ^`, `abs`,
    /// `sqrt`, `min`, `max`, `exp`, `sin`...), e.g. `0.02 + 0.1 * abs(z)`.
    Expression(String),
    /// A field in memory: a closure ([`SizeSource::function`]), or arrays through
    /// [`PointSizes`] or [`SizeGrid`].
    Field(Arc<dyn SizingField>),
    /// A background mesh in memory ([`SizeSource::background`]): checked to cover the domain
    /// as one read from a file is.
    Mesh(Arc<BackgroundMesh>),
}

impl SizeSource {
    /// A field from a closure of the point. A value that is not a positive number stops the
    /// run with an error naming the point.
    pub fn function(f: impl Fn(Point3) -> f64 + Send + Sync + 'static) -> Self {
        SizeSource::Field(Arc::new(move |p: Point3, _: u32| f(p)))
    }

    /// A background tet mesh with a size at every node (see [`BackgroundMesh::new`] for what
    /// is refused).
    pub fn background(
        positions: Vec<Point3>,
        tets: Vec<[u32; 4]>,
        values: Vec<f64>,
    ) -> Result<Self, delamesh_core::refine::sizing::SizingError> {
        BackgroundMesh::new(positions, tets, values).map(|m| SizeSource::Mesh(Arc::new(m)))
    }

    /// A file source (see [`SizeSource::File`]).
    pub fn file(path: impl Into<PathBuf>) -> Self {
        SizeSource::File {
            path: path.into(),
            field: None,
        }
    }

    /// How errors name this source.
    fn describe(&self, option: &str) -> String {
        match self {
            SizeSource::File { path, .. } => path.display().to_string(),
            SizeSource::Expression(e) => format!("--{option}-expr {e:?}"),
            SizeSource::Field(_) | SizeSource::Mesh(_) => format!("the {option} field"),
        }
    }
}

impl PartialEq for SizeSource {
    fn eq(&self, other: &Self) -> bool {
        match (self, other) {
            (
                SizeSource::File { path, field },
                SizeSource::File {
                    path: p2,
                    field: f2,
                },
            ) => path == p2 && field == f2,
            (SizeSource::Expression(a), SizeSource::Expression(b)) => a == b,
            (SizeSource::Field(a), SizeSource::Field(b)) => {
                std::ptr::addr_eq(Arc::as_ptr(a), Arc::as_ptr(b))
            }
            (SizeSource::Mesh(a), SizeSource::Mesh(b)) => Arc::ptr_eq(a, b),
            _ => false,
        }
    }
}

impl fmt::Debug for SizeSource {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SizeSource::File { path, field } => write!(f, "File({}, {field:?})", path.display()),
            SizeSource::Expression(e) => write!(f, "Expression({e:?})"),
            SizeSource::Field(_) => write!(f, "Field"),
            SizeSource::Mesh(_) => write!(f, "Mesh"),
        }
    }
}

/// The sizing options of `delamesh mesh` beyond constant sizes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SizingSettings {
    /// The size of facets (surface Delaunay ball radius) and cells (circumradius), and the edge
    /// size along sharp features (`--sizing FILE`, `--sizing-expr`).
    pub field: Option<SizeSource>,
    /// Cell size per subdomain (`--size-per-subdomain 1=0.05,2=0.2`).
    pub per_subdomain: BTreeMap<u32, f64>,
    /// Facet size per surface patch, as numbered in the output's `patch` data
    /// (`--size-per-patch`).
    pub per_patch: BTreeMap<u32, f64>,
    /// Largest growth of the size per unit length, |∇h| ≤ G (`--size-gradation`).
    pub gradation: Option<f64>,
    /// The facet distance bound as a field (`--distance-field FILE`).
    pub distance: Option<SizeSource>,
}

/// A sizing field that could not be loaded or was not met: names the file or option.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("{source_name}: {problem}")]
pub struct SizingFieldError {
    /// The file, expression or option.
    pub source_name: String,
    /// What is wrong, with the value and where.
    pub problem: String,
}

/// A loaded field: checked on every evaluation, and the background mesh, if any, for the check
/// that it covers the domain.
#[derive(Clone)]
pub(crate) struct Loaded {
    name: String,
    field: Arc<Checked>,
    background: Option<Arc<BackgroundMesh>>,
}

impl Loaded {
    fn sizing(&self) -> Sizing {
        Sizing::Field(self.field.clone())
    }
}

/// An expression of x, y, z.
struct Expression {
    expr: exmex::FlatEx<f64>,
    /// For each variable of the expression (alphabetical, as exmex orders them): the axis.
    axes: Vec<usize>,
}

impl SizingField for Expression {
    fn size_at(&self, p: Point3, _label: u32) -> f64 {
        use exmex::Express;
        let mut vars = [0.0; 3];
        for (v, &axis) in vars.iter_mut().zip(&self.axes) {
            *v = p[axis];
        }
        self.expr.eval(&vars[..self.axes.len()]).unwrap_or(f64::NAN)
    }
}

fn parse_expression(text: &str) -> Result<Expression, String> {
    use exmex::Express;
    let expr = exmex::parse::<f64>(text).map_err(|e| format!("not an expression: {e}"))?;
    let mut axes = Vec::new();
    for name in expr.var_names() {
        match name.as_str() {
            "x" => axes.push(0),
            "y" => axes.push(1),
            "z" => axes.push(2),
            other => {
                return Err(format!(
                    "unknown variable {other:?}: an expression may use x, y and z"
                ));
            }
        }
    }
    Ok(Expression { expr, axes })
}

/// Checks that `text` parses as an expression of x, y and z.
pub(crate) fn check_expression(text: &str) -> Result<(), String> {
    parse_expression(text).map(|_| ())
}

/// Loads `source` (`option` names it in errors: `sizing`, `distance`).
pub(crate) fn load(source: &SizeSource, option: &str) -> Result<Loaded, SizingFieldError> {
    let name = source.describe(option);
    let fail = |problem: String| SizingFieldError {
        source_name: name.clone(),
        problem,
    };
    let mut background = None;
    let field: Arc<dyn SizingField> = match source {
        SizeSource::Field(f) => f.clone(),
        SizeSource::Mesh(mesh) => {
            background = Some(mesh.clone());
            mesh.clone()
        }
        SizeSource::Expression(text) => Arc::new(parse_expression(text).map_err(fail)?),
        SizeSource::File { path, field } => {
            let strip = |e: delamesh_formats::Error| {
                // The file's name comes first already; keep only the problem.
                let text = e.to_string();
                let prefix = format!("{}: ", path.display());
                text.strip_prefix(&prefix).unwrap_or(&text).to_string()
            };
            if is_image_path(path) {
                let image = read_image(path).map_err(|e| fail(strip(e)))?;
                let values = (0..image.voxels.len())
                    .map(|i| image.voxels.value(i))
                    .collect();
                let grid = SizeGrid::new(image.dims, image.index_to_world, values)
                    .map_err(|e| fail(e.0.replacen("node", "voxel", 1)))?;
                Arc::new(grid)
            } else if is_point_file(path) {
                let (points, sizes) =
                    delamesh_formats::read_point_sizes(path).map_err(|e| fail(strip(e)))?;
                Arc::new(PointSizes::new(&points, &sizes).map_err(|e| fail(e.0))?)
            } else {
                let read = delamesh_formats::read_node_field(path, field.as_deref())
                    .map_err(|e| fail(strip(e)))?;
                let mesh = BackgroundMesh::new(read.mesh.positions, read.mesh.tets, read.values)
                    .map_err(|e| fail(format!("point field {:?}: {}", read.name, e.0)))?;
                let mesh = Arc::new(mesh);
                background = Some(mesh.clone());
                mesh
            }
        }
    };
    Ok(Loaded {
        name,
        field: Arc::new(Checked::new(field)),
        background,
    })
}

fn is_point_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ["xyz", "pts", "txt"].contains(&e.to_ascii_lowercase().as_str()))
}

/// How far (relative to the domain's diagonal) a boundary point may lie outside a background
/// mesh: a coarse background mesh of a curved part cuts its chords inside the surface, and the
/// nearest node's value serves there.
pub const COVER_TOLERANCE: f64 = 0.01;

/// The loaded fields of one run.
#[derive(Clone, Default)]
pub(crate) struct Fields {
    size: Option<Loaded>,
    distance: Option<Loaded>,
}

impl Fields {
    /// Loads the settings' fields.
    pub(crate) fn load(settings: &SizingSettings) -> Result<Fields, SizingFieldError> {
        Ok(Fields {
            size: settings
                .field
                .as_ref()
                .map(|s| load(s, "sizing"))
                .transpose()?,
            distance: settings
                .distance
                .as_ref()
                .map(|s| load(s, "distance"))
                .transpose()?,
        })
    }

    /// The size field, if any.
    pub(crate) fn size(&self) -> Option<Sizing> {
        self.size.as_ref().map(Loaded::sizing)
    }

    /// The distance field, if any.
    pub(crate) fn distance(&self) -> Option<Sizing> {
        self.distance.as_ref().map(Loaded::sizing)
    }

    fn all(&self) -> impl Iterator<Item = &Loaded> {
        self.size.iter().chain(&self.distance)
    }

    /// Refuses a background mesh farther than [`COVER_TOLERANCE`] × the domain's diagonal from
    /// a point of `points` (on the domain's boundary), and a field with a bad value at one of
    /// them or at the box's centre.
    pub(crate) fn check_cover(
        &self,
        points: &[Point3],
        bbox: &Aabb,
    ) -> Result<(), SizingFieldError> {
        let tolerance = COVER_TOLERANCE * bbox.diagonal();
        for loaded in self.all() {
            if let Some(bg) = &loaded.background
                && let Some(p) = points
                    .iter()
                    .find(|&&p| !bg.covers(p) && !bg.near(p, tolerance))
            {
                return Err(SizingFieldError {
                    source_name: loaded.name.clone(),
                    problem: format!(
                        "does not cover the domain: its boundary point ({}, {}, {}) lies \
                         outside every tetrahedron",
                        p.x, p.y, p.z
                    ),
                });
            }
            for &p in points.iter().chain([bbox.center()].iter()) {
                loaded.field.size_at(p, 1);
            }
        }
        self.check_values()
    }

    /// Refuses a field that gave a value that is not a positive number somewhere.
    pub(crate) fn check_values(&self) -> Result<(), SizingFieldError> {
        for loaded in self.all() {
            if let Some((p, v)) = loaded.field.first_bad() {
                return Err(SizingFieldError {
                    source_name: loaded.name.clone(),
                    problem: format!(
                        "gives {v} at ({}, {}, {}), not a positive size",
                        p.x, p.y, p.z
                    ),
                });
            }
        }
        Ok(())
    }
}

/// min(a, b) as one sizing (either may be a field).
pub(crate) fn min_of(a: Sizing, b: Sizing) -> Sizing {
    match (a, b) {
        (Sizing::Unbounded, s) | (s, Sizing::Unbounded) => s,
        (a, b) => Sizing::function(move |p, label| a.at(p, label).min(b.at(p, label))),
    }
}

/// `base`, with `values` in their labels.
pub(crate) fn per_label(base: Sizing, values: &BTreeMap<u32, f64>) -> Sizing {
    if values.is_empty() {
        return base;
    }
    match base {
        Sizing::Unbounded => Sizing::PerLabel {
            default: f64::INFINITY,
            values: values.clone(),
        },
        Sizing::Constant(default) => Sizing::PerLabel {
            default,
            values: values.clone(),
        },
        other => {
            let values = values.clone();
            Sizing::function(move |p, label| match values.get(&label) {
                Some(&v) => v,
                None => other.at(p, label),
            })
        }
    }
}

/// The criteria's sizes limited by the cell size graded by `gradation` over the domain, from
/// the cell size's values and from the protecting balls of the sharp features (small where
/// features are close, curves short or bent).
pub(crate) fn grade(
    criteria: &mut delamesh_core::refine::criteria::MeshCriteria,
    oracle: &dyn Oracle,
    gradation: f64,
) -> Result<(), SizingFieldError> {
    let bbox = oracle.bounding_box();
    let seeds = feature_sizes(oracle, criteria);
    let cell = criteria.cell.size.clone();
    let labelled = cell.depends_on_label();
    let sample = move |p: Point3| {
        if labelled {
            match oracle.subdomain(p) {
                OUTSIDE => f64::INFINITY,
                sub => cell.at(p, sub.0),
            }
        } else {
            cell.at(p, 1)
        }
    };
    let grid = graded(&sample, &seeds, &bbox, gradation, DEFAULT_GRADATION_NODES).map_err(|e| {
        SizingFieldError {
            source_name: "--size-gradation".into(),
            problem: e.0,
        }
    })?;
    if let Some(grid) = grid {
        for size in [
            &mut criteria.cell.size,
            &mut criteria.facet.size,
            &mut criteria.edge_size,
        ] {
            let field = std::mem::replace(size, Sizing::Unbounded);
            *size = Sizing::Field(Arc::new(Graded::new(field, grid.clone())));
        }
    }
    Ok(())
}
