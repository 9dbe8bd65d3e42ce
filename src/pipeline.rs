//! The whole meshing pipeline of `delamesh mesh`: read → domain → refine → complex → report data
//! → write, one implementation for files, in-memory surfaces and plugins.

use crate::domain::Domain;
use crate::error::Error;
use crate::plugins::load_domain;
use crate::report::{InputSurface, Report, ReportInput, Times};
use crate::settings::MeshSettings;
use crate::sizing::{Fields, grade};
use delamesh_core::complex::MeshComplex;
use delamesh_core::conform3::{PreserveError, PreserveOptions, preserve_surface};
use delamesh_core::mesh::component_euler_characteristics;
use delamesh_core::mesh::{SurfaceMesh, TetMesh};
use delamesh_core::mesh::{flip_coplanar, weld_exact};
use delamesh_core::optimize::{Flips, OptimizeOptions, OptimizeReport, optimize};
use delamesh_core::oracle::Oracle;
use delamesh_core::refine::criteria::{CellCriteria, MeshCriteria, Sizing};
use delamesh_core::refine::{
    Cancel, MeshError, MeshOptions, Progress, RefineError, RefineStats, mesh_domain,
};
use delamesh_formats::image::{Image, is_image_path, read_image};
use delamesh_formats::{PolygonMesh, WriteOptions, read_polygons, read_surface, write_tet_mesh};
use delamesh_image_label::ImageOptions;
use delamesh_polyhedral::{PolyhedralOptions, PolyhedralOracle};
use std::path::Path;
use std::time::{Duration, Instant};

/// The automatic vertex limit of `--preserve-surface` (no `--max-vertices`): this many vertices
/// per input vertex, over [`RECOVERY_MIN_BUDGET`] for recovery alone or over the criteria's own
/// limit when the cells are refined. Recovery needs up to 22 per input vertex on CGAL's models
/// (conforming, on CAD parts with long thin triangles); one that cycles then stops within
/// seconds with an error naming the limit, instead of running for minutes.
const STEINER_BUDGET_PER_INPUT_VERTEX: usize = 100;
/// See [`STEINER_BUDGET_PER_INPUT_VERTEX`].
const RECOVERY_MIN_BUDGET: usize = 10_000;
/// How far from planar (relative to the bounding-box diagonal) `--merge-coplanar` takes a region
/// to be: TetGen's default tolerance, above the rounding of float32 exports.
const COPLANAR_TOLERANCE: f64 = 1e-8;
/// The times of a domain built from an input read in `read`, its oracle from `t` on.
fn oracle_times(read: Duration, t: Instant) -> Times {
    Times {
        read,
        oracle: t.elapsed(),
        ..Times::default()
    }
}

/// A progress callback: called now and then during refinement.
pub type ProgressFn<'p> = dyn FnMut(&Progress) + 'p;

/// Runs the pipeline with one set of settings and an optional progress callback.
///
/// ```no_run
/// use delamesh::{Mesher, MeshSettings};
/// let settings = MeshSettings::builder().facet_size(0.05).build()?;
/// let mut meshed = Mesher::new(settings).mesh_file("part.stl".as_ref())?;
/// meshed.write("part.vtu".as_ref(), &Default::default())?;
/// println!("{} tetrahedra", meshed.complex.tets.len());
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct Mesher<'p> {
    settings: MeshSettings,
    progress: Option<Box<ProgressFn<'p>>>,
    cancel: Option<Cancel>,
}

/// A finished run: the mesh, what refinement did, and whether a guard stopped it early.
pub struct Meshed {
    /// What the validity repairs could not reach (flat cells, a non-manifold boundary, input
    /// components whose topology the boundary does not reproduce), one sentence each: the mesh
    /// is still returned.
    pub warnings: Vec<String>,
    /// The mesh: points, tetrahedra with subdomains, boundary facets with patches, features.
    pub complex: MeshComplex,
    /// What refinement did (empty when a guard stopped it).
    pub stats: RefineStats,
    /// The guard that stopped refinement before the criteria were met, if any; the mesh is then
    /// the one reached (returned only with [`MeshSettings::keep_partial`]).
    pub stopped: Option<RefineError>,
    /// The criteria used, defaults resolved against the domain's bounding box.
    pub criteria: MeshCriteria,
    /// Wall time of each phase so far.
    pub times: Times,
    /// Quality before and after each optimisation step.
    pub optimization: OptimizeReport,
    domain: Domain,
    name: String,
    input: Option<SurfaceMesh>,
    /// Euler characteristic of each closed component the validity repairs held the boundary to
    /// (the input surface's, the control mesh's; none for an image or a kept surface), for the
    /// report where there is no input surface to measure.
    input_euler: Option<Vec<i64>>,
    output: Option<String>,
    started: Instant,
}

impl<'p> Mesher<'p> {
    /// A pipeline with these settings and no progress callback.
    pub fn new(settings: MeshSettings) -> Self {
        Mesher {
            settings,
            progress: None,
            cancel: None,
        }
    }

    /// Stops refinement with [`RefineError::Cancelled`] once `flag` is raised (from another
    /// thread, or from the progress callback: a user's interrupt).
    pub fn cancel_on(mut self, flag: Cancel) -> Self {
        self.cancel = Some(flag);
        self
    }

    /// Calls `f` now and then during refinement (vertex count, queue lengths).
    pub fn on_progress(mut self, f: impl FnMut(&Progress) + 'p) -> Self {
        self.progress = Some(Box::new(f));
        self
    }

    /// The settings this pipeline runs with.
    pub fn settings(&self) -> &MeshSettings {
        &self.settings
    }

    /// Meshes the inside of the closed surface in the file `path` (any format the formats crate
    /// reads).
    pub fn mesh_file(&mut self, path: &Path) -> Result<Meshed, Error> {
        if is_image_path(path) {
            return self.mesh_image_file(path);
        }
        if self.settings.subdivision.is_some() {
            return self.mesh_control_mesh_file(path);
        }
        self.read_then_mesh(
            path,
            |p| Ok(read_surface(p, None)?.mesh),
            Self::mesh_surface_from,
        )
    }

    /// Meshes the inside of a closed surface given in memory; `name` names it in errors and in the
    /// report.
    pub fn mesh_surface(&mut self, name: &str, surface: SurfaceMesh) -> Result<Meshed, Error> {
        self.settings.validate()?;
        let started = Instant::now();
        self.mesh_surface_from(name.to_string(), surface, started, Default::default())
    }

    /// Meshes the domain of the plugin `spec` (a library path, a name looked up in
    /// [`PLUGIN_PATH_VAR`](crate::plugins::PLUGIN_PATH_VAR), or a built-in plugin's name) created
    /// from `config` (see [`load_domain`]).
    pub fn mesh_plugin(&mut self, spec: &str, config: &str) -> Result<Meshed, Error> {
        self.settings.validate()?;
        let started = Instant::now();
        let domain = load_domain(spec, config)?;
        let times = Times {
            oracle: started.elapsed(),
            ..Times::default()
        };
        self.mesh_domain(format!("plugin `{spec}`"), domain, None, started, times)
    }

    /// Meshes the labels of the 3D image in the file `path` (`.inr`, `.nii`, `.vti`, `.nrrd`,
    /// `.nhdr`, each optionally `.gz`), one subdomain per label.
    pub fn mesh_image_file(&mut self, path: &Path) -> Result<Meshed, Error> {
        self.read_then_mesh(path, |p| Ok(read_image(p)?), Self::mesh_image_from)
    }

    /// Meshes the labels of a 3D image held in memory (voxels x fastest, then y, then z), one
    /// subdomain per label; `name` names it in errors.
    pub fn mesh_image(&mut self, name: &str, image: Image) -> Result<Meshed, Error> {
        self.settings.validate()?;
        let started = Instant::now();
        self.mesh_image_from(name.to_string(), image, started, Default::default())
    }

    /// Validates the settings, reads the file `path` with `read` and meshes what it holds with
    /// `mesh`, given its name, the start time and the reading time.
    fn read_then_mesh<T>(
        &mut self,
        path: &Path,
        read: impl FnOnce(&Path) -> Result<T, Error>,
        mesh: impl FnOnce(&mut Self, String, T, Instant, Duration) -> Result<Meshed, Error>,
    ) -> Result<Meshed, Error> {
        self.settings.validate()?;
        let started = Instant::now();
        let input = read(path)?;
        let read = started.elapsed();
        mesh(self, path.display().to_string(), input, started, read)
    }

    fn mesh_image_from(
        &mut self,
        name: String,
        image: Image,
        started: Instant,
        read: Duration,
    ) -> Result<Meshed, Error> {
        let t = Instant::now();
        // `--no-features` also leaves an image's triple lines and border curves unprotected.
        let options = ImageOptions {
            features: self.settings.image.options.features && self.settings.features.enabled,
            ..self.settings.image.options.clone()
        };
        let domain = Domain::from_image(&name, &image, &options)?;
        drop(image);
        self.mesh_domain(name, domain, None, started, oracle_times(read, t))
    }

    /// Meshes the inside of the limit surface of the subdivision control mesh in the file `path`
    /// (OBJ, OFF or PLY polygons), with [`MeshSettings::subdivision`]'s options (default ones
    /// when unset); `--features` polylines add creases.
    pub fn mesh_control_mesh_file(&mut self, path: &Path) -> Result<Meshed, Error> {
        self.read_then_mesh(
            path,
            |p| Ok(read_polygons(p, None)?.0),
            |m, name, mesh, started, read| m.mesh_control_mesh_from(name, &mesh, started, read),
        )
    }

    /// [`Mesher::mesh_control_mesh_file`] of a control mesh in memory; `name` names it in errors.
    pub fn mesh_control_mesh(&mut self, name: &str, mesh: &PolygonMesh) -> Result<Meshed, Error> {
        self.settings.validate()?;
        let started = Instant::now();
        self.mesh_control_mesh_from(name.to_string(), mesh, started, Default::default())
    }

    fn mesh_control_mesh_from(
        &mut self,
        name: String,
        mesh: &PolygonMesh,
        started: Instant,
        read: Duration,
    ) -> Result<Meshed, Error> {
        let t = Instant::now();
        let options = self.settings.subdivision.clone().unwrap_or_default();
        let polylines = self.settings.features.polylines.as_deref();
        let domain = Domain::from_control_mesh(&name, mesh, &options, polylines)?;
        self.mesh_domain(name, domain, None, started, oracle_times(read, t))
    }

    /// Meshes the domain an oracle of your own describes (see [`Oracle`](delamesh_core::Oracle));
    /// `name` names it in errors.
    pub fn mesh_oracle(
        &mut self,
        name: &str,
        oracle: impl Oracle + 'static,
    ) -> Result<Meshed, Error> {
        self.settings.validate()?;
        let domain = Domain::Custom(Box::new(oracle));
        let times = Times::default();
        self.mesh_domain(name.to_string(), domain, None, Instant::now(), times)
    }

    fn mesh_surface_from(
        &mut self,
        name: String,
        surface: SurfaceMesh,
        started: Instant,
        read: Duration,
    ) -> Result<Meshed, Error> {
        if self.settings.preserve_surface {
            return self.mesh_preserving(name, surface, started, read);
        }
        let t = Instant::now();
        let domain = Domain::from_surface(
            &name,
            &surface,
            &self.settings.features,
            self.settings.strict,
        )?;
        self.mesh_domain(name, domain, Some(surface), started, oracle_times(read, t))
    }

    /// `--preserve-surface`: the surface kept in a conforming Delaunay tetrahedralisation; the
    /// polyhedral oracle names the subdomains. A surface that does not bound a volume as given
    /// (refused with `--strict`) is repaired as for resampling, and the boundary of its
    /// winding-number domain is kept: the input's triangles, cut along their crossings.
    fn mesh_preserving(
        &mut self,
        name: String,
        mut surface: SurfaceMesh,
        started: Instant,
        read: Duration,
    ) -> Result<Meshed, Error> {
        let t = Instant::now();
        let unmeshable = |problem: String| Error::Unmeshable {
            name: name.clone(),
            problem,
        };
        weld_exact(&mut surface.positions, &mut surface.triangles);
        let strict = PolyhedralOptions {
            strict: self.settings.strict,
        };
        let (oracle, defects) = PolyhedralOracle::with_defects(
            &surface.positions,
            &surface.triangles,
            Some(&surface.oracle_patches()),
            &strict,
        )
        .map_err(|e| unmeshable(format!("--preserve-surface: {e}")))?;
        let domain = Domain::Smooth(oracle);
        // A surface that does not bound a volume as given keeps the boundary of its
        // winding-number domain: its triangles cut where they cross, less the buried sheets.
        let kept = match domain.polyhedral() {
            Some(p) if !defects.is_empty() => Some(
                p.winding_boundary()
                    .map_err(|e| unmeshable(format!("--preserve-surface: {e}")))?,
            ),
            _ => None,
        };
        let mut times = oracle_times(read, t);
        let t = Instant::now();
        let mut warnings = Vec::new();
        let (positions, mut triangles, patches) = match kept {
            Some(b) => {
                if b.cut + b.dropped + b.separated > 0 {
                    warnings.push(format!(
                        "kept the boundary of the winding-number domain: {} triangles cut \
                         along their crossings, {} triangles or pieces dropped (buried or \
                         outside), {} points where sheets touched parted",
                        b.cut, b.dropped, b.separated
                    ));
                }
                (b.points, b.triangles, b.patches)
            }
            None => (
                surface.positions.clone(),
                surface.triangles.clone(),
                surface.oracle_patches(),
            ),
        };
        let bbox = domain.oracle().bounding_box();
        if self.settings.merge_coplanar {
            let tolerance = COPLANAR_TOLERANCE * (bbox.max - bbox.min).length();
            let done = flip_coplanar(&positions, &mut triangles, &patches, tolerance);
            if done.moved > 0.0 {
                warnings.push(format!(
                    "--merge-coplanar: {} edges of planar regions flipped; the surface moved by \
                     at most {:.3e} where regions are planar only to within the tolerance",
                    done.flips, done.moved
                ));
            }
        }
        let criteria = self.settings.criteria(&bbox);
        let settings = &self.settings;
        // Quality refinement only when a cell criterion is asked for: by default the surface's
        // own vertices and the recovery's Steiner points are the whole mesh, as `tetgen -p`.
        let sized = settings.cell_size.is_some() || !settings.sizing.per_subdomain.is_empty();
        let shaped = settings.cell_radius_edge_ratio.is_some();
        let options = PreserveOptions {
            max_vertices: settings.max_vertices.unwrap_or_else(|| {
                let base = if sized || shaped {
                    criteria.vertex_budget(&bbox)
                } else {
                    RECOVERY_MIN_BUDGET
                };
                base.saturating_add(STEINER_BUDGET_PER_INPUT_VERTEX.saturating_mul(positions.len()))
            }),
            cells: (sized || shaped).then(|| CellCriteria {
                radius_edge_ratio: settings.cell_radius_edge_ratio.unwrap_or(0.0),
                size: if sized {
                    criteria.cell.size.clone()
                } else {
                    Sizing::Unbounded
                },
            }),
            time_limit: settings.time_limit,
            cancel: self.cancel.clone(),
            ..PreserveOptions::default()
        };
        let preserved =
            match preserve_surface(&positions, &triangles, &patches, domain.oracle(), &options) {
                Ok(p) => p,
                Err(PreserveError::Stopped(source)) => return Err(Error::Stopped { name, source }),
                Err(e) => return Err(unmeshable(format!("--preserve-surface: {e}"))),
            };
        times.refinement = t.elapsed();
        // The cell level stopped early: its mesh keeps the surface, so it is the partial mesh.
        if let Some(source) = preserved.stopped.clone()
            && !settings.keep_partial
        {
            return Err(Error::Stopped { name, source });
        }
        if preserved.complex.tets.is_empty() {
            return Err(Error::Empty {
                name,
                what: "surface",
                floor: None,
            });
        }
        // The sliver steps are the flips: their moves and splits are inside, and perturbation
        // would slide the input's vertices and peel its triangles. A stopped cell level leaves
        // a partial mesh, which is not optimised (as in refinement).
        let options = if preserved.stopped.is_some() {
            OptimizeOptions::none()
        } else {
            let o = &settings.optimize;
            OptimizeOptions {
                perturb: false,
                exude: false,
                flip: match o.flip {
                    Flips::All => Flips::All,
                    Flips::Slivers if o.perturb || o.exude => Flips::All,
                    _ => Flips::Off,
                },
                cancel: self.cancel.clone(),
                ..o.clone()
            }
        };
        let t = Instant::now();
        let (complex, optimization) =
            optimize(preserved.complex, &[], domain.oracle(), &criteria, &options);
        times.optimization = t.elapsed();
        Ok(Meshed {
            complex,
            // The levels: Steiner points on input edges, inside triangles, inside the volume.
            stats: RefineStats {
                insertions: vec![
                    preserved.edge_steiner,
                    preserved.facet_steiner,
                    preserved.cell_steiner,
                ],
                ..RefineStats::default()
            },
            warnings,
            stopped: preserved.stopped,
            criteria,
            times,
            optimization,
            domain,
            name,
            input_euler: None,
            input: Some(surface),
            output: None,
            started,
        })
    }

    /// The criteria and guards for `domain`: the settings with the sizing fields, the input's
    /// topology for the validity repairs, the defaults of image and subdivision domains, and the
    /// vertex budget; checked, so that what cannot terminate is refused before meshing.
    fn refinement_options(
        &self,
        name: &str,
        domain: &Domain,
        input: Option<&SurfaceMesh>,
        fields: &Fields,
    ) -> Result<MeshOptions, Error> {
        let oracle = domain.oracle();
        let bbox = oracle.bounding_box();
        let mut options = self.settings.mesh_options(&bbox);
        options.criteria = self
            .settings
            .criteria_with(&bbox, fields.size(), fields.distance());
        options.limits.cancel = self.cancel.clone();
        options.optimize.cancel = self.cancel.clone();
        if let Some(surface) = input {
            options.validity.input_euler =
                Some(component_euler_characteristics(&surface.triangles).1);
        }
        if let Some(p) = domain.polyhedral()
            && p.repairs().needs_winding_domain()
        {
            // Holes capped, crossings resolved: the input's components are not the domain's.
            options.validity.input_euler = p
                .winding_boundary_euler_characteristics()
                .map(<[_]>::to_vec);
        }
        let boundary: Vec<_> = match input {
            Some(surface) => surface.positions.clone(),
            None => oracle.initial_points().iter().map(|p| p.point).collect(),
        };
        fields.check_cover(&boundary, &bbox)?;
        if let Some(gradation) = self.settings.sizing.gradation {
            grade(&mut options.criteria, oracle, gradation)?;
        }
        let no_distance = self.settings.facet_distance.is_none() && fields.distance().is_none();
        if let Domain::Subdivision(o) = domain {
            // The limit surface has the control mesh's topology.
            options.validity.input_euler = Some(o.euler_characteristics().to_vec());
        }
        if let (Domain::Image(image), true) = (domain, no_distance) {
            // Finer than the voxels, the facet distance would chase their staircase.
            options.criteria.facet.distance = image.default_criteria().facet.distance;
        }
        if let (Domain::Image(image), None) = (domain, self.settings.edge_min_size) {
            options.criteria.edge_min_size = image.default_criteria().edge_min_size;
        }
        if let (Domain::Image(_), None) = (domain, self.settings.edge_size) {
            // The feature curves of an image are followed at the facet size (CGAL's examples),
            // not at the bounding-box default.
            if let (Some(facet), Some(edge)) = (
                options.criteria.facet.size.smallest(),
                options.criteria.edge_size.smallest(),
            ) {
                options.criteria.edge_size = Sizing::Constant(facet.min(edge));
            }
        }
        if self.settings.max_vertices.is_none() {
            // The final criteria (fields, gradation) predict the count.
            options.limits.max_vertices = options.criteria.vertex_budget(&bbox);
        }
        // Warnings were given from the settings before meshing (`MeshSettings::warnings`).
        options
            .criteria
            .validate(&bbox, options.limits.max_vertices)
            .map_err(|problem| Error::Criteria {
                name: name.to_string(),
                problem,
            })?;
        Ok(options)
    }

    /// Refines `domain` and collects the complex; every input ends here.
    fn mesh_domain(
        &mut self,
        name: String,
        domain: Domain,
        input: Option<SurfaceMesh>,
        started: Instant,
        mut times: Times,
    ) -> Result<Meshed, Error> {
        if self.settings.preserve_surface {
            return Err(Error::Unmeshable {
                name,
                problem: "--preserve-surface keeps a triangle surface; this input is not one"
                    .into(),
            });
        }
        let oracle = domain.oracle();
        let fields = Fields::load(&self.settings.sizing)?;
        let options = self.refinement_options(&name, &domain, input.as_ref(), &fields)?;
        let mut silent = |_: &Progress| {};
        let progress: &mut dyn FnMut(&Progress) = match self.progress.as_mut() {
            Some(f) => f,
            None => &mut silent,
        };
        let outcome = mesh_domain(oracle, &options, progress);
        domain.check()?;
        // A closure or an expression may have given a bad value on the way: no mesh then.
        fields.check_values()?;
        let mut warnings = Vec::new();
        let (complex, stats, stopped, optimization) = match outcome {
            Ok(o) => {
                times.initial_points = o.times.initial_points;
                times.refinement = o.times.refinement;
                times.complex = o.times.complex;
                warnings = validity_warnings(&o.validity, options.validity.manifold);
                // A few such facets are a CSG seam's micro-sheets; one in a hundred is a part.
                if o.validity.unresolved_sheets * 100 >= o.complex.facets.len().max(1) {
                    let floor = options.criteria.refinement_floor(&oracle.bounding_box());
                    warnings.push(format!(
                        "{} boundary facets lie where two sheets of the surface are closer than \
                         {floor:.3e} (--edge-min-size): a plate or a slot thinner than that may be \
                         lost or closed; a smaller --edge-min-size resolves it",
                        o.validity.unresolved_sheets
                    ));
                }
                times.optimization = o.times.optimization;
                (o.complex, o.stats, None, o.optimization)
            }
            Err(MeshError::Refinement {
                source,
                partial: Some(complex),
            }) => {
                // A partial mesh is not optimised; its report still gives its quality.
                let none = OptimizeOptions::none();
                let (complex, report) = optimize(*complex, &[], oracle, &options.criteria, &none);
                (complex, RefineStats::default(), Some(source), report)
            }
            Err(MeshError::Refinement {
                source,
                partial: None,
            }) => return Err(Error::Stopped { name, source }),
            Err(source) => return Err(Error::Mesh { name, source }),
        };
        if complex.tets.is_empty() {
            let what = if input.is_some() { "surface" } else { "domain" };
            let floor = Some(options.criteria.refinement_floor(&oracle.bounding_box()));
            return Err(Error::Empty { name, what, floor });
        }
        Ok(Meshed {
            complex,
            stats,
            warnings,
            stopped,
            criteria: options.criteria,
            times,
            optimization,
            domain,
            name,
            input,
            input_euler: options.validity.input_euler,
            output: None,
            started,
        })
    }
}

impl Meshed {
    /// The mesh as the formats crate writes it (with per-cell quality fields).
    pub fn tet_mesh(&self) -> TetMesh {
        self.complex.to_tet_mesh()
    }

    /// The domain that was meshed.
    pub fn domain(&self) -> &Domain {
        &self.domain
    }

    /// The input's name, as given (file path, or plugin).
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Writes the mesh to `path`, the format following its extension (atomically: readers never
    /// see half a file).
    pub fn write(&mut self, path: &Path, options: &WriteOptions) -> Result<(), Error> {
        let t = Instant::now();
        write_tet_mesh(path, &self.tet_mesh(), options)?;
        self.times.write = t.elapsed();
        self.output = Some(path.display().to_string());
        Ok(())
    }

    /// The report of the mesh: counts, times, quality, volumes, boundary topology, and for an
    /// input triangle surface how closely the mesh follows it.
    pub fn report(&mut self) -> Report {
        let t = Instant::now();
        let surface = match (&self.input, self.domain.polyhedral()) {
            (Some(input), Some(polyhedral)) => Some(InputSurface {
                points: &input.positions,
                triangles: &input.triangles,
                polyhedral,
            }),
            _ => None,
        };
        let mut report = Report::new(&ReportInput {
            input: &self.name,
            output: self.output.as_deref().unwrap_or_default(),
            surface,
            input_euler: self.input_euler.as_deref(),
            domain: self.domain.oracle(),
            criteria: &self.criteria,
            complex: &self.complex,
            stats: &self.stats,
            optimization: &self.optimization,
        });
        self.times.quality = t.elapsed();
        self.times.total = self.started.elapsed();
        report.times_s = self.times.seconds();
        report
    }
}

/// Meshes the inside of the closed surface in `input` with default settings and writes it to
/// `output` (format from the extension).
pub fn mesh_file(input: &Path, output: &Path) -> Result<Meshed, Error> {
    let mut meshed = Mesher::new(MeshSettings::default()).mesh_file(input)?;
    meshed.write(output, &WriteOptions::default())?;
    Ok(meshed)
}

/// What the validity repairs could not reach, one sentence each.
fn validity_warnings(v: &delamesh_core::refine::Validity, manifold_asked: bool) -> Vec<String> {
    let mut warnings = Vec::new();
    if v.flat_cells > 0 {
        warnings.push(format!("{} flat tetrahedra are left", v.flat_cells));
    }
    if manifold_asked && !v.manifold {
        warnings.push("the mesh boundary is not a 2-manifold (repairs stopped by a guard)".into());
    }
    warnings.extend(v.topology_warnings.iter().cloned());
    warnings
}
