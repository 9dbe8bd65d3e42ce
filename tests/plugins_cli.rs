//! `delamesh plugins` and `--plugin` on the command line: listing, lookup in
//! DELAMESH_PLUGIN_PATH, and broken plugins turned into a clean non-zero exit naming the plugin.

mod plugins_support;
use plugins_support as common;

use assert_cmd::Command;
use std::path::Path;

fn delamesh() -> Command {
    let mut command = Command::new(common::delamesh_bin());
    // Without backtraces, so that a host frame in stderr can only come from a panic of the host.
    command
        .env_remove("DELAMESH_PLUGIN_PATH")
        .env("RUST_BACKTRACE", "0");
    command
}

fn stdout_of(command: &mut Command) -> String {
    let output = command.output().expect("delamesh runs");
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// Runs a command that must fail cleanly (exit code 1, not a signal or a panic's 101) and returns
/// its stderr.
fn failure_of(command: &mut Command) -> String {
    let output = command.output().expect("delamesh runs");
    assert_eq!(output.status.code(), Some(1), "{output:?}");
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn lists_built_in_and_installed_plugins_with_versions() {
    let dir = tempfile::tempdir().expect("temporary directory");
    let listing = stdout_of(delamesh().arg("plugins"));
    assert!(
        listing.contains("polyhedral") && listing.contains(env!("CARGO_PKG_VERSION")),
        "{listing}"
    );
    for library in [
        common::implicit_plugin(),
        common::c_plugin("examples/plugins/c-sphere/sphere.c", &[]),
    ] {
        let name = library.file_name().expect("a file name");
        std::fs::copy(&library, dir.path().join(name)).expect("copy the plugin");
    }
    std::fs::write(dir.path().join("libnot_a_plugin.so"), b"garbage").expect("write");
    let listing = stdout_of(
        delamesh()
            .arg("plugins")
            .env("DELAMESH_PLUGIN_PATH", dir.path()),
    );
    let line = |name: &str| {
        listing
            .lines()
            .find(|l| l.trim_start().starts_with(name))
            .unwrap_or_default()
            .to_string()
    };
    assert!(
        line("implicit").contains(env!("CARGO_PKG_VERSION")) && line("implicit").contains("ABI v1"),
        "{listing}"
    );
    assert!(line("c-sphere").contains("1.0.0"), "{listing}");
    assert!(
        listing.contains("(unusable)") && listing.contains("libnot_a_plugin.so"),
        "{listing}"
    );
}

#[test]
fn plugins_are_found_by_name_in_the_plugin_path() {
    let library = common::implicit_plugin();
    let dir = library.parent().expect("a directory");
    let report = stdout_of(
        delamesh()
            .args([
                "plugins",
                "--plugin",
                "implicit",
                "--plugin-config",
                "shape=torus",
            ])
            .env("DELAMESH_PLUGIN_PATH", dir),
    );
    assert!(
        report.starts_with("ok:") && report.contains("initial points"),
        "{report}"
    );
    let error = failure_of(
        delamesh()
            .args(["plugins", "--plugin", "no-such-plugin"])
            .env("DELAMESH_PLUGIN_PATH", dir),
    );
    assert!(
        error.contains("no-such-plugin") && error.contains("DELAMESH_PLUGIN_PATH"),
        "{error}"
    );
}

fn check_fails(library: &Path, config: &str, expected: &[&str]) {
    let error = failure_of(
        delamesh()
            .args(["plugins", "--plugin"])
            .arg(library)
            .args(["--plugin-config", config]),
    );
    assert!(
        expected.iter().all(|e| error.contains(e)),
        "expected {expected:?} in:\n{error}"
    );
    assert!(
        !error.contains("delamesh-cli") && !error.contains("host.rs"),
        "the host must not panic:\n{error}"
    );
}

#[test]
fn every_fault_is_a_clean_error_naming_the_plugin() {
    let faulty = common::faulty_plugin();
    check_fails(
        &faulty,
        "fault=fail-create",
        &["`faulty`", "create failed", "deliberate create failure"],
    );
    check_fails(
        &faulty,
        "fault=panic-create",
        &["`faulty`", "panicked", "deliberate panic in create"],
    );
    check_fails(
        &faulty,
        "fault=panic-subdomain",
        &["`faulty`", "subdomains failed", "deliberate panic"],
    );
    check_fails(&faulty, "fault=nan-hits", &["`faulty`", "non-finite"]);
    check_fails(
        &faulty,
        "fault=outside-hits",
        &["`faulty`", "outside its bounding box"],
    );
    let c_file = "tests/plugins/faulty_table.c";
    let missing = common::c_plugin(c_file, &["FAULT_NO_ENTRY"]);
    let file_name = missing
        .file_name()
        .and_then(|n| n.to_str())
        .expect("file name")
        .to_string();
    check_fails(&missing, "", &[file_name.as_str(), "delamesh_plugin_v1"]);
    check_fails(
        &common::c_plugin(c_file, &["FAULT_ABI_VERSION"]),
        "",
        &["ABI version 99"],
    );
    check_fails(
        &common::c_plugin(c_file, &["FAULT_NULL_FUNCTION"]),
        "",
        &["`faulty-table`", "`create` is null"],
    );
    check_fails(
        &common::c_plugin("examples/plugins/c-sphere/sphere.c", &[]),
        "radius=0",
        &["`c-sphere`", "radius must be"],
    );
}

#[test]
fn plugin_config_requires_a_plugin() {
    let output = delamesh()
        .args(["plugins", "--plugin-config", "shape=torus"])
        .output()
        .expect("delamesh runs");
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("--plugin"));
}

#[test]
fn built_in_plugins_are_listed_and_load_by_name_as_the_file_path_meshes() {
    let listing = stdout_of(delamesh().arg("plugins"));
    for name in [
        "polyhedral",
        "piecewise-smooth",
        "subdivision",
        "image-label",
    ] {
        assert!(
            listing.lines().any(|l| l.trim_start().starts_with(name)),
            "{name} missing from {listing}"
        );
    }
    let cube = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/features/cube.off");
    let dir = tempfile::tempdir().expect("temporary directory");
    let (by_name, by_file) = (dir.path().join("name.mesh"), dir.path().join("file.mesh"));
    stdout_of(
        delamesh()
            .args([
                "mesh",
                "-q",
                "--plugin",
                "piecewise-smooth",
                "--plugin-config",
            ])
            .arg(&cube)
            .arg("-o")
            .arg(&by_name),
    );
    stdout_of(
        delamesh()
            .args(["mesh", "-q"])
            .arg(&cube)
            .arg("-o")
            .arg(&by_file),
    );
    let read = |p: &Path| std::fs::read(p).expect("the mesh was written");
    assert!(read(&by_name) == read(&by_file), "the two paths differ");
    let report = stdout_of(
        delamesh()
            .args(["plugins", "--plugin", "polyhedral", "--plugin-config"])
            .arg(&cube),
    );
    assert!(report.starts_with("ok:"), "{report}");
    let error = failure_of(delamesh().args(["plugins", "--plugin", "polyhedral"]));
    assert!(
        error.contains("polyhedral") && error.contains("path"),
        "{error}"
    );
}
