//! The C header plugin authors include is generated from the Rust ABI definition; this test
//! regenerates it with cbindgen and fails when the committed copy is stale.
//! Refresh it with `DELAMESH_BLESS=1 cargo test --test plugins_header`.

use std::path::Path;

#[test]
fn c_header_matches_the_rust_abi() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let config = cbindgen::Config::from_file(root.join("include/cbindgen.toml"))
        .expect("include/cbindgen.toml parses");
    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(root.join("core/src/plugin/abi.rs"))
        .generate()
        .expect("cbindgen understands core/src/plugin/abi.rs");
    let mut generated = Vec::new();
    bindings.write(&mut generated);
    let generated = String::from_utf8(generated).expect("cbindgen writes UTF-8");
    let header = root.join("include/delamesh_plugin.h");
    if std::env::var_os("DELAMESH_BLESS").is_some() {
        std::fs::write(&header, &generated).expect("include/delamesh_plugin.h is writable");
    }
    let committed = std::fs::read_to_string(&header).unwrap_or_default();
    assert!(
        committed == generated,
        "include/delamesh_plugin.h is stale: run `DELAMESH_BLESS=1 cargo test --test plugins_header` and commit it"
    );
}
