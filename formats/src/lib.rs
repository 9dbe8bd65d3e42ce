//! Readers and writers of mesh files: thin adapters over maintained crates.
