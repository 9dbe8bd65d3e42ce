//! `delamesh delaunay`: the Delaunay tetrahedralisation of a point set, to try the kernel alone
//! (the library's [`delamesh::delaunay`]; this module reads and writes).

use anyhow::Result;
use clap::Args;
use delamesh_formats::{Format, WriteOptions};
use std::path::PathBuf;
use std::time::Instant;

#[derive(Args)]
pub struct DelaunayArgs {
    /// Points: `x y z` lines (.xyz, .pts, .txt) or any mesh file whose vertices are taken.
    input: PathBuf,
    /// Output tet mesh (.vtu, .vtk, .mesh, .msh); the convex hull is written as boundary triangles.
    #[arg(short, long)]
    output: PathBuf,
    /// Read the input as this format instead of guessing from its extension.
    #[arg(long)]
    format: Option<Format>,
    /// Write ASCII instead of binary where the format has both.
    #[arg(long)]
    ascii: bool,
}

pub fn run(args: &DelaunayArgs) -> Result<()> {
    delamesh_formats::check_mesh_output(&args.output, None)?;
    let points = delamesh_formats::read_points(&args.input, args.format)?;
    let start = Instant::now();
    let mesh = delamesh::delaunay(&args.input.display().to_string(), &points)?.mesh;
    let elapsed = start.elapsed();
    eprintln!(
        "{} points ({} distinct) -> {} tets, {} hull triangles in {:.3} s",
        points.len(),
        mesh.positions.len(),
        mesh.tets.len(),
        mesh.boundary.len(),
        elapsed.as_secs_f64()
    );
    let options = WriteOptions {
        ascii: args.ascii,
        ..WriteOptions::default()
    };
    delamesh_formats::write_tet_mesh(&args.output, &mesh, &options)?;
    Ok(())
}
