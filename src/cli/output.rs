//! Writing to standard output: a reader that went away (`delamesh info part.stl | head -0`) ends
//! the command quietly instead of as a panic or an error. A leaf module: the subcommands that
//! print depend on it, not on the dispatch in `cli` that depends on them.

/// `println!` that returns the write's error instead of panicking, so a closed stdout
/// (`delamesh info part.stl | head -0`) ends the command quietly (see [`closed_stdout`]).
macro_rules! outln {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
    }};
}
pub(crate) use outln;

/// Whether the command failed only because the reader of its standard output went away: nobody
/// is left to tell, so it is not an error.
pub(crate) fn closed_stdout(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        c.downcast_ref::<std::io::Error>()
            .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
    })
}
