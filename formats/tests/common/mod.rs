//! Meshes shared by the integration tests, built from coordinates with awkward binary expansions so
//! that lossy number formatting would show.

#![allow(dead_code)]

use delamesh_core::mesh::{CellField, CurveId, PatchId, SubdomainId, SurfaceMesh, TetMesh};
use delamesh_formats::{Format, WriteOptions, write_tet_mesh_to};
use glam::DVec3;

/// An outward-oriented box of 12 triangles with one patch per side pair, its corners with
/// coordinates inexact in decimal (0.1, 1/3...), rounded to f32 when `f32_exact` so that f32
/// formats can round-trip them.
pub fn cube_surface(f32_exact: bool) -> SurfaceMesh {
    let (lo, hi) = (0.1, 1.0 / 3.0 + 1.0);
    let round = |p: DVec3| if f32_exact { p.as_vec3().as_dvec3() } else { p };
    let min = round(DVec3::new(lo, lo * 2.0, -lo));
    let max = round(DVec3::new(hi, hi * 3.0, hi + 7.0));
    SurfaceMesh {
        patches: (0..12).map(|t| PatchId(t / 4)).collect(),
        patch_names: vec![
            "bottom-top".into(),
            "front-back".into(),
            "left-right".into(),
        ],
        ..SurfaceMesh::cuboid(min, max)
    }
}

/// The box split into 6 positive tets around the diagonal 0–7, two subdomains, its 12 boundary
/// triangles, the 12 box edges as feature edges and two quality fields.
pub fn cube_tets() -> TetMesh {
    let s = cube_surface(false);
    let tets: Vec<[u32; 4]> = [
        [0, 1, 3, 7],
        [0, 3, 2, 7],
        [0, 2, 6, 7],
        [0, 6, 4, 7],
        [0, 4, 5, 7],
        [0, 5, 1, 7],
    ]
    .to_vec();
    let boundary_patches = s.oracle_patches();
    let mut m = TetMesh {
        positions: s.positions,
        subdomains: (0..6).map(|t| SubdomainId(1 + t / 3)).collect(),
        tets,
        boundary: s.triangles,
        boundary_patches,
        feature_edges: vec![
            [0, 1],
            [2, 3],
            [4, 5],
            [6, 7],
            [0, 2],
            [1, 3],
            [4, 6],
            [5, 7],
            [0, 4],
            [1, 5],
            [2, 6],
            [3, 7],
        ],
        feature_curves: (0..12).map(|e| CurveId(e / 4 + 1)).collect(),
        cell_fields: vec![],
    };
    let vol: Vec<f64> = (0..6).map(|t| m.tet_volume(t)).collect();
    m.cell_fields = vec![
        CellField {
            name: "volume".into(),
            values: vol,
        },
        CellField {
            name: "radius_edge".into(),
            values: (0..6).map(|t| 0.1 * t as f64 + 1.0 / 7.0).collect(),
        },
    ];
    m
}

/// The VTK writers, each binary and ASCII.
pub const VTK_VARIANTS: [(Format, bool); 4] = [
    (Format::Vtu, false),
    (Format::Vtu, true),
    (Format::Vtk, false),
    (Format::Vtk, true),
];

/// [`cube_tets`] written as `format`, in ASCII if `ascii`.
pub fn cube_tets_bytes(format: Format, ascii: bool) -> Vec<u8> {
    let mut out = Vec::new();
    let options = WriteOptions {
        ascii,
        ..WriteOptions::default()
    };
    write_tet_mesh_to(&mut out, &cube_tets(), format, &options).unwrap();
    out
}
