//! The regression corpus of bad files (tests/bad at the repository root): each must give a clean,
//! one-line error that names the file and the problem, and never panic.

mod common;

use delamesh_formats::{Format, read, read_bytes};
use std::path::{Path, PathBuf};

/// Every file of the corpus, with a fragment its error message must contain.
const EXPECTED: &[(&str, &str)] = &[
    ("accessor_past_buffer.gltf", "runs past its buffer view"),
    ("binary_junk.off", "line 1: expected an OFF header"),
    (
        "count_larger_than_file.off",
        "line 4: unexpected end of file",
    ),
    ("counts_larger_than_file.vtk", "not a readable VTK file"),
    ("dimension2.mesh", "line 2: dimension 2"),
    ("empty.off", "the file is empty"),
    (
        "glb_chunk_past_end.glb",
        "byte 12: a GLB chunk of 1000 bytes",
    ),
    (
        "glb_length_below_header.glb",
        "byte 8: the GLB header announces 4 bytes",
    ),
    (
        "index_out_of_range.mesh",
        "line 10: vertex index 4 out of range",
    ),
    (
        "index_out_of_range.off",
        "line 6: vertex index 3 out of range",
    ),
    ("index_out_of_range.ply", "refers to vertex 9"),
    ("index_out_of_range.vtk", "refers to point 99"),
    ("inf_vertex.mesh", "line 6: non-finite coordinate"),
    ("inf_vertex.ply", "line 11: not a readable PLY file"),
    ("missing_buffer.gltf", "nowhere.bin"),
    ("nan_point.vtk", "non-finite coordinate"),
    ("nan_vertex.off", "line 4: non-finite coordinate"),
    ("nan_vertex.stl", "expected finite"),
    ("no_faces.obj", "no triangles"),
    ("no_faces.off", "no triangles"),
    ("not_json.gltf", "not a readable glTF file"),
    ("not_xml.vtu", "not a readable VTK file"),
    ("out_of_bounds_index.obj", "out of bounds"),
    ("shorter_than_header.stl", "byte 40: truncated binary STL"),
    (
        "truncated.glb",
        "the GLB header announces 4000 bytes, the file holds 22",
    ),
    ("truncated.mesh", "line 6: unexpected end of file"),
    ("truncated.ply", "line 12: not a readable PLY file"),
    ("truncated.vtu", "truncated file"),
    ("truncated_binary.stl", "announces 100 triangles"),
    ("unknown_keyword.mesh", "line 6: unknown keyword"),
    ("vtkio_slice_panic.vtu", "vtkio gave up"),
    ("wrong_magic.mesh", "line 1: expected MeshVersionFormatted"),
    ("wrong_magic.off", "line 1: expected an OFF header"),
    ("wrong_magic.ply", "line 1: not a readable PLY file"),
    ("wrong_magic.vtk", "byte 0: wrong magic"),
];

fn corpus() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/bad")
}

#[test]
fn every_bad_file_gives_a_clean_error() {
    let mut files: Vec<String> = std::fs::read_dir(corpus())
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    let listed: Vec<String> = EXPECTED.iter().map(|(f, _)| f.to_string()).collect();
    assert_eq!(
        files, listed,
        "tests/bad and EXPECTED must list the same files"
    );
    for (file, fragment) in EXPECTED {
        let path = corpus().join(file);
        let err = match read(&path, None) {
            Ok(m) => panic!("{file} was accepted: {m:?}"),
            Err(e) => e.to_string(),
        };
        assert!(
            err.contains(file),
            "{file}: the error does not name the file: {err}"
        );
        assert!(
            err.contains(fragment),
            "{file}: expected {fragment:?} in: {err}"
        );
        assert!(!err.contains('\n'), "{file}: multi-line error: {err}");
    }
}

#[test]
fn a_directory_or_unknown_extension_is_an_error() {
    let dir = tempfile::tempdir().unwrap();
    let fake = dir.path().join("looks_like.stl");
    std::fs::create_dir(&fake).unwrap();
    let err = read(&fake, None).unwrap_err().to_string();
    assert!(
        err.contains("looks_like.stl") && err.contains("directory"),
        "{err}"
    );
    let unknown = dir.path().join("mesh.xyz");
    std::fs::write(&unknown, "1 2 3").unwrap();
    let err = read(&unknown, None).unwrap_err().to_string();
    assert!(err.contains("--format"), "{err}");
    let missing = dir.path().join("missing.off");
    assert!(
        read(&missing, None)
            .unwrap_err()
            .to_string()
            .contains("missing.off")
    );
}

/// Every prefix of valid files is either a valid mesh or a clean error: truncation at any byte.
#[test]
fn every_truncation_of_the_sample_models_is_handled() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data");
    for name in [
        "box.off",
        "box.mesh",
        "torus.ply",
        "tetrahedron.stl",
        "pyramid.glb",
        "icosahedron.obj",
    ] {
        let bytes = std::fs::read(data.join(name)).unwrap();
        let format = Format::from_path(Path::new(name)).unwrap();
        truncations(&bytes, format);
    }
    for (format, ascii) in common::VTK_VARIANTS {
        truncations(&common::cube_tets_bytes(format, ascii), format);
    }
}

fn truncations(bytes: &[u8], format: Format) {
    let step = (bytes.len() / 97).max(1);
    for cut in (0..bytes.len()).step_by(step) {
        // Either outcome is fine; a panic fails the test.
        let _ = read_bytes(&bytes[..cut], format, None);
    }
}
