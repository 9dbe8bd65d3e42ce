//! Every writer/reader pair: what is written is read back, positions bit-exact where the format
//! stores f64 (f32 formats are tested on f32-representable coordinates).

mod common;

use common::{cube_surface, cube_tets, cube_tets_bytes};
use delamesh_core::mesh::{PatchId, SurfaceMesh, TetMesh};
use delamesh_formats::{
    AnyMesh, Format, WriteOptions, read, read_bytes, read_surface, write_surface_to, write_tet_mesh,
};

fn surface_bytes(m: &SurfaceMesh, f: Format) -> Vec<u8> {
    let mut out = Vec::new();
    write_surface_to(&mut out, m, f, &WriteOptions::default()).unwrap();
    out
}

fn read_surface_back(bytes: &[u8], f: Format) -> SurfaceMesh {
    match read_bytes(bytes, f, None).unwrap().mesh {
        AnyMesh::Surface(s) => s,
        AnyMesh::Volume(v) => v.boundary_surface(),
    }
}

fn bits(m: &SurfaceMesh) -> Vec<[u64; 3]> {
    m.positions
        .iter()
        .map(|p| p.to_array().map(f64::to_bits))
        .collect()
}

/// Same triangles over the same positions, whatever the vertex numbering (for soup formats).
fn same_geometry(a: &SurfaceMesh, b: &SurfaceMesh) {
    let corners = |m: &SurfaceMesh| {
        let mut t: Vec<[[u64; 3]; 3]> = m
            .triangles
            .iter()
            .map(|t| t.map(|v| m.positions[v as usize].to_array().map(f64::to_bits)))
            .collect();
        t.sort_unstable();
        t
    };
    assert_eq!(corners(a), corners(b));
}

#[test]
fn off_ply_and_medit_round_trips_are_exact() {
    // OFF keeps the triangles, MEDIT (a volume format, read back as its boundary) the patches,
    // PLY both.
    for (f, triangles, patches) in [
        (Format::Off, true, false),
        (Format::Ply, true, true),
        (Format::Medit, false, true),
    ] {
        let m = cube_surface(false);
        let back = read_surface_back(&surface_bytes(&m, f), f);
        assert_eq!(bits(&back), bits(&m), "{f}");
        if triangles {
            assert_eq!(back.triangles, m.triangles, "{f}");
        }
        if patches {
            assert_eq!(back.patches, m.patches, "{f}");
        }
    }
}

#[test]
fn stl_round_trip_welds_the_soup_closed() {
    let m = cube_surface(true);
    let bytes = surface_bytes(&m, Format::Stl);
    assert_eq!(bytes.len(), 84 + 50 * 12);
    let read = read_bytes(&bytes, Format::Stl, None).unwrap();
    assert_eq!(read.welded_vertices, 36 - 8);
    let AnyMesh::Surface(back) = read.mesh else {
        panic!("STL is a surface")
    };
    same_geometry(&back, &m);
    let topo = back.topology();
    assert!(topo.closed && topo.manifold && topo.orientation_consistent);
    assert!(topo.signed_volume > 0.0);
}

#[test]
fn medit_round_trip_keeps_every_label() {
    let m = cube_tets();
    let out = cube_tets_bytes(Format::Medit, false);
    let AnyMesh::Volume(back) = read_bytes(&out, Format::Medit, None).unwrap().mesh else {
        panic!("MEDIT holds volumes")
    };
    assert_eq!(
        back,
        TetMesh {
            cell_fields: vec![],
            ..m
        }
    );
}

#[test]
fn atomic_write_replaces_whole_files_and_leaves_nothing_on_failure() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.mesh");
    std::fs::write(&path, "old").unwrap();
    write_tet_mesh(&path, &cube_tets(), &WriteOptions::default()).unwrap();
    assert!(matches!(
        read(&path, None).unwrap().mesh,
        AnyMesh::Volume(_)
    ));
    // An invalid mesh is refused before anything is written.
    let mut bad = cube_tets();
    bad.tets[0][0] = 99;
    let err = write_tet_mesh(&path, &bad, &WriteOptions::default()).unwrap_err();
    assert!(err.to_string().contains("out.mesh"), "{err}");
    assert!(read(&path, None).is_ok());
    // Writing onto a directory fails cleanly.
    assert!(write_tet_mesh(dir.path(), &cube_tets(), &WriteOptions::default()).is_err());
    let leftovers: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert_eq!(leftovers.len(), 1);
    let s = read_surface(&path, None).unwrap();
    assert!(s.mesh.patches.iter().all(|&p| p > PatchId(0)));
}

#[test]
fn vtu_and_legacy_vtk_round_trips_are_exact_with_cell_data() {
    let m = cube_tets();
    for (format, ascii) in common::VTK_VARIANTS {
        let read = read_bytes(&cube_tets_bytes(format, ascii), format, None)
            .unwrap_or_else(|e| panic!("{format} ascii={ascii}: {e}"));
        let AnyMesh::Volume(back) = read.mesh else {
            panic!("{format} holds volumes")
        };
        assert_eq!(back, m, "{format} ascii={ascii}");
        assert!(read.warnings.is_empty(), "{:?}", read.warnings);
    }
}

#[test]
fn test_mesh_is_positively_oriented() {
    let m = cube_tets();
    assert!((0..m.tets.len()).all(|t| m.tet_volume(t) > 0.0));
    let total: f64 = (0..m.tets.len()).map(|t| m.tet_volume(t)).sum();
    assert!((total - cube_surface(false).topology().signed_volume).abs() < 1e-12);
}

#[test]
fn obj_round_trip_keeps_geometry_and_named_groups() {
    let m = cube_surface(false);
    let read = read_bytes(&surface_bytes(&m, Format::Obj), Format::Obj, None).unwrap();
    let AnyMesh::Surface(back) = read.mesh else {
        panic!("OBJ is a surface")
    };
    same_geometry(&back, &m);
    assert_eq!(back.positions.len(), 8, "groups are welded back together");
    assert_eq!(back.patch_names, m.patch_names);
    let names = |s: &SurfaceMesh| -> Vec<String> {
        s.patches
            .iter()
            .map(|p| s.patch_names[p.0 as usize].clone())
            .collect()
    };
    // Same patch name per triangle, compared through the triangles' sorted corner positions.
    let keyed = |s: &SurfaceMesh| {
        let mut v: Vec<_> = s
            .triangles
            .iter()
            .zip(names(s))
            .map(|(t, n)| {
                let mut c = t.map(|v| s.positions[v as usize].to_array().map(f64::to_bits));
                c.sort_unstable();
                (c, n)
            })
            .collect();
        v.sort();
        v
    };
    assert_eq!(keyed(&back), keyed(&m));
    assert!(back.topology().closed);
}

#[cfg(target_os = "linux")]
#[test]
fn written_files_get_ordinary_permissions() {
    use std::os::unix::fs::PermissionsExt;
    let status = std::fs::read_to_string("/proc/self/status").unwrap();
    let umask = status
        .lines()
        .find_map(|l| l.strip_prefix("Umask:"))
        .map(|u| u32::from_str_radix(u.trim(), 8).unwrap())
        .unwrap();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("c.off");
    delamesh_formats::write_surface(&path, &cube_surface(false), &WriteOptions::default()).unwrap();
    let mode = std::fs::metadata(&path).unwrap().permissions().mode() & 0o777;
    assert_eq!(mode, 0o666 & !umask);
}
