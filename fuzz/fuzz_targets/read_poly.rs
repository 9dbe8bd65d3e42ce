//! Fuzzes the `.poly` reader and the planar-graph validation: any input must give a graph or an
//! error, never a panic, a hang or an allocation sized by an announced count.
#![no_main]

use delamesh_formats::poly::parse_poly;
use libfuzzer_sys::fuzz_target;
use std::path::{Path, PathBuf};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let node = || Ok((String::new(), PathBuf::from("fuzz.node")));
    if let Ok(pslg) = parse_poly(&text, Path::new("fuzz.poly"), node) {
        let _ = pslg.validate();
    }
});
