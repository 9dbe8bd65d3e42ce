//! `delamesh mesh` terminates on features it cannot protect at the requested size: a slab
//! thinner than any sensible ball, a sliver wedge, an absurd edge size. Each run either meshes
//! or stops with a one-line error naming the option to change, and leaves no output behind.

mod cli_support;

use cli_support::delamesh;

/// A box `[0, x] × [0, y] × [0, z]` as OFF quads.
fn cuboid(x: f64, y: f64, z: f64) -> String {
    format!(
        "OFF\n8 6 0\n0 0 0\n{x} 0 0\n{x} {y} 0\n0 {y} 0\n0 0 {z}\n{x} 0 {z}\n{x} {y} {z}\n0 {y} {z}\n\
         4 0 3 2 1\n4 4 5 6 7\n4 0 1 5 4\n4 2 3 7 6\n4 0 4 7 3\n4 1 2 6 5\n"
    )
}

/// A prism over a triangle with an angle of `degrees` at the origin, height 1.
fn wedge(degrees: f64) -> String {
    let (c, s) = (degrees.to_radians().cos(), degrees.to_radians().sin());
    format!(
        "OFF\n6 5 0\n0 0 0\n1 0 0\n{c} {s} 0\n0 0 1\n1 0 1\n{c} {s} 1\n\
         3 0 2 1\n3 3 4 5\n4 0 1 4 3\n4 1 2 5 4\n4 2 0 3 5\n"
    )
}

/// Runs `delamesh mesh` on `off` with `args`; returns whether it succeeded, its stderr, and
/// whether the output exists.
fn run(off: &str, args: &[&str]) -> (bool, String, bool) {
    let dir = tempfile::tempdir().expect("temp dir");
    let input = dir.path().join("in.off");
    std::fs::write(&input, off).expect("write input");
    let out = dir.path().join("out.vtu");
    let o = delamesh()
        .args(["mesh", "-q"])
        .arg(&input)
        .arg("-o")
        .arg(&out)
        .args(args)
        .output()
        .expect("runs");
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    (o.status.success(), err, out.exists())
}

#[test]
fn features_too_close_stop_at_the_vertex_limit_with_a_clear_error() {
    for (name, off) in [("slab", cuboid(1.0, 1.0, 1e-6)), ("wedge", wedge(0.1))] {
        let (ok, err, written) = run(&off, &["--max-vertices", "1000"]);
        if ok {
            assert!(written, "{name}: success without output");
            continue;
        }
        assert!(!written, "{name}: output left behind");
        assert_eq!(err.trim().lines().count(), 1, "{name}: {err}");
        assert!(
            err.contains("--max-vertices") || err.contains("--edge-min-size"),
            "{name}: {err}"
        );
    }
}

#[test]
fn a_tiny_edge_size_is_bounded_by_the_smallest_ball() {
    let (ok, err, written) = run(
        &cuboid(1.0, 1.0, 1.0),
        &["--edge-size", "1e-300", "--max-vertices", "1000"],
    );
    assert!(!ok && !written);
    assert!(err.contains("--max-vertices"), "{err}");
    // With a smallest ball of 0.05, the same request meshes.
    let (ok, err, _) = run(
        &cuboid(1.0, 1.0, 1.0),
        &["--edge-size", "1e-300", "--edge-min-size", "0.05"],
    );
    assert!(ok, "{err}");
}

#[test]
fn the_time_limit_stops_with_a_clear_error() {
    let (ok, err, written) = run(&cuboid(1.0, 1.0, 1.0), &["--time-limit", "1e-9"]);
    assert!(!ok && !written);
    assert!(err.contains("--time-limit"), "{err}");
    let out = delamesh()
        .args(["mesh", "-q", "x.off", "-o", "x.vtu", "--time-limit", "-1"])
        .output()
        .expect("delamesh runs");
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("--time-limit"));
}

#[test]
fn the_time_limit_bounds_the_surface_keeping_mode() {
    let quality = [
        "--preserve-surface",
        "--cell-size",
        "0.1",
        "--time-limit",
        "1e-9",
    ];
    // Recovery stopped: no mesh keeps the surface yet.
    let (ok, err, written) = run(&cuboid(1.0, 1.0, 1.0), &quality);
    assert!(!ok && !written, "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("--time-limit"), "{err}");
    // A tetrahedron needs no Steiner point, and the cell level stops between rounds, where its
    // mesh keeps the surface: a partial mesh.
    let corner = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
    let (ok, err, written) = run(corner, &quality);
    assert!(!ok && !written, "{err}");
    let (ok, err, written) = run(corner, &[&quality[..], &["--keep-partial"]].concat());
    assert!(!ok && written, "{err}");
    assert!(err.contains("partial mesh"), "{err}");
}
