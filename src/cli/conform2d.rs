//! `delamesh conform2d`: Pébay's a-priori subdivision of a planar constraint so that it is
//! Delaunay-admissible, and the Delaunay triangulation of the result.

use super::output::outln;
use anyhow::{Context, Result};
use delamesh_core::mesh::PatchId;
use delamesh_core::mesh2d::{Algorithm, ConformOptions, conform};
use delamesh_core::triangulation::Triangulation;
use std::path::PathBuf;

#[derive(Clone, Copy, clap::ValueEnum)]
pub enum AlgorithmArg {
    /// Algorithm 3.1: clean every acute angle met by a non-admissible edge.
    #[value(name = "3.1")]
    Brute,
    /// Algorithm 3.1′: clean only at nodes of more than two edges.
    #[value(name = "3.1p")]
    BruteLargeNodes,
    /// Algorithm 3.2: clean only at closed nodes.
    #[value(name = "3.2")]
    ClosedNodes,
}

#[derive(clap::Args)]
pub struct Args {
    /// Input planar straight-line graph: Triangle `.poly`, or z = 0 polylines from OBJ `l` lines or
    /// VTK line cells.
    pub input: PathBuf,
    /// Output (`.vtu`, `.vtk`...): the Delaunay triangles of the convex hull in the z = 0 plane and
    /// the subdivided constraint as lines.
    #[arg(short, long)]
    pub output: PathBuf,
    #[arg(long, value_enum, default_value = "3.2")]
    pub algorithm: AlgorithmArg,
    /// Give up after this many projection / cleaning steps.
    #[arg(long, default_value_t = 100_000)]
    pub max_iterations: usize,
}

pub fn run(args: &Args) -> Result<()> {
    delamesh_formats::check_mesh_output(&args.output, None)?;
    let pslg = delamesh_formats::pslg::read_pslg(&args.input)?;
    let options = ConformOptions {
        algorithm: match args.algorithm {
            AlgorithmArg::Brute => Algorithm::Brute,
            AlgorithmArg::BruteLargeNodes => Algorithm::BruteLargeNodes,
            AlgorithmArg::ClosedNodes => Algorithm::ClosedNodes,
        },
        max_iterations: args.max_iterations,
        ..ConformOptions::default()
    };
    let out =
        conform(&pslg, &options).with_context(|| format!("conforming {}", args.input.display()))?;
    let t = &out.triangulation;
    // Triangulation vertices are numbered in insertion order; write points in input order.
    let mut index = vec![0u32; out.points.len()];
    for (i, v) in out.vertex_of_point.iter().enumerate() {
        index[v.0 as usize] = i as u32;
    }
    let triangles: Vec<[u32; 3]> = t
        .finite_cells()
        .map(|c| t.cell(c).map(|v| index[v.0 as usize]))
        .collect();
    let patches = vec![PatchId(0); triangles.len()];
    super::mesh2d::write_planar_mesh(
        &args.output,
        &out.points,
        &triangles,
        &patches,
        &out.segments,
        &out.segment_origins,
    )?;
    outln!(
        "{} points ({} added), {} constraint edges, {} steps, {} triangles -> {}",
        out.points.len(),
        out.points.len() - pslg.points.len(),
        out.segments.len(),
        out.iterations,
        triangles.len(),
        args.output.display()
    )?;
    Ok(())
}
