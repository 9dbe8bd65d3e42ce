//! The `mesh2d` and `conform2d` commands as a user runs them.

mod cli_support;

use cli_support::delamesh;

use std::path::PathBuf;

/// A scratch directory of its own for each test (tests run in parallel).
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("delamesh-twod-{}-{test}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

const SQUARE_WITH_HOLE: &str = "# square with a square hole\n8 2 0 1\n1 0 0 1\n2 10 0 1\n3 10 10 1\n\
    4 0 10 1\n5 4 4 2\n6 6 4 2\n7 6 6 2\n8 4 6 2\n8 1\n1 1 2 1\n2 2 3 1\n3 3 4 1\n4 4 1 1\n\
    5 5 6 2\n6 6 7 2\n7 7 8 2\n8 8 5 2\n1\n1 5 5\n";

#[test]
fn mesh2d_writes_a_deterministic_vtu() {
    let dir = scratch("mesh2d");
    let input = dir.join("square.poly");
    std::fs::write(&input, SQUARE_WITH_HOLE).unwrap();
    let mut outputs = Vec::new();
    for k in 0..2 {
        let out = dir.join(format!("out{k}.vtu"));
        let run = delamesh()
            .args([
                "mesh2d",
                input.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ])
            .args(["--min-angle", "30", "--max-area", "0.5"])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let text = String::from_utf8_lossy(&run.stdout).into_owned();
        let angle: f64 = text
            .split("smallest angle ")
            .nth(1)
            .and_then(|s| s.split('°').next())
            .and_then(|s| s.parse().ok())
            .expect("reports the smallest angle");
        assert!(angle >= 30.0, "{text}");
        outputs.push(std::fs::read(&out).unwrap());
    }
    assert!(outputs[0].starts_with(b"<?xml"));
    assert_eq!(outputs[0], outputs[1]);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn conform2d_runs_every_algorithm() {
    let dir = scratch("conform2d");
    let input = dir.join("square.poly");
    std::fs::write(&input, SQUARE_WITH_HOLE).unwrap();
    for algorithm in ["3.1", "3.1p", "3.2"] {
        let out = dir.join(format!("out{algorithm}.vtu"));
        let run = delamesh()
            .args([
                "conform2d",
                input.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ])
            .args(["--algorithm", algorithm])
            .output()
            .unwrap();
        assert!(
            run.status.success(),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        assert!(std::fs::read(&out).unwrap().starts_with(b"<?xml"));
    }
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bad_poly_files_fail_with_the_file_named() {
    let dir = scratch("bad");
    let input = dir.join("crossing.poly");
    std::fs::write(
        &input,
        "4 2 0 0\n1 0 0\n2 1 0\n3 1 1\n4 0 1\n2 0\n1 1 3\n2 2 4\n0\n",
    )
    .unwrap();
    for command in ["mesh2d", "conform2d"] {
        let out = dir.join("out.vtu");
        let run = delamesh()
            .args([
                command,
                input.to_str().unwrap(),
                "-o",
                out.to_str().unwrap(),
            ])
            .output()
            .unwrap();
        assert_eq!(run.status.code(), Some(1));
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(
            err.contains("crossing.poly") && err.contains("cross"),
            "{err}"
        );
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(dir).ok();
}

/// The square with a square hole of `SQUARE_WITH_HOLE` as OBJ polylines (same point order).
const SQUARE_WITH_HOLE_OBJ: &str = "v 0 0\nv 10 0\nv 10 10\nv 0 10 0\nv 4 4\nv 6 4\nv 6 6\nv 4 6\n\
    l 1 2 3 4 1\nl 5 6 7 8 -4\n";

/// The same as VTK legacy poly data lines.
const SQUARE_WITH_HOLE_VTK: &str = "# vtk DataFile Version 3.0\nsquare\nASCII\nDATASET POLYDATA\n\
    POINTS 8 double\n0 0 0 10 0 0 10 10 0 0 10 0\n4 4 0 6 4 0 6 6 0 4 6 0\n\
    LINES 2 12\n5 0 1 2 3 0\n5 4 5 6 7 4\n";

fn mesh2d(input: &std::path::Path, out: &std::path::Path, extra: &[&str]) -> std::process::Output {
    delamesh()
        .args([
            "mesh2d",
            input.to_str().unwrap(),
            "-o",
            out.to_str().unwrap(),
        ])
        .args(["--min-angle", "30", "--max-area", "0.5"])
        .args(extra)
        .output()
        .unwrap()
}

#[test]
fn obj_and_vtk_polylines_mesh_like_the_poly_file() {
    let dir = scratch("polylines");
    let mut outputs = Vec::new();
    for (name, text, extra) in [
        ("square.poly", SQUARE_WITH_HOLE, &[][..]),
        ("square.obj", SQUARE_WITH_HOLE_OBJ, &["--hole", "5,5"][..]),
        ("square.vtk", SQUARE_WITH_HOLE_VTK, &["--hole", "5,5"][..]),
    ] {
        let input = dir.join(name);
        std::fs::write(&input, text).unwrap();
        let out = dir.join(format!("{name}.vtu"));
        let run = mesh2d(&input, &out, extra);
        assert!(
            run.status.success(),
            "{name}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        outputs.push(std::fs::read(&out).unwrap());
    }
    // Same points in the same order, same segments, same hole: byte-identical meshes.
    assert_eq!(outputs[0], outputs[1]);
    assert_eq!(outputs[0], outputs[2]);
    // Without the hole seed the hole is meshed: a different mesh.
    let input = dir.join("square.obj");
    let out = dir.join("filled.vtu");
    assert!(mesh2d(&input, &out, &[]).status.success());
    assert_ne!(std::fs::read(&out).unwrap(), outputs[0]);
    std::fs::remove_dir_all(dir).ok();
}

#[test]
fn bad_polyline_files_fail_with_the_file_named() {
    let dir = scratch("bad-polylines");
    let vtk_head = "# vtk DataFile Version 3.0\nbad\nASCII\nDATASET POLYDATA\n";
    for (name, text, why) in [
        (
            "nan.obj",
            "v 0 0\nv nan 0\nv 1 1\nl 1 2 3 1\n",
            "non-finite",
        ),
        (
            "lifted.obj",
            "v 0 0\nv 1 0 0.5\nv 1 1\nl 1 2 3 1\n",
            "z = 0.5",
        ),
        (
            "degenerate.obj",
            "v 0 0\nv 1 0\nv 1 1\nl 1 2 2 3 1\n",
            "both ends",
        ),
        ("truncated.obj", "v 0 0\nv 1 0\nv 1\n", "x and y"),
        ("dangling.obj", "v 0 0\nv 1 0\nl 1 2 3\n", "out of range"),
        (
            "lifted.vtk",
            &format!("{vtk_head}POINTS 3 double\n0 0 0 1 0 2 1 1 0\nLINES 1 5\n4 0 1 2 0\n"),
            "z = 2",
        ),
        (
            "truncated.vtk",
            &format!("{vtk_head}POINTS 3 double\n0 0 0 1 0 0 1 1 0\nLINES 1 5\n4 0 1\n"),
            "",
        ),
    ] {
        let input = dir.join(name);
        std::fs::write(&input, text).unwrap();
        let out = dir.join("out.vtu");
        let run = mesh2d(&input, &out, &[]);
        assert_eq!(run.status.code(), Some(1), "{name}");
        let err = String::from_utf8_lossy(&run.stderr);
        assert!(err.contains(name) && err.contains(why), "{name}: {err}");
        assert!(!err.contains("panicked"), "{name}: {err}");
        assert!(!out.exists());
    }
    std::fs::remove_dir_all(dir).ok();
}
