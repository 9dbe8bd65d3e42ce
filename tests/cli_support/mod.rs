//! What the end-to-end tests of the command-line tool share: the binary, repository paths and
//! criteria coarse enough that a run takes a fraction of a second.

#![allow(dead_code)] // each test binary uses a subset

use assert_cmd::Command;
use std::path::{Path, PathBuf};

/// The `delamesh` binary built for this test run.
pub fn delamesh() -> Command {
    Command::new(env!("CARGO_BIN_EXE_delamesh"))
}

/// A path in the repository.
pub fn repo(path: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// A bundled model (`models/`).
pub fn model(name: &str) -> PathBuf {
    repo("models").join(name)
}

/// A test input with sharp features (`tests/data/features/`).
pub fn feature_shape(name: &str) -> PathBuf {
    repo("tests/data/features").join(name)
}

/// Coarse meshing criteria for `delamesh mesh`.
pub const COARSE: [&str; 6] = [
    "--facet-size",
    "0.3",
    "--facet-distance",
    "0.02",
    "--cell-size",
    "0.4",
];

/// A test input file (`tests/data/`).
pub fn test_data(name: &str) -> PathBuf {
    repo("tests/data").join(name)
}
