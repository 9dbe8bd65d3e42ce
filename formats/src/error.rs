//! Errors: every failure names the file and, where known, the line or byte offset of the problem.

use delamesh_core::mesh::MeshError;
use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a file a problem was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
    /// Nowhere more precise than the file.
    Unknown,
    /// 1-based line of a text file.
    Line(usize),
    /// 0-based byte offset of a binary file.
    Byte(u64),
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Location::Unknown => Ok(()),
            Location::Line(l) => write!(f, "line {l}: "),
            Location::Byte(b) => write!(f, "byte {b}: "),
        }
    }
}

/// What went wrong, without the file name (see [`Error`]).
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum Problem {
    #[error("{0}")]
    Io(#[from] std::io::Error),
    #[error("{at}{message}")]
    Syntax { at: Location, message: String },
    #[error("{0}")]
    Unsupported(String),
    #[error("invalid mesh: {0}")]
    Invalid(#[from] MeshError),
}

impl Problem {
    pub(crate) fn syntax(at: Location, message: impl Into<String>) -> Problem {
        Problem::Syntax {
            at,
            message: message.into(),
        }
    }

    pub(crate) fn at_line(line: usize, message: impl Into<String>) -> Problem {
        Problem::syntax(Location::Line(line), message)
    }

    pub(crate) fn at_byte(byte: u64, message: impl Into<String>) -> Problem {
        Problem::syntax(Location::Byte(byte), message)
    }

    pub(crate) fn bad(message: impl Into<String>) -> Problem {
        Problem::syntax(Location::Unknown, message)
    }
}

/// A read or write failure of one file.
#[derive(Debug, thiserror::Error)]
#[error("{}: {problem}", path.display())]
pub struct Error {
    /// The file.
    pub path: PathBuf,
    /// What is wrong with it.
    pub problem: Problem,
}

impl Error {
    pub(crate) fn new(path: &Path, problem: impl Into<Problem>) -> Error {
        Error {
            path: path.to_path_buf(),
            problem: problem.into(),
        }
    }
}

/// The result of reading or writing a file.
pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Runs a parsing library, turning its panics into errors: vtkio 0.7.0-rc2 slices appended data
/// without bounds checks and tobj indexes texture and normal arrays unchecked (both found by
/// fuzzing), so a malformed file can make them panic. The panic hook is silenced for this thread
/// meanwhile, so the user sees one error line instead of a backtrace; panics of other threads
/// still reach the previous hook.
pub(crate) fn contain_panics<T>(
    parse: impl FnOnce() -> T + std::panic::UnwindSafe,
) -> Result<T, String> {
    use std::sync::{Arc, Mutex};
    static HOOK_SWAP: Mutex<()> = Mutex::new(());
    let _one_at_a_time = HOOK_SWAP
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    let previous = Arc::new(std::panic::take_hook());
    let forward = Arc::clone(&previous);
    let me = std::thread::current().id();
    std::panic::set_hook(Box::new(move |info| {
        if std::thread::current().id() != me {
            forward(info);
        }
    }));
    let result = std::panic::catch_unwind(parse);
    drop(std::panic::take_hook());
    match Arc::try_unwrap(previous) {
        Ok(hook) => std::panic::set_hook(hook),
        Err(shared) => std::panic::set_hook(Box::new(move |info| shared(info))),
    }
    result.map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into())
    })
}
