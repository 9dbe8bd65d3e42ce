//! Fuzzes the stl reader: any input must give a mesh or an error, never a panic or a hang.
#![no_main]

use delamesh_formats::{Format, read_bytes};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = read_bytes(data, Format::Stl, None);
});
