//! The `convert` and `info` commands as a user runs them.

mod cli_support;

use cli_support::{delamesh, test_data};

use serde_json::Value;
use std::path::Path;

fn info(path: &Path) -> Value {
    let out = delamesh()
        .arg("info")
        .arg(path)
        .arg("--json")
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn info_reports_topology_of_a_torus_and_a_tet_mesh() {
    let t = info(&test_data("torus.ply"));
    assert_eq!(t["topology"]["genus"], 1);
    assert_eq!(t["topology"]["euler_characteristic"], 0);
    assert_eq!(t["topology"]["closed"], true);
    assert!(t["topology"]["signed_volume"].as_f64().unwrap() > 0.0);
    let v = info(&test_data("box.mesh"));
    assert_eq!(v["kind"], "volume");
    let subdomains = v["volume_mesh"]["subdomains"].as_array().unwrap();
    let volume: f64 = subdomains
        .iter()
        .map(|s| s["volume"].as_f64().unwrap())
        .sum();
    // The tets fill the box their boundary encloses.
    assert!((volume - v["topology"]["signed_volume"].as_f64().unwrap()).abs() < 1e-12);
    assert_eq!(v["volume_mesh"]["inverted_tetrahedra"], 0);
}

#[test]
fn info_finds_holes_in_an_open_surface() {
    let dir = tempfile::tempdir().unwrap();
    let open = dir.path().join("open.off");
    std::fs::write(
        &open,
        "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n",
    )
    .unwrap();
    let t = info(&open);
    assert_eq!(t["topology"]["closed"], false);
    assert_eq!(t["topology"]["boundary_edges"], 4);
    assert_eq!(t["topology"]["genus"], Value::Null);
    let text = delamesh().arg("info").arg(&open).output().unwrap();
    assert!(String::from_utf8_lossy(&text.stdout).contains("4 boundary edges"));
}

#[test]
fn convert_chain_preserves_counts_and_labels() {
    let dir = tempfile::tempdir().unwrap();
    let reference = info(&test_data("box.mesh"));
    let mut previous = test_data("box.mesh");
    for (name, flags) in [
        ("a.vtu", vec![]),
        ("b.vtk", vec!["--ascii"]),
        ("c.mesh", vec![]),
        ("d.vtu", vec!["--ascii"]),
    ] {
        let next = dir.path().join(name);
        delamesh()
            .arg("convert")
            .arg(&previous)
            .arg(&next)
            .args(flags)
            .assert()
            .success();
        let now = info(&next);
        for key in [
            "vertices",
            "triangles",
            "bounding_box",
            "patches",
            "volume_mesh",
        ] {
            assert_eq!(now[key], reference[key], "{name}: {key}");
        }
        previous = next;
    }
    // Tet mesh to a surface format: the boundary.
    let ply = dir.path().join("boundary.ply");
    delamesh()
        .arg("convert")
        .arg(&previous)
        .arg(&ply)
        .assert()
        .success();
    assert_eq!(info(&ply)["triangles"], reference["triangles"]);
}

#[test]
fn format_flags_override_extensions() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("mesh.dat");
    delamesh()
        .args(["convert", "--format", "OFF"])
        .arg(test_data("icosahedron.obj"))
        .arg(&out)
        .assert()
        .success();
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(text.starts_with("OFF"));
    let out = delamesh()
        .args(["info", "--json", "--format", "off"])
        .arg(dir.path().join("mesh.dat"))
        .output()
        .unwrap();
    assert!(out.status.success());
}

#[test]
fn bad_input_fails_cleanly_without_output() {
    let dir = tempfile::tempdir().unwrap();
    let bad = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/bad");
    for entry in std::fs::read_dir(&bad).unwrap() {
        let path = entry.unwrap().path();
        let out = dir.path().join("out.vtu");
        let res = delamesh()
            .arg("convert")
            .arg(&path)
            .arg(&out)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&res.stderr);
        assert_eq!(res.status.code(), Some(1), "{}: {stderr}", path.display());
        assert!(
            stderr.contains("error: ") && !stderr.contains("panicked"),
            "{stderr}"
        );
        assert!(!out.exists(), "{}: partial output written", path.display());
    }
    // A failed write leaves an existing file untouched: the output's directory does not exist.
    let res = delamesh()
        .arg("convert")
        .arg(test_data("box.off"))
        .arg(dir.path().join("no/such/dir/x.vtu"))
        .output()
        .unwrap();
    assert_eq!(res.status.code(), Some(1));
    let existing = dir.path().join("keep.stl");
    std::fs::write(&existing, "precious").unwrap();
    let res = delamesh()
        .arg("convert")
        .arg(bad.join("truncated.mesh"))
        .arg(&existing)
        .output()
        .unwrap();
    assert_eq!(res.status.code(), Some(1));
    assert_eq!(std::fs::read_to_string(&existing).unwrap(), "precious");
    let leftovers = std::fs::read_dir(dir.path()).unwrap().count();
    assert_eq!(leftovers, 1, "temporary files left behind");
}
