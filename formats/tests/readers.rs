//! Readers on hand-made files in the variants other programs write.

mod common;

use delamesh_formats::{AnyMesh, Format, read_bytes};

fn surface(bytes: &[u8], f: Format) -> delamesh_core::mesh::SurfaceMesh {
    match read_bytes(bytes, f, None)
        .unwrap_or_else(|e| panic!("{f}: {e}"))
        .mesh
    {
        AnyMesh::Surface(s) => s,
        AnyMesh::Volume(v) => v.boundary_surface(),
    }
}

#[test]
fn ply_ascii_and_big_endian_with_quads_and_ushort_indices() {
    let ascii = b"ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\nelement face 1\nproperty list uchar ushort vertex_indices\nend_header\n0 0 0 255\n1 0 0 255\n1 1 0 255\n0 1 0 255\n4 0 1 2 3\n";
    let s = surface(ascii, Format::Ply);
    assert_eq!(s.triangles, vec![[0, 1, 2], [0, 2, 3]]);
    assert_eq!(s.positions[2].to_array(), [1.0, 1.0, 0.0]);

    let mut be = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar uint vertex_index\nend_header\n".to_vec();
    for p in [[0.1f64, 0.2, 0.3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]] {
        p.iter().for_each(|x| be.extend(x.to_be_bytes()));
    }
    be.push(3);
    [2u32, 1, 0].iter().for_each(|i| be.extend(i.to_be_bytes()));
    let s = surface(&be, Format::Ply);
    assert_eq!(s.triangles, vec![[2, 1, 0]]);
    assert_eq!(s.positions[0].to_array(), [0.1, 0.2, 0.3]);
}

#[test]
fn obj_with_negative_indices_polygons_and_objects() {
    let src =
        "o first\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\no second\nv 0 0 1\nf 1 2 5\n";
    let s = surface(src.as_bytes(), Format::Obj);
    assert_eq!(
        s.patch_names,
        vec!["first".to_string(), "second".to_string()]
    );
    assert_eq!(s.triangles.len(), 3);
    assert_eq!(
        s.positions.len(),
        5,
        "shared vertices are welded across objects"
    );
    assert_eq!(s.patches.iter().filter(|p| p.0 == 1).count(), 1);
}

#[test]
fn ascii_stl_and_binary_stl_whose_header_says_solid() {
    let ascii = b"solid\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid\n";
    assert_eq!(surface(ascii, Format::Stl).triangles.len(), 1);
    let mut bin = b"solid but really binary".to_vec();
    bin.resize(80, b' ');
    bin.extend(1u32.to_le_bytes());
    for x in [0f32, 0., 1., 0., 0., 0., 1., 0., 0., 0., 1., 0.] {
        bin.extend(x.to_le_bytes());
    }
    bin.extend([0, 0]);
    let s = surface(&bin, Format::Stl);
    assert_eq!(s.triangles.len(), 1);
    assert_eq!(s.positions[1].to_array(), [1.0, 0.0, 0.0]);
}

#[test]
fn legacy_vtk_polydata_with_strips() {
    let src = "# vtk DataFile Version 3.0\nstrip\nASCII\nDATASET POLYDATA\nPOINTS 4 float\n0 0 0 1 0 0 0 1 0 1 1 0\nTRIANGLE_STRIPS 1 5\n4 0 1 2 3\n";
    let s = surface(src.as_bytes(), Format::Vtk);
    assert_eq!(s.triangles, vec![[0, 1, 2], [2, 1, 3]]);
    assert!(s.topology().orientation_consistent);
}

#[test]
fn medit_with_skipped_sections_warns() {
    let src = "MeshVersionFormatted 1\nDimension\n3\nVertices\n3\n0 0 0 1\n1 0 0 1\n0 1 0 1\nCorners\n1\n1\nTriangles\n1\n1 2 3 5\nEnd\n";
    let r = read_bytes(src.as_bytes(), Format::Medit, None).unwrap();
    assert_eq!(r.warnings.len(), 1);
    let AnyMesh::Volume(v) = r.mesh else {
        panic!("MEDIT holds volumes")
    };
    assert_eq!(v.boundary_patches[0].0, 5);
}

#[test]
fn vtp_poly_data_with_polygons() {
    let src = r#"<?xml version="1.0"?>
<VTKFile type="PolyData" version="1.0" byte_order="LittleEndian">
  <PolyData>
    <Piece NumberOfPoints="5" NumberOfVerts="0" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="2">
      <Points>
        <DataArray type="Float64" NumberOfComponents="3" format="ascii">0 0 0 1 0 0 1 1 0 0 1 0 0.5 0.5 1</DataArray>
      </Points>
      <Polys>
        <DataArray type="Int64" Name="connectivity" format="ascii">0 3 2 1 0 1 4</DataArray>
        <DataArray type="Int64" Name="offsets" format="ascii">4 7</DataArray>
      </Polys>
    </Piece>
  </PolyData>
</VTKFile>
"#;
    let s = surface(src.as_bytes(), Format::Vtp);
    assert_eq!(s.triangles, vec![[0, 3, 2], [0, 2, 1], [0, 1, 4]]);
    assert_eq!(s.positions[4].to_array(), [0.5, 0.5, 1.0]);
}

#[test]
fn off_header_variants_and_counts_on_the_header_line() {
    let s = surface(
        b"NOFF 3 1 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n",
        Format::Off,
    );
    assert_eq!(s.triangles, vec![[0, 1, 2]]);
    assert_eq!(s.positions[1].to_array(), [1.0, 0.0, 0.0]);
}

/// The test mesh as written by delamesh, then re-saved by VTK 9's vtkXMLUnstructuredGridWriter in each
/// of its encodings (raw and base64 appended, zlib-compressed, inline, ASCII): all read back
/// identical to what was written, labels and fields included.
#[test]
fn vtu_files_written_by_vtk_in_every_encoding() {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/written_by_vtk");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    assert_eq!(files.len(), 5);
    for path in files {
        let read = delamesh_formats::read(&path, None).unwrap_or_else(|e| panic!("{e}"));
        let AnyMesh::Volume(m) = read.mesh else {
            panic!("{} holds a volume", path.display())
        };
        assert_eq!(m, common::cube_tets(), "{}", path.display());
    }
}
