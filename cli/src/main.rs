//! `delamesh`: quality tetrahedral meshing from the command line.

mod convert;
mod info;

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
    /// Convert a mesh from one file format to another
    Convert(convert::ConvertArgs),
    /// Describe a mesh: counts, bounding box, patches, closedness, manifoldness, genus
    Info(info::InfoArgs),
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Convert(args) => convert::run(args),
        Command::Info(args) => info::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
