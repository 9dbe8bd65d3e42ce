//! Readers and writers of mesh files: thin adapters over maintained crates.
pub mod poly;
