//! The `delamesh` binary: the command line (src/cli/) over the library's pipeline.

mod cli;

fn main() -> std::process::ExitCode {
    cli::main()
}
