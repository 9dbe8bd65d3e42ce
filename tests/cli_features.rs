//! `delamesh mesh` with sharp features: the piecewise-smooth domain by default, the smooth one
//! unchanged when there is no feature, and clean errors for bad feature options.

mod cli_support;

use cli_support::{COARSE, delamesh, feature_shape, repo};

#[test]
fn a_smooth_surface_is_meshed_exactly_as_without_features() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a.vtu"), dir.path().join("b.vtu"));
    for (out, extra) in [(&a, None), (&b, Some("--no-features"))] {
        delamesh()
            .args(["mesh", "-q"])
            .arg(repo("models/torus.off"))
            .arg("-o")
            .arg(out)
            .args(extra)
            .assert()
            .success();
    }
    assert_eq!(std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
}

#[test]
fn two_boxes_sharing_a_face_give_two_subdomains_of_unit_volume() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("boxes.mesh");
    delamesh()
        .args(["mesh", "-q"])
        .arg(feature_shape("two_boxes.off"))
        .arg("-o")
        .arg(&out)
        .args(COARSE)
        .assert()
        .success();
    let m = delamesh_formats::read_tet_mesh(&out, None).unwrap();
    let mut volume = [0.0f64; 2];
    for t in 0..m.tets.len() {
        let s = m.subdomains[t].0 as usize;
        assert!((1..=2).contains(&s), "subdomain {s}");
        // Subdomain 1 is the box of the first component, x ≤ 1 (the mesh approximates the
        // interface, so tets right at it may cross it).
        let x = m.tets[t]
            .iter()
            .map(|&v| m.positions[v as usize].x)
            .sum::<f64>()
            / 4.0;
        if (x - 1.0).abs() > 0.2 {
            assert_eq!(s == 1, x < 1.0, "tet {t} at x = {x} in subdomain {s}");
        }
        volume[s - 1] += m.tet_volume(t);
    }
    for v in volume {
        assert!((v - 1.0).abs() < 0.02, "{v}");
    }
}

#[test]
fn user_polylines_are_accepted_when_on_surface_edges() {
    let dir = tempfile::tempdir().unwrap();
    delamesh()
        .args(["mesh", "-q"])
        .arg(feature_shape("block_2x2.off"))
        .arg("--features")
        .arg(feature_shape("block_2x2.polylines.txt"))
        .arg("-o")
        .arg(dir.path().join("block.vtu"))
        .args(COARSE)
        .assert()
        .success();
    // The same polyline is off the unit cube's surface.
    let out = delamesh()
        .args(["mesh", "-q"])
        .arg(feature_shape("cube.off"))
        .arg("--features")
        .arg(feature_shape("block_2x2.polylines.txt"))
        .arg("-o")
        .arg(dir.path().join("cube.vtu"))
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    let err = String::from_utf8_lossy(&out);
    assert!(
        err.contains("block_2x2.polylines.txt") && err.contains("line 2"),
        "{err}"
    );
    assert!(!dir.path().join("cube.vtu").exists());
}

#[test]
fn bad_feature_options_are_clean_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("x.vtu");
    let bad = repo("plugins/piecewise-smooth/tests/data/nan.polylines.txt");
    let stderr = |args: &[&std::ffi::OsStr], code: i32| {
        let o = delamesh()
            .args(["mesh", "-q"])
            .arg(feature_shape("cube.off"))
            .arg("-o")
            .arg(&out)
            .args(args)
            .assert()
            .code(code)
            .get_output()
            .stderr
            .clone();
        String::from_utf8_lossy(&o).into_owned()
    };
    let e = stderr(&["--features".as_ref(), bad.as_os_str()], 1);
    assert!(
        e.contains("nan.polylines.txt:1:") && e.contains("not a finite number"),
        "{e}"
    );
    let e = stderr(&["--feature-angle".as_ref(), "200".as_ref()], 1);
    assert!(e.contains("feature angle"), "{e}");
    let e = stderr(
        &[
            "--no-features".as_ref(),
            "--features".as_ref(),
            bad.as_os_str(),
        ],
        2,
    );
    assert!(e.contains("--no-features"), "{e}");
    assert!(!out.exists());
}

#[test]
fn info_counts_the_features_mesh_would_find() {
    let out = delamesh()
        .args(["info", "--json"])
        .arg(feature_shape("box_with_hole.off"))
        .assert()
        .success()
        .get_output()
        .stdout
        .clone();
    let v: serde_json::Value = serde_json::from_slice(&out).unwrap();
    let f = &v["features"];
    // The outer box's 12 edges and the hole's 12, meeting at 8 + 8 corners.
    assert_eq!(f["curves"], 24);
    assert_eq!(f["corners"], 16);
    assert_eq!(f["closed_curves"], 0);
    let out = delamesh()
        .args(["info", "--json"])
        .arg(feature_shape("cylinder.off"))
        .output()
        .unwrap();
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["features"]["closed_curves"], 2);
    assert_eq!(v["features"]["corners"], 0);
}
