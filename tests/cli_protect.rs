//! `delamesh mesh` on CAD-like shapes with sharp features: corners kept exactly, every curve
//! followed by feature edges written as line cells, small angles meshed without cascading.

mod cli_support;

use cli_support::{delamesh, feature_shape};

/// Mesh `name` to MEDIT with a report; returns the report and the mesh read back.
fn mesh(name: &str, extra: &[&str]) -> (serde_json::Value, delamesh::core::mesh::TetMesh) {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out.mesh");
    let report = dir.path().join("report.json");
    delamesh()
        .args(["mesh", "-q"])
        .arg(feature_shape(name))
        .arg("-o")
        .arg(&out)
        .arg("--report")
        .arg(&report)
        .args(extra)
        .assert()
        .success();
    let r = serde_json::from_slice(&std::fs::read(&report).expect("report")).expect("JSON");
    let m = delamesh_formats::read_tet_mesh(&out, None).expect("mesh readable");
    (r, m)
}

#[test]
fn cad_shapes_keep_corners_and_curves_exactly() {
    for name in [
        "cube.off",
        "l_bracket.off",
        "box_with_hole.off",
        "wedge20.off",
        "wedge5.off",
    ] {
        let (r, m) = mesh(name, &[]);
        let f = &r["features"];
        assert!(f["corners"].as_u64().expect("corners") > 0, "{name}");
        assert_eq!(f["missing_corners"], 0, "{name}");
        assert_eq!(f["max_corner_displacement"], 0.0, "{name}");
        assert_eq!(f["lost_curves"], 0, "{name}");
        // Straight input edges are followed exactly (up to rounding) by the feature edges.
        let h = f["max_curve_hausdorff"].as_f64().expect("every curve kept");
        assert!(h < 1e-9, "{name}: curve Hausdorff {h}");
        assert_eq!(r["quality"]["inverted_tets"], 0, "{name}");
        assert_eq!(r["boundary"]["closed"], true, "{name}");
        let volume = r["approximation"]["volume_ratio"].as_f64().expect("number");
        assert!((volume - 1.0).abs() < 1e-9, "{name}: volume ratio {volume}");
        assert!(!m.feature_edges.is_empty(), "{name}: no line cells written");
        assert_eq!(m.feature_edges.len(), m.feature_curves.len());
        assert_eq!(
            m.feature_edges.len() as u64,
            f["feature_edges"].as_u64().expect("count")
        );
    }
}

#[test]
fn cylinder_rims_are_closed_feature_curves() {
    let (r, m) = mesh("cylinder.off", &[]);
    let f = &r["features"];
    assert_eq!(f["lost_curves"], 0);
    assert!(f["curves"].as_u64().expect("curves") >= 2);
    // Each curve's feature edges form closed cycles: every vertex in exactly two of them.
    let mut degree = std::collections::BTreeMap::new();
    for (e, c) in m.feature_edges.iter().zip(&m.feature_curves) {
        for v in e {
            *degree.entry((c.0, *v)).or_insert(0) += 1;
        }
    }
    assert!(degree.values().all(|&d| d == 2), "a rim is not closed");
    // The rims are polygons: every bend is a mesh vertex, so the feature edges follow them
    // exactly (up to rounding), however coarse the edge size.
    let diagonal = bbox_diagonal(&m);
    for edge_size in ["0.3", "0.05"] {
        let (r, _) = mesh("cylinder.off", &["--edge-size", edge_size]);
        let h = r["features"]["max_curve_hausdorff"]
            .as_f64()
            .expect("every curve kept");
        assert!(
            h <= 1e-9 * diagonal,
            "edge size {edge_size}: rim Hausdorff {h}"
        );
    }
}

/// A closed cylinder of radius 1 and height 2 whose rims are `n`-gons, as OFF text.
fn cylinder_off(n: usize) -> String {
    let mut off = format!("OFF\n{} {} 0\n", 2 * n, 4 * n - 4);
    for z in [-1.0, 1.0] {
        for k in 0..n {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            off += &format!("{} {} {z}\n", a.cos(), a.sin());
        }
    }
    for k in 0..n {
        let (a, b) = (k, (k + 1) % n);
        off += &format!("3 {a} {} {}\n3 {a} {b} {}\n", n + b, n + a, n + b);
    }
    for k in 1..n - 1 {
        off += &format!("3 0 {} {k}\n3 {n} {} {}\n", k + 1, n + k, n + k + 1);
    }
    off
}

#[test]
fn optimised_curve_vertices_keep_their_edges_on_a_fine_rim() {
    // Rims of 256 segments: each vertex lies well within the bend tolerance of its neighbours'
    // chord, so the perturbation may slide curve vertices across them; the feature edges must
    // still follow the rims within that tolerance (a quarter of the facet distance).
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("fine_cylinder.off");
    std::fs::write(&input, cylinder_off(256)).expect("written");
    let report = dir.path().join("report.json");
    delamesh()
        .args(["mesh", "-q"])
        .arg(&input)
        .arg("-o")
        .arg(dir.path().join("out.vtu"))
        .arg("--report")
        .arg(&report)
        .assert()
        .success();
    let r: serde_json::Value =
        serde_json::from_slice(&std::fs::read(&report).expect("report")).expect("JSON");
    let f = &r["features"];
    assert_eq!(f["lost_curves"], 0);
    assert_eq!(f["missing_corners"], 0);
    let distance = r["criteria"]["facet_distance"].as_f64().expect("criteria");
    let h = f["max_curve_hausdorff"].as_f64().expect("every curve kept");
    assert!(
        h <= 0.25 * distance,
        "rim Hausdorff {h}, facet distance {distance}"
    );
    assert_eq!(r["quality"]["inverted_tets"], 0);
    assert_eq!(r["boundary"]["closed"], true);
}

fn bbox_diagonal(m: &delamesh::core::mesh::TetMesh) -> f64 {
    let (lo, hi) = m.positions.iter().fold(
        ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]),
        |(mut lo, mut hi), p| {
            for (k, x) in p.to_array().into_iter().enumerate() {
                lo[k] = lo[k].min(x);
                hi[k] = hi[k].max(x);
            }
            (lo, hi)
        },
    );
    (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
}

#[test]
fn edge_size_bounds_the_feature_edges() {
    let (coarse, _) = mesh("cube.off", &["--edge-size", "0.5"]);
    let (fine, m) = mesh("cube.off", &["--edge-size", "0.1"]);
    let count = |r: &serde_json::Value| r["features"]["feature_edges"].as_u64().expect("count");
    assert!(count(&fine) > count(&coarse));
    for e in &m.feature_edges {
        let [a, b] = e.map(|v| m.positions[v as usize]);
        // Consecutive protecting balls of radius ≤ edge_size overlap: edges are shorter than 2×.
        assert!(
            a.distance(b) < 2.0 * 0.1,
            "feature edge of length {}",
            a.distance(b)
        );
    }
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("never.vtu");
    let err = delamesh()
        .args(["mesh", "-q"])
        .arg(feature_shape("cube.off"))
        .arg("-o")
        .arg(&out)
        .arg("--edge-size=0")
        .assert()
        .failure()
        .get_output()
        .stderr
        .clone();
    assert!(String::from_utf8_lossy(&err).contains("--edge-size"));
    assert!(!out.exists());
}

#[test]
fn meshing_with_features_is_deterministic() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (a, b) = (dir.path().join("a.vtu"), dir.path().join("b.vtu"));
    for out in [&a, &b] {
        delamesh()
            .args(["mesh", "-q"])
            .arg(feature_shape("wedge5.off"))
            .arg("-o")
            .arg(out)
            .assert()
            .success();
    }
    assert_eq!(std::fs::read(&a).expect("a"), std::fs::read(&b).expect("b"));
}
