//! What `delamesh mesh` can be asked: the criteria overrides, the guards, the feature detection.
//!
//! [`MeshSettings`] has public fields and a [`Default`] (the command line's defaults);
//! [`MeshSettings::builder`] sets them one by one and validates on [`MeshSettingsBuilder::build`].
//! The pipeline validates again, so settings written field by field are checked too.
//!
//! Adding an option: a field here (with its default in `Default`), a builder method, its check in
//! [`MeshSettings::validate`], its use in [`MeshSettings::criteria`] or
//! [`MeshSettings::mesh_options`] (or wherever the pipeline needs it), then the command-line flag
//! in `src/cli/mesh.rs` (`MeshArgs` and `MeshArgs::settings`).

use crate::sizing::{SizeSource, SizingSettings, min_of, per_label};
use delamesh_core::optimize::OptimizeOptions;
use delamesh_core::oracle::Aabb;
use delamesh_core::refine::criteria::{MeshCriteria, Sizing};
use delamesh_core::refine::{Limits, MeshOptions, ValidityOptions};
use delamesh_subdivision::SubdivisionOptions;
use std::collections::BTreeMap;
use std::fmt;
use std::path::PathBuf;

/// Everything the meshing pipeline can be told. `Default` gives the command line's defaults:
/// criteria scaled by the domain's bounding box, sharp features detected at
/// [`DEFAULT_FEATURE_ANGLE_DEG`](delamesh_piecewise_smooth::DEFAULT_FEATURE_ANGLE_DEG).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshSettings {
    /// Largest protecting ball radius along sharp feature curves (default: bounding-box
    /// diagonal / 20). Unused without features.
    pub edge_size: Option<f64>,
    /// Smallest protecting ball radius (CGAL's `edge_min_size`): sharp features closer than this
    /// are no longer split, but still meshed (default: bounding-box diagonal / 1000).
    pub edge_min_size: Option<f64>,
    /// Smallest facet angle in degrees (0 disables; ≤ 30 guarantees termination; default 25).
    pub facet_angle: Option<f64>,
    /// Largest surface Delaunay ball radius (default: diagonal / 20).
    pub facet_size: Option<f64>,
    /// Largest distance between a facet's circumcentre and the surface (default: diagonal / 400).
    pub facet_distance: Option<f64>,
    /// Largest tetrahedron circumradius / shortest edge (0 disables; default 3).
    pub cell_radius_edge_ratio: Option<f64>,
    /// Largest tetrahedron circumradius (default: diagonal / 20).
    pub cell_size: Option<f64>,
    /// Refinement stops past this many vertices; `None`: 50 times the count the criteria predict
    /// for the domain's bounding box, between 100,000 and 2,000,000
    /// ([`MeshCriteria::vertex_budget`]).
    pub max_vertices: Option<usize>,
    /// Refinement (protection included) stops when it has taken longer than this.
    pub time_limit: Option<std::time::Duration>,
    /// When a guard stops refinement, still return the mesh reached (marked as stopped).
    pub keep_partial: bool,
    /// Skip the repairs that make the boundary a 2-manifold with the input's topology (faster).
    pub non_manifold: bool,
    /// How sharp features of a surface are found.
    pub features: FeatureSettings,
    /// How a 3D image becomes a domain, and its sizes per label.
    pub image: ImageSettings,
    /// Refuse a surface that does not bound a volume as given (open, non-manifold,
    /// inconsistently oriented, self-intersecting, with degenerate triangles) instead of
    /// repairing it and meshing where its winding number is at least one.
    pub strict: bool,
    /// Mesh the input file as the control mesh of a subdivision surface (its limit surface
    /// bounds the domain) instead of as a triangle surface; `None`: a surface.
    pub subdivision: Option<SubdivisionOptions>,
    /// The optimisers run after refinement (default: CGAL's, perturbation and exudation;
    /// `OptimizeOptions::none()` for the refined mesh as it is).
    pub optimize: OptimizeOptions,
    /// Sizing fields, per-subdomain and per-patch sizes, gradation.
    pub sizing: SizingSettings,
    /// Keep the input surface exactly: every input vertex is a mesh vertex and every input
    /// triangle a union of boundary facets (Steiner points on the input edges and triangles as
    /// needed, no re-sampling). The surface must be closed and not self-intersecting.
    pub preserve_surface: bool,
    /// With `preserve_surface`: retriangulate each planar region of a patch (neighbouring
    /// triangles coplanar to within 1e-8 of the bounding-box diagonal, TetGen's tolerance) by
    /// Lawson flips first, as TetGen merges coplanar facets. The surface and its vertices are
    /// kept (to that tolerance), its triangles are not: CAD and CSG parts triangulate planar
    /// faces as fans of slivers that no mesh keeping them can avoid.
    pub merge_coplanar: bool,
}

/// Options of segmented and gray-level 3D images (unused for surfaces and plugins).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ImageSettings {
    /// Background label, isovalue, interpolation between voxel centres.
    pub options: delamesh_image_label::ImageOptions,
    /// Largest tetrahedron circumradius per label (subdomain); other labels use `cell_size`.
    pub cell_size_per_label: BTreeMap<u32, f64>,
}

/// Sharp-feature detection on a surface input.
#[derive(Clone, Debug, PartialEq)]
pub struct FeatureSettings {
    /// Look for sharp features at all; `false` meshes every surface as smooth.
    pub enabled: bool,
    /// Edges whose two triangles' normals differ by more than this many degrees are sharp.
    pub angle_deg: f64,
    /// More feature curves, from a CGAL `.polylines.txt` file.
    pub polylines: Option<PathBuf>,
}

impl Default for FeatureSettings {
    fn default() -> Self {
        FeatureSettings {
            enabled: true,
            angle_deg: delamesh_piecewise_smooth::DEFAULT_FEATURE_ANGLE_DEG,
            polylines: None,
        }
    }
}

/// An option with a value it cannot take.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("--{option} {problem}")]
pub struct SettingsError {
    /// The option, spelt as the command-line flag without its dashes (`facet-size`).
    pub option: &'static str,
    /// What is wrong with the value.
    pub problem: String,
}

impl SettingsError {
    fn new(option: &'static str, problem: impl fmt::Display) -> Self {
        SettingsError {
            option,
            problem: problem.to_string(),
        }
    }
}

fn positive(option: &'static str, v: Option<f64>) -> Result<(), SettingsError> {
    match v {
        Some(v) if !(v.is_finite() && v > 0.0) => Err(SettingsError::new(
            option,
            format!("must be a positive number, got {v}"),
        )),
        _ => Ok(()),
    }
}

fn non_negative(option: &'static str, v: Option<f64>) -> Result<(), SettingsError> {
    match v {
        Some(v) if !(v.is_finite() && v >= 0.0) => Err(SettingsError::new(
            option,
            format!("must be a number ≥ 0, got {v}"),
        )),
        _ => Ok(()),
    }
}

impl MeshSettings {
    /// A builder starting from the defaults.
    pub fn builder() -> MeshSettingsBuilder {
        MeshSettingsBuilder::default()
    }

    /// Checks every value on its own (the criteria against each other once the domain's bounding
    /// box gives the defaults, in the pipeline).
    pub fn validate(&self) -> Result<(), SettingsError> {
        positive("edge-size", self.edge_size)?;
        positive("edge-min-size", self.edge_min_size)?;
        if self.time_limit.is_some_and(|t| t.is_zero()) {
            return Err(SettingsError::new(
                "time-limit",
                "must be a positive number of seconds",
            ));
        }
        non_negative("facet-angle", self.facet_angle)?;
        positive("facet-size", self.facet_size)?;
        positive("facet-distance", self.facet_distance)?;
        non_negative("cell-radius-edge-ratio", self.cell_radius_edge_ratio)?;
        positive("cell-size", self.cell_size)?;
        for &size in self.image.cell_size_per_label.values() {
            positive("cell-size-per-label", Some(size))?;
        }
        if let Some(v) = self.image.options.isovalue.filter(|v| !v.is_finite()) {
            return Err(SettingsError::new(
                "isovalue",
                format!("must be a number, got {v}"),
            ));
        }
        self.validate_sizing()?;
        self.validate_preserve_surface()?;
        if let Some(a) = self.subdivision.as_ref().and_then(|s| s.crease_angle_deg)
            && !(0.0..=180.0).contains(&a)
        {
            return Err(SettingsError::new(
                "crease-angle",
                format!("must be an angle in degrees from 0 to 180, got {a}"),
            ));
        }
        if self.optimize.time_limit.is_some_and(|t| t.is_zero()) {
            return Err(SettingsError::new(
                "optimize-time",
                "must be a positive number of seconds",
            ));
        }
        Ok(())
    }

    /// The checks of [`SizingSettings`] that need no file: sizes, gradation, expressions.
    /// `--preserve-surface` keeps the input triangles as they are: options that re-sample the
    /// surface have nothing to act on (the cell criteria refine the volume, splitting input
    /// triangles only where a cell's centre asks it).
    fn validate_preserve_surface(&self) -> Result<(), SettingsError> {
        if !self.preserve_surface {
            return match self.merge_coplanar {
                true => Err(SettingsError::new(
                    "merge-coplanar",
                    "retriangulates the planar regions of a kept surface: it needs --preserve-surface",
                )),
                false => Ok(()),
            };
        }
        let conflicts = [
            ("edge-size", self.edge_size.is_some()),
            ("edge-min-size", self.edge_min_size.is_some()),
            ("facet-angle", self.facet_angle.is_some()),
            ("facet-size", self.facet_size.is_some()),
            ("facet-distance", self.facet_distance.is_some()),
            ("subdivision", self.subdivision.is_some()),
        ];
        match conflicts.iter().find(|c| c.1) {
            Some((option, _)) => Err(SettingsError::new(
                "preserve-surface",
                format!(
                    "keeps the input triangles as given and cannot be combined with --{option}"
                ),
            )),
            None => Ok(()),
        }
    }

    fn validate_sizing(&self) -> Result<(), SettingsError> {
        let s = &self.sizing;
        for &size in s.per_subdomain.values() {
            positive("size-per-subdomain", Some(size))?;
        }
        for &size in s.per_patch.values() {
            positive("size-per-patch", Some(size))?;
        }
        positive("size-gradation", s.gradation)?;
        for (option, source) in [("sizing-expr", &s.field), ("distance-expr", &s.distance)] {
            if let Some(SizeSource::Expression(e)) = source {
                crate::sizing::check_expression(e)
                    .map_err(|problem| SettingsError::new(option, format!("{e:?}: {problem}")))?;
            }
        }
        Ok(())
    }

    /// Values that are valid but may keep refinement from terminating before `max_vertices`.
    pub fn warnings(&self) -> Vec<String> {
        // What cannot terminate at all is refused by `MeshCriteria::validate`; the rule for what
        // may not lives there too.
        self.cell_radius_edge_ratio
            .and_then(delamesh_core::refine::criteria::radius_edge_warning)
            .map(|w| format!("--{w}"))
            .into_iter()
            .collect()
    }

    /// The CGAL-style criteria for a domain in `bbox`: defaults scaled by the box, overridden by
    /// the settings' constant, per-subdomain and per-patch sizes. The pipeline adds the sizing
    /// fields and the gradation once it has loaded them and built the domain.
    pub fn criteria(&self, bbox: &Aabb) -> MeshCriteria {
        self.criteria_with(bbox, None, None)
    }

    /// [`criteria`](Self::criteria) with a size field and a distance field (see
    /// [`crate::sizing`] for how they combine with the other sizes).
    pub(crate) fn criteria_with(
        &self,
        bbox: &Aabb,
        size: Option<Sizing>,
        distance: Option<Sizing>,
    ) -> MeshCriteria {
        let mut c = MeshCriteria::default_for(bbox);
        // A number given caps a field; without one the field replaces the default.
        let base =
            |given: Option<f64>, default: Sizing, field: &Option<Sizing>| match (given, field) {
                (Some(v), _) => Sizing::Constant(v),
                (None, Some(_)) => Sizing::Unbounded,
                (None, None) => default,
            };
        c.edge_size = base(self.edge_size, c.edge_size, &size);
        if let Some(v) = self.edge_min_size {
            c.edge_min_size = v;
        }
        if let Some(v) = self.facet_angle {
            c.facet.angle_deg = v;
        }
        let facet = base(self.facet_size, c.facet.size, &size);
        c.facet.size = per_label(facet, &self.sizing.per_patch);
        c.facet.distance = base(self.facet_distance, c.facet.distance, &distance);
        if let Some(v) = self.cell_radius_edge_ratio {
            c.cell.radius_edge_ratio = v;
        }
        let mut per_subdomain = self.image.cell_size_per_label.clone();
        per_subdomain.extend(&self.sizing.per_subdomain);
        let cell = base(self.cell_size, c.cell.size, &size);
        c.cell.size = per_label(cell, &per_subdomain);
        if let Some(field) = size {
            c.edge_size = min_of(c.edge_size, field.clone());
            c.facet.size = min_of(c.facet.size, field.clone());
            c.cell.size = min_of(c.cell.size, field);
        }
        if let Some(field) = distance {
            c.facet.distance = min_of(c.facet.distance, field);
        }
        c
    }

    /// The core mesher's options for a domain in `bbox`.
    pub fn mesh_options(&self, bbox: &Aabb) -> MeshOptions {
        let criteria = self.criteria(bbox);
        MeshOptions {
            limits: Limits {
                max_vertices: self
                    .max_vertices
                    .unwrap_or_else(|| criteria.vertex_budget(bbox)),
                time_limit: self.time_limit,
                ..Limits::default()
            },
            keep_partial: self.keep_partial,
            validity: ValidityOptions {
                manifold: !self.non_manifold,
                ..ValidityOptions::default()
            },
            optimize: self.optimize.clone(),
            criteria,
        }
    }
}

/// Sets [`MeshSettings`] one option at a time; [`build`](Self::build) validates them.
///
/// ```
/// let settings = delamesh::MeshSettings::builder()
///     .facet_size(0.1)
///     .max_vertices(100_000)
///     .build()
///     .unwrap();
/// assert_eq!(settings.facet_size, Some(0.1));
/// assert!(delamesh::MeshSettings::builder().cell_size(-1.0).build().is_err());
/// ```
#[derive(Clone, Debug, Default)]
pub struct MeshSettingsBuilder {
    settings: MeshSettings,
}

/// Builder setters that assign one field of the settings each: `fn name(value: Type) =>
/// field.path = expression;` with the doc comments above each.
macro_rules! setters {
    ($($(#[$attr:meta])* fn $name:ident($v:ident: $t:ty) => $($field:ident).+ = $value:expr;)*) => {
        $(
            $(#[$attr])*
            pub fn $name(mut self, $v: $t) -> Self {
                self.settings.$($field).+ = $value;
                self
            }
        )*
    };
}

impl MeshSettingsBuilder {
    setters! {
        /// See [`MeshSettings::edge_size`].
        fn edge_size(v: f64) => edge_size = Some(v);
        /// See [`MeshSettings::edge_min_size`].
        fn edge_min_size(v: f64) => edge_min_size = Some(v);
        /// See [`MeshSettings::time_limit`].
        fn time_limit(limit: std::time::Duration) => time_limit = Some(limit);
        /// See [`MeshSettings::facet_angle`].
        fn facet_angle(degrees: f64) => facet_angle = Some(degrees);
        /// See [`MeshSettings::facet_size`].
        fn facet_size(v: f64) => facet_size = Some(v);
        /// See [`MeshSettings::facet_distance`].
        fn facet_distance(v: f64) => facet_distance = Some(v);
        /// See [`MeshSettings::cell_radius_edge_ratio`].
        fn cell_radius_edge_ratio(v: f64) => cell_radius_edge_ratio = Some(v);
        /// See [`MeshSettings::cell_size`].
        fn cell_size(v: f64) => cell_size = Some(v);
        /// See [`MeshSettings::max_vertices`].
        fn max_vertices(n: usize) => max_vertices = Some(n);
        /// See [`MeshSettings::optimize`].
        fn optimize(optimize: OptimizeOptions) => optimize = optimize;
        /// See [`MeshSettings::keep_partial`].
        fn keep_partial(keep: bool) => keep_partial = keep;
        /// See [`FeatureSettings::enabled`].
        fn features(enabled: bool) => features.enabled = enabled;
        /// See [`FeatureSettings::angle_deg`].
        fn feature_angle(degrees: f64) => features.angle_deg = degrees;
        /// See [`FeatureSettings::polylines`].
        fn feature_polylines(path: impl Into<PathBuf>) => features.polylines = Some(path.into());
        /// See [`ImageSettings::options`]: the outside label of a segmented image.
        fn background(label: u32) => image.options.background = label;
        /// See [`ImageSettings::options`]: mesh a gray-level image as {value ≥ `v`}.
        fn isovalue(v: f64) => image.options.isovalue = Some(v);
        /// See [`SizingSettings::field`].
        fn sizing(source: SizeSource) => sizing.field = Some(source);
        /// See [`SizingSettings::gradation`].
        fn size_gradation(gradation: f64) => sizing.gradation = Some(gradation);
        /// See [`SizingSettings::distance`].
        fn distance_field(source: SizeSource) => sizing.distance = Some(source);
        /// See [`MeshSettings::subdivision`].
        fn subdivision(options: SubdivisionOptions) => subdivision = Some(options);
        /// See [`MeshSettings::preserve_surface`].
        fn preserve_surface(preserve: bool) => preserve_surface = preserve;
        /// See [`MeshSettings::merge_coplanar`].
        fn merge_coplanar(merge: bool) => merge_coplanar = merge;
        /// See [`MeshSettings::strict`].
        fn strict(strict: bool) => strict = strict;
    }

    /// See [`ImageSettings::cell_size_per_label`].
    pub fn cell_size_for_label(mut self, label: u32, size: f64) -> Self {
        self.settings.image.cell_size_per_label.insert(label, size);
        self
    }
    /// See [`SizingSettings::per_subdomain`].
    pub fn size_for_subdomain(mut self, subdomain: u32, size: f64) -> Self {
        self.settings.sizing.per_subdomain.insert(subdomain, size);
        self
    }
    /// See [`SizingSettings::per_patch`].
    pub fn size_for_patch(mut self, patch: u32, size: f64) -> Self {
        self.settings.sizing.per_patch.insert(patch, size);
        self
    }
    /// The settings, if every value is valid.
    pub fn build(self) -> Result<MeshSettings, SettingsError> {
        self.settings.validate()?;
        Ok(self.settings)
    }
}
