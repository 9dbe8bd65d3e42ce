//! `delamesh mesh` end to end: bundled models in, every output format out, bad input refused.

mod cli_support;

use cli_support::{COARSE, delamesh, model};

use std::path::Path;

#[test]
fn default_options_give_a_closed_quality_mesh_and_a_report() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("sphere.vtu");
    let report = dir.path().join("report.json");
    delamesh()
        .args(["mesh", "-q"])
        .arg(model("sphere.off"))
        .arg("-o")
        .arg(&out)
        .arg("--report")
        .arg(&report)
        .assert()
        .success();
    assert!(std::fs::metadata(&out).expect("output written").len() > 0);
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report).expect("report written")).expect("JSON");
    assert_eq!(r["boundary"]["closed"], true);
    assert_eq!(r["boundary"]["manifold"], true);
    assert_eq!(
        r["boundary"]["euler_characteristic"],
        r["boundary"]["input_euler_characteristic"]
    );
    assert_eq!(r["quality"]["inverted_tets"], 0);
    let ratio = r["quality"]["max_radius_edge"].as_f64().expect("number");
    assert!(
        ratio <= 3.0 + 1e-9,
        "radius-edge {ratio} above the default bound"
    );
    let volume_ratio = r["approximation"]["volume_ratio"].as_f64().expect("number");
    assert!(
        (volume_ratio - 1.0).abs() < 0.05,
        "volume ratio {volume_ratio}"
    );
    let histogram: u64 = r["quality"]["min_dihedral_histogram"]
        .as_array()
        .expect("array")
        .iter()
        .filter_map(|v| v.as_u64())
        .sum();
    assert_eq!(Some(histogram), r["counts"]["tets"].as_u64());
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let mode = |p: &Path| std::fs::metadata(p).expect("written").permissions().mode() & 0o777;
        assert_eq!(mode(&report), mode(&out), "report and mesh written alike");
    }
}

/// By default the optimisation ends with a flip step on the slivers the sliver steps leave,
/// `--flip` extends it to every cell below the sliver bound and `--no-flip` leaves it out;
/// flips keep the boundary and the volume and do not lower the smallest dihedral angle.
#[test]
fn flips_keep_the_boundary_and_raise_the_smallest_angle() {
    let dir = tempfile::tempdir().expect("temp dir");
    let run = |extra: &[&str], name: &str| -> serde_json::Value {
        let report = dir.path().join(format!("{name}.json"));
        delamesh()
            .args(["mesh", "-q"])
            .arg(model("torus.off"))
            .arg("-o")
            .arg(dir.path().join(format!("{name}.vtu")))
            .args(extra)
            .arg("--report")
            .arg(&report)
            .assert()
            .success();
        serde_json::from_slice(&std::fs::read(&report).expect("report written")).expect("JSON")
    };
    let last_step = |r: &serde_json::Value| {
        let steps = r["optimization"]["steps"].as_array().expect("steps");
        steps.last().expect("a step").clone()
    };
    let plain = run(&["--no-flip"], "plain");
    assert_eq!(last_step(&plain)["step"], "exude");
    let smallest = |r: &serde_json::Value| r["quality"]["min_dihedral_deg"].as_f64();
    let volume = |r: &serde_json::Value| r["approximation"]["volume_ratio"].as_f64();
    for (extra, name) in [(&[][..], "default"), (&["--flip"][..], "flipped")] {
        let flipped = run(extra, name);
        let last = last_step(&flipped);
        assert_eq!(last["step"], "flip", "{name}");
        if name == "flipped" {
            assert!(last["changes"].as_u64().expect("count") > 0);
        }
        for key in ["boundary_facets", "surface_vertices"] {
            assert_eq!(
                flipped["counts"][key], plain["counts"][key],
                "{name}: {key}"
            );
        }
        assert_eq!(flipped["boundary"]["closed"], true);
        assert_eq!(flipped["boundary"]["manifold"], true);
        assert_eq!(flipped["quality"]["inverted_tets"], 0);
        let (a, b) = (
            volume(&plain).expect("volume"),
            volume(&flipped).expect("volume"),
        );
        assert!((a - b).abs() <= 1e-12 * a, "{name}: volume {b}, before {a}");
        assert!(smallest(&flipped) >= smallest(&plain), "{name}");
    }
    delamesh()
        .args(["mesh", "-q"])
        .arg(model("torus.off"))
        .arg("-o")
        .arg(dir.path().join("both.vtu"))
        .args(["--flip", "--no-flip"])
        .assert()
        .code(2);
}

#[test]
fn every_output_format_is_written() {
    let dir = tempfile::tempdir().expect("temp dir");
    for ext in ["vtu", "vtk", "mesh", "msh", "off", "stl", "ply", "obj"] {
        let out = dir.path().join(format!("torus.{ext}"));
        delamesh()
            .args(["mesh", "-q"])
            .arg(model("torus.off"))
            .arg("-o")
            .arg(&out)
            .args(COARSE)
            .assert()
            .success();
        assert!(
            std::fs::metadata(&out).map(|m| m.len()).unwrap_or(0) > 0,
            "{ext} not written"
        );
    }
    // The MEDIT file reads back as positively oriented tets with a closed genus-1 boundary.
    let mesh =
        delamesh_formats::read_tet_mesh(&dir.path().join("torus.mesh"), None).expect("reads back");
    assert!((0..mesh.tets.len()).all(|t| mesh.tet_volume(t) > 0.0));
    let topology = delamesh_core::mesh::surface_topology(&mesh.positions, &mesh.boundary);
    assert!(
        topology.closed && topology.manifold && topology.euler_characteristic == 0,
        "{topology:?}"
    );
}

#[test]
fn same_input_same_bytes() {
    let dir = tempfile::tempdir().expect("temp dir");
    let run = |name: &str| {
        let out = dir.path().join(name);
        delamesh()
            .args(["mesh", "-q"])
            .arg(model("torus.off"))
            .arg("-o")
            .arg(&out)
            .args(COARSE)
            .assert()
            .success();
        std::fs::read(out).expect("output written")
    };
    assert_eq!(run("a.vtu"), run("b.vtu"));
}

#[test]
fn bad_input_is_refused_with_a_clear_error() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out.vtu");
    // Missing file.
    says(
        delamesh()
            .args(["mesh", "no-such-file.off", "-o"])
            .arg(&out)
            .assert()
            .failure(),
        "no-such-file.off",
    );
    // An open surface: one triangle removed from the sphere.
    let sphere = std::fs::read_to_string(model("sphere.off")).expect("bundled model");
    let mut lines: Vec<&str> = sphere.lines().collect();
    let header = lines
        .iter()
        .position(|l| l.starts_with("642 "))
        .expect("counts line");
    lines[header] = "642 1279 0";
    lines.pop();
    let open = dir.path().join("open.off");
    std::fs::write(&open, lines.join("\n")).expect("write");
    // Refused with --strict, with its diagnosis; else capped, meshed and reported on stderr.
    says(
        delamesh()
            .arg("mesh")
            .arg(&open)
            .arg("-o")
            .arg(&out)
            .arg("--strict")
            .assert()
            .failure(),
        "delamesh info",
    );
    says(
        delamesh()
            .arg("mesh")
            .arg(&open)
            .arg("-o")
            .arg(&out)
            .arg("-q")
            .assert()
            .success(),
        "border edges (holes capped)",
    );
    std::fs::remove_file(&out).ok();
    // Garbage.
    let garbage = dir.path().join("garbage.off");
    std::fs::write(&garbage, "OFF\n3 1 0\n0 0 nan\n").expect("write");
    delamesh()
        .arg("mesh")
        .arg(&garbage)
        .arg("-o")
        .arg(&out)
        .assert()
        .failure();
    // Nonsense criteria.
    says(
        delamesh()
            .arg("mesh")
            .arg(model("sphere.off"))
            .arg("-o")
            .arg(&out)
            .arg("--facet-size=-1")
            .assert()
            .failure(),
        "facet-size",
    );
    assert!(!out.exists(), "nothing is written on failure");
}

#[test]
fn vertex_guard_stops_refinement_and_keeps_the_partial_mesh_on_request() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("partial.vtu");
    let args = ["--max-vertices", "200", "--facet-size", "0.05"];
    delamesh()
        .args(["mesh", "-q"])
        .arg(model("sphere.off"))
        .arg("-o")
        .arg(&out)
        .args(args)
        .assert()
        .failure();
    assert!(!out.exists());
    says(
        delamesh()
            .args(["mesh", "-q", "--keep-partial"])
            .arg(model("sphere.off"))
            .arg("-o")
            .arg(&out)
            .args(args)
            .assert()
            .failure(),
        "partial",
    );
    assert!(out.exists());
}

/// The command failed and said `needle` on stderr.
fn says(assert: assert_cmd::assert::Assert, needle: &str) {
    let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
    assert!(
        stderr.contains(needle),
        "stderr {stderr:?} does not mention {needle:?}"
    );
}
