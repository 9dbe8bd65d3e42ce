//! `delamesh`: quality tetrahedral meshing from the command line.
//!
//! Exit codes: 0 success, 1 the work failed (bad input, I/O, refinement guard), 2 bad usage.

mod delaunay;

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
    /// Delaunay tetrahedralisation of a point set.
    Delaunay(delaunay::DelaunayArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match &cli.command {
        Command::Delaunay(args) => delaunay::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("delamesh: error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
