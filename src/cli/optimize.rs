//! The optimisation options of `delamesh mesh`, their section of the JSON report, and the
//! before/after histogram of smallest dihedral angles (`--report-plot`).

use anyhow::{Context, Result, bail};
use clap::Args;
use delamesh_core::optimize::{Flips, OptimizeOptions, OptimizeReport};
use plotters::prelude::*;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// Mesh optimisation after refinement (CGAL's optimisers: perturbation and exudation by
/// default, smoothing on request).
#[derive(Args, Debug, Default)]
pub struct OptimizeArgs {
    /// No sliver perturbation (by default the vertices of the worst tets move: inside, along
    /// the surface and along feature curves).
    #[arg(long)]
    pub no_perturb: bool,
    /// No sliver exudation (by default the weights of the worst tets' vertices are pumped).
    #[arg(long)]
    pub no_exude: bool,
    /// ODT smoothing of the interior vertices before the sliver steps.
    #[arg(long)]
    pub odt: bool,
    /// Lloyd smoothing of the interior vertices before the sliver steps.
    #[arg(long)]
    pub lloyd: bool,
    /// After the sliver steps, replace every tet below the sliver bound (18°), not only the
    /// slivers they leave (below 16°, the default), by edge removals, 2-3 flips, interior
    /// vertex moves and interior edge splits (the mesh is then no longer Delaunay there).
    /// With --preserve-surface they replace perturbation and exudation (on unless --no-perturb
    /// and --no-exude are both given).
    #[arg(long, conflicts_with = "no_flip")]
    pub flip: bool,
    /// No flips after the sliver steps: the mesh stays the regular triangulation they leave,
    /// slivers included.
    #[arg(long)]
    pub no_flip: bool,
    /// Bound the whole optimisation phase to this many seconds (the result then depends on
    /// the machine's speed).
    #[arg(long, value_name = "S")]
    pub optimize_time: Option<f64>,
    /// Draw the histogram of smallest dihedral angles before and after optimisation (SVG).
    #[arg(long, value_name = "FILE.svg")]
    pub report_plot: Option<PathBuf>,
}

impl OptimizeArgs {
    /// The core options, or a one-line error naming the bad option.
    pub fn options(&self) -> Result<OptimizeOptions> {
        let time_limit = match self.optimize_time {
            None => None,
            Some(s) if s.is_finite() && s > 0.0 && s < 1e9 => Some(Duration::from_secs_f64(s)),
            Some(s) => bail!("--optimize-time {s}: expected a positive number of seconds"),
        };
        Ok(OptimizeOptions {
            lloyd: self.lloyd,
            odt: self.odt,
            perturb: !self.no_perturb,
            exude: !self.no_exude,
            flip: match (self.flip, self.no_flip) {
                (true, _) => Flips::All,
                (_, true) => Flips::Off,
                _ => Flips::Slivers,
            },
            time_limit,
            ..OptimizeOptions::default()
        })
    }

    /// Checks the plot path before meshing, so a bad one costs no meshing time.
    pub fn check_plot_path(&self) -> Result<()> {
        let Some(path) = &self.report_plot else {
            return Ok(());
        };
        let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("");
        if !ext.eq_ignore_ascii_case("svg") {
            bail!(
                "--report-plot {}: only SVG plots are written (give a .svg file)",
                path.display()
            );
        }
        Ok(())
    }
}

/// Draws the smallest-dihedral histograms before and after optimisation into the SVG `path`,
/// with `title` (the criteria) on top. Written through a temporary file and a rename.
pub fn write_plot(path: &Path, report: &OptimizeReport, title: &str) -> Result<()> {
    let mut svg = String::new();
    draw(&mut svg, report, title).map_err(|e| anyhow::anyhow!("{e}"))?;
    delamesh_formats::write_document(path, |w| {
        w.write_all(svg.as_bytes())?;
        Ok(())
    })
    .with_context(|| format!("writing {}", path.display()))
}

fn draw(
    svg: &mut String,
    report: &OptimizeReport,
    title: &str,
) -> std::result::Result<(), Box<dyn std::error::Error>> {
    let before = &report.before.histogram;
    let after = &report.after().histogram;
    let top = before
        .counts
        .iter()
        .chain(&after.counts)
        .copied()
        .max()
        .unwrap_or(1);
    let root = SVGBackend::with_string(svg, (900, 520)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 16))
        .margin(12)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(before.lo..before.hi, 0u64..top + top / 20 + 1)?;
    chart
        .configure_mesh()
        .x_desc("smallest dihedral angle of the tetrahedron (degrees)")
        .y_desc("tetrahedra")
        .draw()?;
    let width = (before.hi - before.lo) / before.counts.len() as f64;
    for (h, color, name) in [
        (
            before,
            RED.mix(0.45),
            format!("refined: min {:.1}°", report.before.min_dihedral_deg),
        ),
        (
            after,
            BLUE.mix(0.45),
            format!("optimised: min {:.1}°", report.after().min_dihedral_deg),
        ),
    ] {
        chart
            .draw_series(h.counts.iter().enumerate().map(|(i, &n)| {
                let x = h.lo + i as f64 * width;
                Rectangle::new([(x, 0), (x + width, n)], color.filled())
            }))?
            .label(name)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 10, y + 5)], color.filled()));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()?;
    root.present()?;
    Ok(())
}
