//! `delamesh mesh`: a quality tetrahedral mesh of the volume bounded by a closed surface.

use crate::domain::{Domain, FeatureArgs};
use anyhow::{Result, bail};
use clap::Args;
use delamesh_core::complex::MeshComplex;
use delamesh_core::oracle::Oracle;
use delamesh_core::quality::{self, TetQuality};
use delamesh_core::refine::criteria::{MeshCriteria, Sizing};
use delamesh_core::refine::{Limits, MeshError, MeshOptions, MeshOutcome, Progress, mesh_domain};
use delamesh_formats::{WriteOptions, read_surface, write_tet_mesh};
use delamesh_polyhedral::{PolyhedralOracle, TriangleTree};
use glam::DVec3;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

#[derive(Args, Debug)]
pub struct MeshArgs {
    /// Closed triangle surface bounding the volume (STL, OFF, OBJ, PLY, glTF...).
    #[arg(required_unless_present = "plugin", conflicts_with = "plugin")]
    pub input: Option<PathBuf>,
    /// Output tet mesh; the format follows the extension (.vtu .vtk .mesh .msh, or a surface format
    /// for the boundary only).
    #[arg(short, long)]
    pub output: PathBuf,
    /// Largest protecting ball radius along sharp feature curves, so the length of the edges
    /// that follow them (default: bounding-box diagonal / 20). Unused without features.
    #[arg(long)]
    pub edge_size: Option<f64>,
    /// Smallest facet angle, in degrees (0 disables; ≤ 30 guarantees termination).
    #[arg(long)]
    pub facet_angle: Option<f64>,
    /// Largest surface Delaunay ball radius (default: bounding-box diagonal / 20).
    #[arg(long)]
    pub facet_size: Option<f64>,
    /// Largest distance between a facet's circumcentre and the surface (default: diagonal / 400).
    #[arg(long)]
    pub facet_distance: Option<f64>,
    /// Largest tetrahedron circumradius / shortest edge (0 disables; default 3).
    #[arg(long)]
    pub cell_radius_edge_ratio: Option<f64>,
    /// Largest tetrahedron circumradius (default: diagonal / 20).
    #[arg(long)]
    pub cell_size: Option<f64>,
    /// Stop with an error past this many vertices.
    #[arg(long, default_value_t = 2_000_000)]
    pub max_vertices: usize,
    /// When --max-vertices stops refinement, still write the mesh reached.
    #[arg(long)]
    pub keep_partial: bool,
    /// Write a JSON report (counts, timings, quality, approximation, topology) here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Edges whose two triangles' normals differ by more than this many degrees are sharp
    /// features, kept as curves in the mesh (as CGAL's detect_features).
    #[arg(long, value_name = "DEG", default_value_t = delamesh_piecewise_smooth::DEFAULT_FEATURE_ANGLE_DEG)]
    pub feature_angle: f64,
    /// More feature curves: polylines along surface edges, CGAL's .polylines.txt format (one per
    /// line: `n x1 y1 z1 ... xn yn zn`).
    #[arg(long, value_name = "FILE", conflicts_with = "no_features")]
    pub features: Option<PathBuf>,
    /// Mesh the surface as smooth: no feature curves nor corners.
    #[arg(long)]
    pub no_features: bool,
    /// ASCII instead of binary for .vtu / .vtk.
    #[arg(long)]
    pub ascii: bool,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
    /// Mesh the domain of an oracle plugin instead of a surface file.
    #[command(flatten)]
    pub plugin: crate::plugins::PluginArgs,
    /// Optimisation after refinement.
    #[command(flatten)]
    pub optimize: crate::optimize::OptimizeArgs,
}

pub fn run(args: &MeshArgs) -> Result<()> {
    let input = match (&args.input, &args.plugin.plugin) {
        (_, Some(spec)) => return crate::plugins::mesh(args, spec),
        (Some(input), None) => input,
        (None, None) => bail!("give a closed surface file to mesh, or --plugin"),
    };
    let started = Instant::now();
    let mut times = Times::default();
    let optimize = args.optimize.options()?;
    args.optimize.check_plot_path()?;

    let t = Instant::now();
    let surface = read_surface(input, None)?.mesh;
    times.read = t.elapsed();

    let t = Instant::now();
    let features = FeatureArgs {
        enabled: !args.no_features,
        angle_deg: args.feature_angle,
        polylines: args.features.as_deref(),
    };
    let domain = Domain::new(input, &surface, &features)?;
    let oracle = domain.oracle();
    times.oracle = t.elapsed();

    let criteria = criteria(args, oracle)?;
    let options = MeshOptions {
        criteria: criteria.clone(),
        limits: Limits {
            max_vertices: args.max_vertices,
            ..Limits::default()
        },
        keep_partial: args.keep_partial,
        optimize,
    };
    let bar = progress_bar(args.quiet);
    let mut on_progress = |p: &Progress| {
        let queues: Vec<String> = p
            .pending
            .iter()
            .map(|(name, n)| format!("{name} {n}"))
            .collect();
        bar.set_message(format!(
            "{} vertices; queued: {}",
            p.vertices,
            queues.join(", ")
        ));
        bar.tick();
    };
    let outcome = mesh_domain(oracle, &options, &mut on_progress);
    bar.finish_and_clear();
    let (outcome, partial_error) = match outcome {
        Ok(o) => (o, None),
        Err(MeshError::Refinement {
            source,
            partial: Some(complex),
        }) => {
            let (complex, optimization) = delamesh_core::optimize::optimize(
                *complex,
                &[],
                oracle,
                &criteria,
                &delamesh_core::optimize::OptimizeOptions::none(),
            );
            let outcome = MeshOutcome {
                complex,
                stats: Default::default(),
                times: Default::default(),
                optimization,
            };
            (outcome, Some(source))
        }
        Err(e) => {
            return Err(anyhow::Error::new(e).context(format!("meshing {}", input.display())));
        }
    };
    times.initial_points = outcome.times.initial_points;
    times.refinement = outcome.times.refinement;
    times.complex = outcome.times.complex;
    times.optimization = outcome.times.optimization;
    if outcome.complex.tets.is_empty() {
        bail!(
            "{}: the mesh has no tetrahedron inside the surface (criteria too coarse?)",
            input.display()
        );
    }

    let t = Instant::now();
    let tet_mesh = outcome.complex.to_tet_mesh();
    let write_options = WriteOptions {
        ascii: args.ascii,
        ..WriteOptions::default()
    };
    write_tet_mesh(&args.output, &tet_mesh, &write_options)?;
    times.write = t.elapsed();

    if let Some(path) = &args.report {
        let t = Instant::now();
        let mut report = Report::new(
            args,
            &surface.positions,
            &surface.triangles,
            domain.polyhedral(),
            domain.oracle(),
            &criteria,
            &outcome,
        );
        times.quality = t.elapsed();
        times.total = started.elapsed();
        report.times_s = times.seconds();
        write_json_atomically(path, &report)?;
    }
    if let Some(path) = &args.optimize.report_plot {
        let title = format!(
            "{}: {}",
            input.file_name().unwrap_or_default().to_string_lossy(),
            criteria_title(&criteria, oracle)
        );
        crate::optimize::write_plot(path, &outcome.optimization, &title)?;
    }
    match partial_error {
        Some(e) => Err(anyhow::Error::new(e).context(format!(
            "{}: stopped early; the partial mesh was written to {}",
            input.display(),
            args.output.display()
        ))),
        None => Ok(()),
    }
}

/// The criteria in one line, for the plot's title.
fn criteria_title(criteria: &MeshCriteria, oracle: &dyn Oracle) -> String {
    let center = oracle.bounding_box().center();
    format!(
        "edge {:.3}, facet {}° / {:.3} / {:.4}, cell {} / {:.3}",
        criteria.edge_size.at(center, 1),
        criteria.facet.angle_deg,
        criteria.facet.size.at(center, 1),
        criteria.facet.distance.at(center, 1),
        criteria.cell.radius_edge_ratio,
        criteria.cell.size.at(center, 1),
    )
}

/// The CGAL-style criteria: defaults from the bounding box, overridden by the options.
pub(crate) fn criteria(args: &MeshArgs, oracle: &dyn Oracle) -> Result<MeshCriteria> {
    let mut c = MeshCriteria::default_for(&oracle.bounding_box());
    let positive = |name: &str, v: f64| -> Result<f64> {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            bail!("--{name} must be a positive number, got {v}")
        }
    };
    let non_negative = |name: &str, v: f64| -> Result<f64> {
        if v.is_finite() && v >= 0.0 {
            Ok(v)
        } else {
            bail!("--{name} must be a number ≥ 0, got {v}")
        }
    };
    if let Some(v) = args.edge_size {
        c.edge_size = Sizing::Constant(positive("edge-size", v)?);
    }
    if let Some(v) = args.facet_angle {
        c.facet.angle_deg = non_negative("facet-angle", v)?;
        if v > 30.0 {
            eprintln!("warning: --facet-angle above 30° may not terminate before --max-vertices");
        }
    }
    if let Some(v) = args.facet_size {
        c.facet.size = Sizing::Constant(positive("facet-size", v)?);
    }
    if let Some(v) = args.facet_distance {
        c.facet.distance = Sizing::Constant(positive("facet-distance", v)?);
    }
    if let Some(v) = args.cell_radius_edge_ratio {
        c.cell.radius_edge_ratio = non_negative("cell-radius-edge-ratio", v)?;
        if v > 0.0 && v < 2.0 {
            eprintln!(
                "warning: --cell-radius-edge-ratio below 2 may not terminate before --max-vertices"
            );
        }
    }
    if let Some(v) = args.cell_size {
        c.cell.size = Sizing::Constant(positive("cell-size", v)?);
    }
    Ok(c)
}

pub(crate) fn progress_bar(quiet: bool) -> ProgressBar {
    if quiet || !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::with_draw_target(None, ProgressDrawTarget::stderr());
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(Duration::from_millis(200));
    bar
}

/// Wall time of each phase.
#[derive(Default)]
struct Times {
    read: Duration,
    oracle: Duration,
    initial_points: Duration,
    refinement: Duration,
    complex: Duration,
    optimization: Duration,
    quality: Duration,
    write: Duration,
    total: Duration,
}

#[derive(Default, Serialize)]
struct TimesSeconds {
    read: f64,
    oracle: f64,
    initial_points: f64,
    refinement: f64,
    complex: f64,
    optimization: f64,
    write: f64,
    quality: f64,
    total: f64,
}

impl Times {
    fn seconds(&self) -> TimesSeconds {
        TimesSeconds {
            read: self.read.as_secs_f64(),
            oracle: self.oracle.as_secs_f64(),
            initial_points: self.initial_points.as_secs_f64(),
            refinement: self.refinement.as_secs_f64(),
            complex: self.complex.as_secs_f64(),
            optimization: self.optimization.as_secs_f64(),
            write: self.write.as_secs_f64(),
            quality: self.quality.as_secs_f64(),
            total: self.total.as_secs_f64(),
        }
    }
}

#[derive(Serialize)]
struct Report {
    input: String,
    output: String,
    criteria: CriteriaReport,
    counts: Counts,
    refinement: RefinementReport,
    times_s: TimesSeconds,
    quality: QualityReport,
    /// Quality before and after each optimisation step.
    optimization: crate::optimize::OptimizationReport,
    approximation: Approximation,
    boundary: BoundaryReport,
    /// Sharp features: absent for smooth domains.
    #[serde(skip_serializing_if = "Option::is_none")]
    features: Option<FeaturesReport>,
}

#[derive(Serialize)]
struct FeaturesReport {
    edge_size: f64,
    curves: usize,
    corners: usize,
    /// Corners without a mesh vertex.
    missing_corners: usize,
    /// Largest distance between an input corner and its mesh vertex.
    max_corner_displacement: f64,
    /// Curves with no feature edge in the mesh.
    lost_curves: usize,
    feature_edges: usize,
    /// Largest per-curve Hausdorff distance between the input polyline and the feature edges.
    max_curve_hausdorff: Option<f64>,
    per_curve: Vec<CurveReport>,
}

#[derive(Serialize)]
struct CurveReport {
    curve: u32,
    feature_edges: usize,
    hausdorff: Option<f64>,
}

impl FeaturesReport {
    /// `None` when the oracle has no sharp feature.
    fn new(oracle: &dyn Oracle, criteria: &MeshCriteria, c: &MeshComplex) -> Option<Self> {
        let curves = oracle.feature_curves();
        if curves.is_empty() && c.corners.is_empty() {
            return None;
        }
        let bbox = oracle.bounding_box();
        let f = quality::feature_fidelity(
            &curves,
            &c.points,
            &c.feature_edges,
            &c.feature_edge_curve,
            &c.corners,
            bbox.diagonal() / 2000.0,
        );
        let max_curve_hausdorff = f
            .curves
            .iter()
            .map(|c| c.hausdorff)
            .try_fold(0.0f64, |m, h| h.map(|h| m.max(h)));
        Some(FeaturesReport {
            edge_size: criteria.edge_size.at(bbox.center(), 1),
            curves: curves.len(),
            corners: f.corners,
            missing_corners: f.missing_corners,
            max_corner_displacement: f.max_corner_displacement,
            lost_curves: f.curves.iter().filter(|c| c.hausdorff.is_none()).count(),
            feature_edges: c.feature_edges.len(),
            max_curve_hausdorff,
            per_curve: f
                .curves
                .iter()
                .map(|c| CurveReport {
                    curve: c.curve,
                    feature_edges: c.edges,
                    hausdorff: c.hausdorff,
                })
                .collect(),
        })
    }
}

#[derive(Serialize)]
struct CriteriaReport {
    facet_angle_deg: f64,
    facet_size: f64,
    facet_distance: f64,
    cell_radius_edge_ratio: f64,
    cell_size: f64,
}

#[derive(Serialize)]
struct Counts {
    input_vertices: usize,
    input_triangles: usize,
    vertices: usize,
    surface_vertices: usize,
    tets: usize,
    boundary_facets: usize,
    subdomains: usize,
}

#[derive(Serialize)]
struct RefinementReport {
    insertions_per_level: Vec<usize>,
    rejections: usize,
    dropped: usize,
}

#[derive(Serialize)]
struct QualityReport {
    min_dihedral_deg: f64,
    max_dihedral_deg: f64,
    max_radius_edge: f64,
    mean_radius_edge: f64,
    inverted_tets: usize,
    /// Tets per 10° bin of their smallest dihedral angle, from 0° to 180°.
    min_dihedral_histogram: Vec<u64>,
}

#[derive(Serialize)]
struct Approximation {
    /// Largest distance from the mesh boundary to the input surface (sampled).
    hausdorff_mesh_to_input: f64,
    /// Largest distance from the input surface to the mesh boundary (sampled).
    hausdorff_input_to_mesh: f64,
    hausdorff: f64,
    volume: f64,
    input_volume: f64,
    volume_ratio: f64,
}

#[derive(Serialize)]
struct BoundaryReport {
    closed: bool,
    manifold: bool,
    euler_characteristic: i64,
    components: usize,
    input_euler_characteristic: i64,
    input_components: usize,
    /// Boundary facets whose dual Voronoi edge the surface level did not find crossing the input.
    unrestricted_facets: usize,
}

impl Report {
    fn new(
        args: &MeshArgs,
        input_points: &[DVec3],
        input_triangles: &[[u32; 3]],
        oracle: &PolyhedralOracle,
        domain: &dyn Oracle,
        criteria: &MeshCriteria,
        outcome: &MeshOutcome,
    ) -> Report {
        let c = &outcome.complex;
        let center = oracle.bounding_box().center();
        let q: TetQuality = quality::tet_quality((0..c.tets.len()).map(|t| c.tet_points(t)));
        let (to_input, to_mesh) = hausdorff(c, oracle);
        let input_topology = quality::surface_topology(input_triangles);
        let topology = quality::surface_topology(&c.facets);
        let mut subdomains = c.tet_subdomain.clone();
        subdomains.sort_unstable();
        subdomains.dedup();
        Report {
            input: args
                .input
                .as_deref()
                .map(|p| p.display().to_string())
                .unwrap_or_default(),
            output: args.output.display().to_string(),
            criteria: CriteriaReport {
                facet_angle_deg: criteria.facet.angle_deg,
                facet_size: criteria.facet.size.at(center, 1),
                facet_distance: criteria.facet.distance.at(center, 1),
                cell_radius_edge_ratio: criteria.cell.radius_edge_ratio,
                cell_size: criteria.cell.size.at(center, 1),
            },
            counts: Counts {
                input_vertices: input_points.len(),
                input_triangles: input_triangles.len(),
                vertices: c.num_vertices(),
                surface_vertices: c
                    .vertex_dimension
                    .iter()
                    .filter(|d| **d == delamesh_core::complex::VertexDimension::Surface)
                    .count(),
                tets: c.tets.len(),
                boundary_facets: c.facets.len(),
                subdomains: subdomains.len(),
            },
            refinement: RefinementReport {
                insertions_per_level: outcome.stats.insertions.clone(),
                rejections: outcome.stats.rejections,
                dropped: outcome.stats.dropped,
            },
            times_s: TimesSeconds::default(),
            quality: QualityReport {
                min_dihedral_deg: q.min_dihedral_deg,
                max_dihedral_deg: q.max_dihedral_deg,
                max_radius_edge: q.max_radius_edge,
                mean_radius_edge: q.mean_radius_edge,
                inverted_tets: q.inverted,
                min_dihedral_histogram: q.min_dihedral_histogram.counts.clone(),
            },
            optimization: crate::optimize::OptimizationReport::new(&outcome.optimization),
            approximation: Approximation {
                hausdorff_mesh_to_input: to_input,
                hausdorff_input_to_mesh: to_mesh,
                hausdorff: to_input.max(to_mesh),
                volume: q.volume,
                input_volume: oracle.domain_volume(),
                volume_ratio: q.volume / oracle.domain_volume(),
            },
            boundary: BoundaryReport {
                closed: topology.border_edges == 0,
                manifold: topology.non_manifold_edges == 0 && topology.non_manifold_vertices == 0,
                euler_characteristic: topology.euler_characteristic,
                components: topology.components,
                input_euler_characteristic: input_topology.euler_characteristic,
                input_components: input_topology.components,
                unrestricted_facets: c.facet_patch.iter().filter(|&&p| p == 0).count(),
            },
            features: FeaturesReport::new(domain, criteria, c),
        }
    }
}

/// The two sides of the sampled Hausdorff distance between the mesh boundary and the input.
fn hausdorff(c: &MeshComplex, oracle: &PolyhedralOracle) -> (f64, f64) {
    let spacing = oracle.bounding_box().diagonal() / 300.0;
    let boundary: Vec<[DVec3; 3]> = (0..c.facets.len()).map(|f| c.facet_points(f)).collect();
    let mesh_samples = quality::sample_triangles(boundary.iter().copied(), spacing);
    let to_input = quality::one_sided_distance(&mesh_samples, |p| oracle.distance_to_surface(p));
    let tree = TriangleTree::new(&boundary);
    let input_samples = quality::sample_triangles(oracle.triangles().iter().copied(), spacing);
    let to_mesh = quality::one_sided_distance(&input_samples, |p| tree.distance(p, &boundary));
    (to_input, to_mesh)
}

/// Written like the meshes (atomically, same permissions): readers never see half a report.
fn write_json_atomically(path: &Path, value: &impl Serialize) -> Result<()> {
    delamesh_formats::write_document(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })?;
    Ok(())
}
