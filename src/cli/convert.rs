//! `delamesh convert IN OUT`: any readable mesh to any writable format.

use anyhow::Result;
use delamesh_formats::{AnyMesh, Format, WriteOptions};
use std::path::PathBuf;

#[derive(clap::Args)]
pub struct ConvertArgs {
    /// Mesh to read (stl, obj, ply, off, gltf/glb, vtk, vtu, vtp, mesh)
    input: PathBuf,
    /// File to write (vtu, vtk, mesh, msh, ply, obj, stl, off)
    output: PathBuf,
    /// Output format, when the extension does not say it
    #[arg(long, value_name = "F")]
    format: Option<Format>,
    /// Input format, when the extension does not say it
    #[arg(long, value_name = "F")]
    input_format: Option<Format>,
    /// ASCII instead of binary .vtu / .vtk
    #[arg(long)]
    ascii: bool,
    /// Gmsh 2.2 instead of 4.1
    #[arg(long)]
    msh22: bool,
}

pub fn run(args: ConvertArgs) -> Result<()> {
    let read = delamesh_formats::read(&args.input, args.input_format)?;
    for w in &read.warnings {
        eprintln!("warning: {}: {w}", args.input.display());
    }
    let options = WriteOptions {
        format: args.format,
        ascii: args.ascii,
        msh22: args.msh22,
    };
    let summary = match &read.mesh {
        AnyMesh::Surface(s) => {
            delamesh_formats::write_surface(&args.output, s, &options)?;
            format!(
                "{} vertices, {} triangles",
                s.positions.len(),
                s.triangles.len()
            )
        }
        AnyMesh::Volume(v) => {
            delamesh_formats::write_tet_mesh(&args.output, v, &options)?;
            let out_format = args.format.or_else(|| Format::from_path(&args.output));
            if !v.tets.is_empty() && out_format.is_some_and(|f| !f.is_volume()) {
                eprintln!(
                    "note: {} holds surfaces only: wrote the boundary triangles",
                    args.output.display()
                );
            }
            format!(
                "{} vertices, {} tetrahedra, {} boundary triangles",
                v.positions.len(),
                v.tets.len(),
                v.boundary.len()
            )
        }
    };
    let welded = match read.welded_vertices {
        0 => String::new(),
        n => format!(" ({n} duplicate vertices welded)"),
    };
    eprintln!(
        "{} → {}: {summary}{welded}",
        args.input.display(),
        args.output.display()
    );
    Ok(())
}
