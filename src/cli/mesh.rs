//! `delamesh mesh`: a quality tetrahedral mesh of the volume bounded by a closed surface, or of a
//! plugin's domain. The work is the library's [`Mesher`]; this module maps flags to
//! [`MeshSettings`], shows progress and writes the report.

use anyhow::{Result, bail};
use clap::Args;
use delamesh::{Error, FeatureSettings, MeshSettings, Meshed, Mesher, WriteOptions};
use delamesh_core::refine::Progress;
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use serde::Serialize;
use std::io::IsTerminal;
use std::path::{Path, PathBuf};
use std::time::Duration;

#[derive(Args, Debug)]
pub struct MeshArgs {
    /// Closed triangle surface bounding the volume (STL, OFF, OBJ, PLY, glTF...), or a segmented
    /// 3D image (.inr .nii .vti .nrrd .nhdr, optionally .gz): one subdomain per label.
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
    /// Smallest protecting ball radius (CGAL's edge_min_size): sharp features closer than this
    /// are no longer split, but still meshed (default: bounding-box diagonal / 1000).
    #[arg(long)]
    pub edge_min_size: Option<f64>,
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
    /// Stop with an error past this many vertices [default: 50 times the count the criteria
    /// predict for the bounding box, between 100,000 and 2,000,000]
    #[arg(long)]
    pub max_vertices: Option<usize>,
    /// Stop with an error when meshing takes longer than this many seconds.
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub time_limit: Option<f64>,
    /// When --max-vertices or --time-limit stops refinement, still write the mesh reached.
    #[arg(long)]
    pub keep_partial: bool,
    /// Skip the refinement that makes the boundary a 2-manifold with the input's topology
    /// (faster; the boundary may then have edges in four facets or pinched vertices).
    #[arg(long)]
    pub non_manifold: bool,
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
    /// Refuse a surface that does not bound a volume as given (open, non-manifold, inconsistently
    /// oriented, self-intersecting, with degenerate triangles) instead of repairing it and meshing
    /// the region where its winding number is at least one.
    #[arg(long)]
    pub strict: bool,
    /// Read the input (OBJ, OFF, PLY polygons) as the control mesh of a subdivision surface and
    /// mesh its exact limit surface: loop, catmull-clark, or auto (Loop for triangles only).
    /// Group borders and --features polylines along control edges are creases.
    #[arg(long, value_name = "SCHEME")]
    pub subdivision: Option<String>,
    /// With --subdivision: control edges whose faces' normals differ by more than this many
    /// degrees are creases too.
    #[arg(long, value_name = "DEG", requires = "subdivision")]
    pub crease_angle: Option<f64>,
    /// Keep the input surface exactly: every input vertex is a mesh vertex and every input triangle
    /// a union of boundary facets (Steiner points on input edges and triangles where the Delaunay
    /// tetrahedralisation misses them). A surface that does not bound a volume as given is
    /// repaired as without the option, and the boundary of its winding-number domain is kept:
    /// its triangles cut where they cross, buried parts dropped (--strict refuses it instead).
    /// With --cell-radius-edge-ratio / --cell-size the volume is then refined.
    #[arg(long)]
    pub preserve_surface: bool,
    /// With --preserve-surface: first retriangulate each planar region of a patch (triangles
    /// coplanar to within 1e-8 of the bounding-box diagonal) by Lawson flips, as TetGen does by
    /// default (its -M turns that off). The surface and its vertices are kept, the input's
    /// triangles are not: a fan of slivers on a planar face then costs no slivers in the volume.
    #[arg(long, requires = "preserve_surface")]
    pub merge_coplanar: bool,
    /// ASCII instead of binary for .vtu / .vtk.
    #[arg(long)]
    pub ascii: bool,
    /// No progress bar.
    #[arg(short, long)]
    pub quiet: bool,
    /// Mesh the domain of an oracle plugin instead of a surface file.
    #[command(flatten)]
    pub plugin: crate::cli::plugins::PluginArgs,
    /// Options of segmented and gray-level 3D images (.inr .nii .vti .nrrd .nhdr, optionally .gz).
    #[command(flatten)]
    pub image: crate::cli::image::ImageArgs,
    /// Optimisation after refinement.
    #[command(flatten)]
    pub optimize: crate::cli::optimize::OptimizeArgs,
    /// Sizing fields, per-subdomain and per-patch sizes, gradation.
    #[command(flatten)]
    pub sizing: crate::cli::sizing::SizingArgs,
}

impl MeshArgs {
    /// The library's settings for these flags (one line per option).
    fn settings(&self) -> Result<MeshSettings> {
        Ok(MeshSettings {
            edge_size: self.edge_size,
            edge_min_size: self.edge_min_size,
            facet_angle: self.facet_angle,
            facet_size: self.facet_size,
            facet_distance: self.facet_distance,
            cell_radius_edge_ratio: self.cell_radius_edge_ratio,
            cell_size: self.cell_size,
            max_vertices: self.max_vertices,
            time_limit: match self.time_limit {
                None => None,
                Some(t) if t.is_finite() && t > 0.0 && t < 1e9 => Some(Duration::from_secs_f64(t)),
                Some(t) => bail!("--time-limit must be a positive number of seconds, got {t}"),
            },
            keep_partial: self.keep_partial,
            non_manifold: self.non_manifold,
            features: FeatureSettings {
                enabled: !self.no_features,
                angle_deg: self.feature_angle,
                polylines: self.features.clone(),
            },
            image: self.image.settings()?,
            strict: self.strict,
            subdivision: self.subdivision_options()?,
            optimize: self.optimize.options()?,
            sizing: self.sizing.settings()?,
            preserve_surface: self.preserve_surface,
            merge_coplanar: self.merge_coplanar,
        })
    }
}

impl MeshArgs {
    fn subdivision_options(&self) -> Result<Option<delamesh::subdivision::SubdivisionOptions>> {
        let Some(name) = &self.subdivision else {
            return Ok(None);
        };
        let scheme = match name.as_str() {
            "auto" => None,
            other => Some(
                other
                    .parse()
                    .map_err(|e: String| anyhow::anyhow!("--subdivision: {e}"))?,
            ),
        };
        Ok(Some(delamesh::subdivision::SubdivisionOptions {
            scheme,
            group_creases: !self.no_features,
            crease_angle_deg: self.crease_angle,
        }))
    }
}

pub fn run(args: &MeshArgs) -> Result<()> {
    // Every output is checked before any work: a typo in a folder name costs nothing.
    delamesh_formats::check_mesh_output(&args.output, None)?;
    if let Some(report) = &args.report {
        delamesh_formats::check_document_output(report)?;
    }
    if args.plugin.plugin.is_some() && args.optimize.report_plot.is_some() {
        bail!("--report-plot is drawn for an input surface and is not available with --plugin");
    }
    args.optimize.check_plot_path()?;
    let settings = args.settings()?;
    settings.validate()?;
    for warning in settings.warnings() {
        eprintln!("warning: {warning}");
    }
    let bar = progress_bar(args.quiet);
    let mut mesher = Mesher::new(settings).on_progress(|p| show_progress(&bar, p));
    let meshed = match (&args.input, &args.plugin.plugin) {
        (_, Some(spec)) => mesher.mesh_plugin(spec, &args.plugin.plugin_config),
        (Some(input), None) => mesher.mesh_file(input),
        (None, None) => bail!("give a closed surface file to mesh, or --plugin"),
    };
    bar.finish_and_clear();
    let mut meshed = meshed.map_err(with_hint)?;
    let repairs = meshed.domain().repairs();
    if !repairs.is_empty() {
        eprintln!(
            "warning: {}: repaired: {}",
            meshed.name(),
            repairs.join("; ")
        );
    }
    for w in &meshed.warnings {
        eprintln!("warning: {}: {w}", meshed.name());
    }
    let write_options = WriteOptions {
        ascii: args.ascii,
        ..WriteOptions::default()
    };
    meshed.write(&args.output, &write_options)?;
    if let Some(path) = &args.report
        && let Err(e) = write_report(path, &mut meshed)
    {
        // One run, one result: a mesh without the report asked for is not left behind.
        let _ = std::fs::remove_file(&args.output);
        return Err(e.context(format!("{} was not kept", args.output.display())));
    }
    if let Some(path) = &args.optimize.report_plot {
        let title = format!("{}: {}", meshed.name(), criteria_title(&meshed));
        crate::cli::optimize::write_plot(path, &meshed.optimization, &title)?;
    }
    match meshed.stopped.take() {
        Some(e) => Err(anyhow::Error::new(e).context(format!(
            "{}: stopped early; the partial mesh was written to {}",
            meshed.name(),
            args.output.display()
        ))),
        None => Ok(()),
    }
}

/// The criteria in one line, for the plot's title.
fn criteria_title(meshed: &Meshed) -> String {
    let c = &meshed.criteria;
    let center = meshed.domain().oracle().bounding_box().center();
    format!(
        "edge {:.3}, facet {}° / {:.3} / {:.4}, cell {} / {:.3}",
        c.edge_size.at(center, 1),
        c.facet.angle_deg,
        c.facet.size.at(center, 1),
        c.facet.distance.at(center, 1),
        c.cell.radius_edge_ratio,
        c.cell.size.at(center, 1),
    )
}

/// Points an unmeshable surface's error at `delamesh info`, which diagnoses it in full.
fn with_hint(e: Error) -> anyhow::Error {
    match &e {
        Error::Unmeshable { name, .. } | Error::FeaturePolylines { name, .. } => {
            let hint = format!("\n(run `delamesh info {name}` for a full diagnosis)");
            anyhow::anyhow!("{e}{hint}")
        }
        _ => e.into(),
    }
}

fn show_progress(bar: &ProgressBar, p: &Progress) {
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
}

fn progress_bar(quiet: bool) -> ProgressBar {
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

/// The library's report as JSON, written like the meshes (atomically, same permissions): readers
/// never see half a report.
fn write_report(path: &Path, meshed: &mut Meshed) -> Result<()> {
    write_json_atomically(path, &meshed.report())
}

fn write_json_atomically(path: &Path, value: &impl Serialize) -> Result<()> {
    delamesh_formats::write_document(path, |w| {
        serde_json::to_writer_pretty(&mut *w, value)?;
        w.write_all(b"\n")
    })?;
    Ok(())
}
