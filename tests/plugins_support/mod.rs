//! Building plugin libraries for the tests and benchmarks: Rust plugins with the same cargo and
//! target directory as the running test (so a fresh clone needs nothing prepared), C plugins with
//! the system C compiler.

#![allow(dead_code)] // each test binary uses a subset

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

pub fn repo_root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The profile directory the running test or bench executable was built in (`target/debug`,
/// `target/release`): executables live in its `deps/` subdirectory.
fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("the test knows its executable");
    exe.parent()
        .and_then(Path::parent)
        .expect("test executables live in target/<profile>/deps")
        .to_path_buf()
}

fn dylib_name(lib: &str) -> String {
    format!(
        "{}{lib}{}",
        std::env::consts::DLL_PREFIX,
        std::env::consts::DLL_SUFFIX
    )
}

/// Runs `cargo rustc -p package --lib --crate-type cdylib [--features ...]` once per process, in
/// the profile of the running executable but in the target subdirectory `plugins/`; returns that
/// build's profile directory.
///
/// A separate target directory because a feature build of the built-in plugins in the test's own
/// directory would overwrite the rlib that later test and doctest builds link.
fn cargo_build(package: &str, features: &[&str]) -> PathBuf {
    static BUILT: Mutex<Vec<String>> = Mutex::new(Vec::new());
    let own = profile_dir();
    let profile = own.file_name().map(|name| name.to_os_string());
    let target = own.parent().map(|t| t.join("plugins"));
    let dir = match (&target, &profile) {
        (Some(t), Some(p)) => t.join(p),
        _ => own.clone(),
    };
    let key = format!("{package} {features:?}");
    let mut built = BUILT
        .lock()
        .unwrap_or_else(|poisoned| poisoned.into_inner());
    if !built.contains(&key) {
        let mut cargo = Command::new(env!("CARGO"));
        cargo.current_dir(repo_root()).args([
            "rustc",
            "--quiet",
            "-p",
            package,
            "--lib",
            "--crate-type",
            "cdylib",
        ]);
        if !features.is_empty() {
            cargo.arg("--features").arg(features.join(","));
        }
        if own.file_name().is_some_and(|name| name == "release") {
            cargo.arg("--release");
        }
        if let Some(target) = &target {
            cargo.env("CARGO_TARGET_DIR", target);
        }
        let status = cargo.status().expect("cargo runs");
        assert!(status.success(), "cargo rustc -p {package} failed");
        built.push(key);
    }
    dir
}

/// The `delamesh` binary of the root package, built by cargo for these tests.
pub fn delamesh_bin() -> PathBuf {
    PathBuf::from(env!("CARGO_BIN_EXE_delamesh"))
}

/// Builds the cdylib of workspace package `package` (library name `lib`) with `features`, in the
/// profile of the running executable, and returns its path. Each build runs once per process.
pub fn rust_plugin(package: &str, lib: &str, features: &[&str]) -> PathBuf {
    cargo_build(package, features).join(dylib_name(lib))
}

/// Compiles C `source` (relative to the repository) with `defines` into a shared library under
/// the target directory, against `include/delamesh_plugin.h`.
pub fn c_plugin(source: &str, defines: &[&str]) -> PathBuf {
    let stem = Path::new(source)
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("plugin");
    let out_dir = profile_dir().join("c-plugins");
    std::fs::create_dir_all(&out_dir).expect("the target directory is writable");
    let name = dylib_name(&format!(
        "{stem}{}",
        defines
            .iter()
            .map(|d| format!("_{}", d.to_lowercase()))
            .collect::<String>()
    ));
    let output = out_dir.join(&name);
    // Compile to a file of our own and rename: test binaries running in parallel may build the same
    // library, and one may be loading it meanwhile.
    let partial = out_dir.join(format!("{name}.{}.tmp", std::process::id()));
    let compiler = std::env::var("CC").unwrap_or_else(|_| "cc".to_string());
    let mut cc = Command::new(&compiler);
    cc.args([
        "-std=c99",
        "-O1",
        "-Wall",
        "-Wextra",
        "-Werror",
        "-shared",
        "-fPIC",
        "-fvisibility=hidden",
    ])
    .arg("-I")
    .arg(repo_root().join("include"))
    .args(defines.iter().map(|d| format!("-D{d}")))
    .arg(repo_root().join(source))
    .arg("-o")
    .arg(&partial)
    .arg("-lm");
    let result = cc
        .output()
        .unwrap_or_else(|e| panic!("cannot run the C compiler `{compiler}`: {e}"));
    assert!(
        result.status.success(),
        "{compiler} failed on {source}:\n{}",
        String::from_utf8_lossy(&result.stderr)
    );
    std::fs::rename(&partial, &output).expect("the target directory is writable");
    output
}

/// The implicit-surface example plugin, built as a shared library.
pub fn implicit_plugin() -> PathBuf {
    rust_plugin("delamesh-implicit-example", "delamesh_implicit", &[])
}

/// The fault-injection plugin of `tests/plugins/faulty`.
pub fn faulty_plugin() -> PathBuf {
    rust_plugin("delamesh-faulty-plugin", "delamesh_faulty", &[])
}
