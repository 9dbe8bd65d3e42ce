//! Fuzzes the `x y z` point reader of `delamesh delaunay`: any input must give points or an error.
#![no_main]

use delamesh_formats::parse_xyz;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = parse_xyz(data);
});
