//! `delamesh delaunay` end to end: the written mesh is read back and checked with exact predicates.

mod cli_support;

use cli_support::delamesh;

use delamesh::core::kernel::{Point3, Sign, insphere, orient3d};
use std::fmt::Write as _;
use std::path::Path;

/// A small deterministic pseudo-random point set (a linear congruential generator keeps the test
/// free of extra dependencies).
fn points(n: usize) -> Vec<Point3> {
    let mut state = 0x2545_f491_4f6c_dd1d_u64;
    let mut next = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..n)
        .map(|_| Point3::new(next(), next(), next()))
        .collect()
}

fn write_xyz(path: &Path, pts: &[Point3]) {
    let mut text = String::new();
    for p in pts {
        writeln!(text, "{:?} {:?} {:?}", p.x, p.y, p.z).expect("formatting into a String");
    }
    std::fs::write(path, text).expect("temp dir is writable");
}

#[test]
fn triangulation_written_to_vtu_is_positive_delaunay_and_fills_the_hull() {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("cloud.xyz");
    let output = dir.path().join("cloud.vtu");
    let pts = points(300);
    write_xyz(&input, &pts);
    delamesh()
        .args([
            "delaunay",
            input.to_str().unwrap(),
            "-o",
            output.to_str().unwrap(),
        ])
        .assert()
        .success();

    let mesh = delamesh::formats::read_tet_mesh(&output, None).expect("our own .vtu reads back");
    assert_eq!(mesh.positions.len(), pts.len());
    let mut sorted_in: Vec<[u64; 3]> = pts.iter().map(|p| p.to_array().map(f64::to_bits)).collect();
    let mut sorted_out: Vec<[u64; 3]> = mesh
        .positions
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect();
    sorted_in.sort_unstable();
    sorted_out.sort_unstable();
    assert_eq!(sorted_in, sorted_out, "positions are written bit-exactly");

    let at = |i: u32| mesh.positions[i as usize];
    let mut volume = 0.0;
    for t in &mesh.tets {
        let [a, b, c, d] = t.map(at);
        // det[b-a, c-a, d-a] > 0 (the files' convention) is Shewchuk's orient3d < 0.
        assert_eq!(
            orient3d(a, b, c, d),
            Sign::Negative,
            "tet {t:?} is not positive"
        );
        volume += (b - a).dot((c - a).cross(d - a)) / 6.0;
        // Empty circumsphere, brute force with the exact in-sphere test (orientation reversed).
        for (i, &e) in mesh.positions.iter().enumerate() {
            if !t.contains(&(i as u32)) {
                assert_ne!(
                    insphere(a, b, d, c, e),
                    Sign::Positive,
                    "vertex {i} inside tet {t:?}"
                );
            }
        }
    }
    // The tets fill the convex hull written as outward boundary triangles.
    let hull: f64 = mesh
        .boundary
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(at);
            a.dot(b.cross(c)) / 6.0
        })
        .sum();
    assert!(hull > 0.0, "hull triangles face outwards");
    assert!((volume - hull).abs() < 1e-9, "tets {volume} vs hull {hull}");
}

#[test]
fn bad_point_files_fail_with_the_file_named() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("out.vtu");
    let cases: [(&str, &str); 4] = [
        ("nan.xyz", "0 0 0\n1 0 0\n0 1 0\n0 0 NaN\n"),
        ("short.xyz", "0 0 0\n1 0\n"),
        ("empty.xyz", ""),
        ("flat.xyz", "0 0 0\n1 0 0\n0 1 0\n1 1 0\n"),
    ];
    for (name, text) in cases {
        let input = dir.path().join(name);
        std::fs::write(&input, text).expect("temp dir is writable");
        let assert = delamesh()
            .args([
                "delaunay",
                input.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ])
            .assert()
            .code(1);
        let stderr = String::from_utf8_lossy(&assert.get_output().stderr).into_owned();
        assert!(
            stderr.contains(name),
            "{name}: error does not name the file: {stderr}"
        );
        assert!(!out.exists(), "{name}: no output is written on failure");
    }
}
