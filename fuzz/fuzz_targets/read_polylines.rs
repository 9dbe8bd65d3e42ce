//! Fuzzes the `.polylines.txt` reader of `--features`: any input must give polylines or an error.
#![no_main]

use delamesh_piecewise_smooth::parse_polylines;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let _ = parse_polylines(&String::from_utf8_lossy(data));
});
