//! The `delamesh` binary; everything lives in the `delamesh-cli` library.

fn main() -> std::process::ExitCode {
    delamesh_cli::main()
}
