//! Files: the test shapes committed under `tests/data/features/` (for the end-to-end tests), and
//! polylines files good and bad.

use delamesh_core::mesh::SurfaceMesh;
use delamesh_formats::{WriteOptions, read_surface, write_surface};
use delamesh_piecewise_smooth::models::{
    box_with_hole, cylinder, l_bracket, two_boxes, voxels, wedge,
};
use delamesh_piecewise_smooth::{FeatureOptions, Features, PolylineError, read_polylines};
use glam::DVec3;
use std::path::{Path, PathBuf};

fn shapes() -> Vec<(&'static str, SurfaceMesh)> {
    vec![
        ("cube", SurfaceMesh::cuboid(DVec3::ZERO, DVec3::ONE)),
        ("cylinder", cylinder(1.0, 2.0, 32)),
        ("l_bracket", l_bracket()),
        ("box_with_hole", box_with_hole()),
        ("wedge20", wedge(20.0, 1.0, 0.5)),
        ("wedge5", wedge(5.0, 1.0, 0.5)),
        ("two_boxes", two_boxes()),
        (
            "block_2x2",
            voxels(&[[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0]], 1.0),
        ),
    ]
}

fn shared_data() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/features")
}

fn local_data(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data")
        .join(name)
}

/// The committed OFF files are exactly the generated shapes (set DELAMESH_WRITE_FEATURE_MODELS=1
/// to rewrite them after changing a shape).
#[test]
fn committed_feature_models_are_the_generated_shapes() {
    let dir = shared_data();
    for (name, shape) in shapes() {
        let path = dir.join(format!("{name}.off"));
        if std::env::var_os("DELAMESH_WRITE_FEATURE_MODELS").is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            write_surface(&path, &shape, &WriteOptions::default()).unwrap();
        }
        let read = read_surface(&path, None)
            .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
            .mesh;
        assert_eq!(read.positions, shape.positions, "{name}");
        assert_eq!(read.triangles, shape.triangles, "{name}");
    }
}

#[test]
fn polylines_file_adds_a_curve() {
    let block = read_surface(&shared_data().join("block_2x2.off"), None)
        .unwrap()
        .mesh;
    let lines = read_polylines(&shared_data().join("block_2x2.polylines.txt")).unwrap();
    assert_eq!(lines.len(), 1);
    assert_eq!(lines[0].line, 2);
    let plain = Features::extract(&block, &FeatureOptions::default(), &[]).unwrap();
    let f = Features::extract(&block, &FeatureOptions::default(), &lines).unwrap();
    assert_eq!(f.num_patches, plain.num_patches + 1);
    assert_eq!(f.curves.len(), plain.curves.len() + 3);
}

#[test]
fn bad_polylines_files_name_the_file_and_the_line() {
    for (name, line, problem) in [
        ("bad_count.polylines.txt", 2, "9 coordinates, found 6"),
        ("nan.polylines.txt", 1, "not a finite number"),
        ("truncated.polylines.txt", 2, "12 coordinates, found 8"),
    ] {
        let path = local_data(name);
        let e = read_polylines(&path).unwrap_err();
        assert!(
            matches!(e, PolylineError::Syntax { line: l, .. } if l == line),
            "{name}: {e}"
        );
        let message = e.to_string();
        assert!(
            message.contains(name) && message.contains(problem),
            "{message}"
        );
    }
    let missing = read_polylines(&local_data("missing.polylines.txt")).unwrap_err();
    assert!(matches!(missing, PolylineError::Io { .. }));
    assert!(missing.to_string().contains("missing.polylines.txt"));
}
