//! The `delamesh` command line: argument parsing and one module per subcommand, each a thin shell
//! over the library (`delamesh mesh` is the library's `Mesher`). Built only with the `cli` feature.
//!
//! Exit codes: 0 success, 1 the work failed (bad input, I/O, refinement guard), 2 bad usage.

mod conform2d;
mod convert;
mod delaunay;
mod image;
mod info;
mod mesh;
mod mesh2d;
mod optimize;
mod output;
mod plugins;
mod sizing;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "delamesh",
    version,
    about = "Quality tetrahedral meshes by Delaunay refinement"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Mesh the volume bounded by a closed surface.
    Mesh(Box<mesh::MeshArgs>),
    /// Delaunay tetrahedralisation of a point set.
    Delaunay(delaunay::DelaunayArgs),
    /// Convert a mesh from one file format to another
    Convert(convert::ConvertArgs),
    /// Describe a mesh (counts, bounding box, patches, closedness, manifoldness, genus) or a 3D
    /// image (grid, voxel size, values, labels)
    Info(info::InfoArgs),
    /// Subdivide a planar constraint until it is Delaunay-admissible (Pébay) and triangulate it.
    Conform2d(conform2d::Args),
    /// Quality triangle mesh of a planar straight-line graph.
    Mesh2d(mesh2d::Args),
    /// List built-in and installed oracle plugins, or check one with --plugin
    Plugins(plugins::PluginsArgs),
}

/// Parses the process arguments, runs the subcommand and reports its error on stderr.
pub fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Mesh(args) => mesh::run(&args),
        Command::Delaunay(args) => delaunay::run(&args),
        Command::Convert(args) => convert::run(args),
        Command::Info(args) => info::run(args),
        Command::Conform2d(args) => conform2d::run(&args),
        Command::Mesh2d(args) => mesh2d::run(&args),
        Command::Plugins(args) => plugins::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) if output::closed_stdout(&e) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
