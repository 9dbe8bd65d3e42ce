//! `delamesh`: quality tetrahedral meshing from the command line.

mod conform2d;
mod mesh2d;

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
    /// Subdivide a planar constraint until it is Delaunay-admissible (Pébay) and triangulate it.
    Conform2d(conform2d::Args),
    /// Quality triangle mesh of a planar straight-line graph.
    Mesh2d(mesh2d::Args),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Conform2d(args) => conform2d::run(args),
        Command::Mesh2d(args) => mesh2d::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
