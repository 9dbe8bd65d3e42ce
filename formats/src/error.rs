//! Errors: every failure names the file and, where known, the line or byte offset of the problem.

use delamesh_core::mesh::MeshError;
use std::fmt;
use std::path::{Path, PathBuf};

/// Where in a file a problem was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Location {
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
    pub path: PathBuf,
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

pub type Result<T, E = Error> = std::result::Result<T, E>;
