//! MEDIT / INRIA `.mesh` (ASCII), hand-written: the format of CGAL's and Inria's tools, no maintained
//! Rust crate. Vertices, edges (with curve refs), triangles (patch refs), tetrahedra (subdomain refs).

use crate::error::Problem;
use crate::text::{Exact, Tokens, as_text, capped};
use delamesh_core::mesh::{CurveId, PatchId, SubdomainId, TetMesh};
use glam::DVec3;
use std::io::Write;

/// Reads a `.mesh` file; returns the mesh and warnings about sections that were skipped.
pub(crate) fn read(bytes: &[u8]) -> Result<(TetMesh, Vec<String>), Problem> {
    let text = as_text(bytes)?;
    let mut t = Tokens::new(&text);
    let mut m = TetMesh::default();
    let mut warnings = Vec::new();
    let mut seen_version = false;
    while let Some(keyword) = t.next_token() {
        let line = t.line();
        if !seen_version {
            if !keyword.eq_ignore_ascii_case("MeshVersionFormatted") {
                return Err(Problem::at_line(
                    line,
                    format!(
                        "expected MeshVersionFormatted, found {} (not a MEDIT .mesh file)", crate::text::quote(keyword)
                    ),
                ));
            }
            let v: u32 = t.parse("the format version")?;
            if !(1..=4).contains(&v) {
                return Err(Problem::at_line(
                    line,
                    format!("unknown format version {v}"),
                ));
            }
            seen_version = true;
            continue;
        }
        let count = |t: &mut Tokens| -> Result<usize, Problem> { t.parse("an element count") };
        let nv = m.positions.len();
        match keyword.to_ascii_lowercase().as_str() {
            "end" => break,
            "dimension" => {
                let d: u32 = t.parse("the dimension")?;
                if d != 3 {
                    return Err(Problem::at_line(
                        line,
                        format!("dimension {d} meshes are not supported (only 3)"),
                    ));
                }
            }
            "vertices" => {
                let n = count(&mut t)?;
                m.positions.reserve(capped(n, bytes.len()));
                for _ in 0..n {
                    m.positions.push(DVec3::new(
                        t.coordinate()?,
                        t.coordinate()?,
                        t.coordinate()?,
                    ));
                    let _ref: i64 = t.parse("a vertex reference")?;
                }
            }
            "edges" => {
                let n = count(&mut t)?;
                for _ in 0..n {
                    m.feature_edges
                        .push([t.index_1based(nv)?, t.index_1based(nv)?]);
                    m.feature_curves
                        .push(CurveId(t.parse("an edge reference")?));
                }
            }
            "triangles" => {
                let n = count(&mut t)?;
                for _ in 0..n {
                    m.boundary.push([
                        t.index_1based(nv)?,
                        t.index_1based(nv)?,
                        t.index_1based(nv)?,
                    ]);
                    m.boundary_patches
                        .push(PatchId(t.parse("a triangle reference")?));
                }
            }
            "quadrilaterals" => {
                let n = count(&mut t)?;
                for _ in 0..n {
                    let q = [
                        t.index_1based(nv)?,
                        t.index_1based(nv)?,
                        t.index_1based(nv)?,
                        t.index_1based(nv)?,
                    ];
                    let patch = PatchId(t.parse("a quadrilateral reference")?);
                    m.boundary.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
                    m.boundary_patches.extend([patch, patch]);
                }
            }
            "tetrahedra" => {
                let n = count(&mut t)?;
                m.tets.reserve(capped(n, bytes.len()));
                for _ in 0..n {
                    m.tets.push([
                        t.index_1based(nv)?,
                        t.index_1based(nv)?,
                        t.index_1based(nv)?,
                        t.index_1based(nv)?,
                    ]);
                    m.subdomains
                        .push(SubdomainId(t.parse("a tetrahedron reference")?));
                }
            }
            other => {
                // Sections we do not keep, with the number of tokens per entry.
                let width = match other {
                    "corners" | "requiredvertices" | "ridges" | "requirededges"
                    | "requiredtriangles" => 1,
                    "normalatvertices" | "tangentatvertices" => 2,
                    "normals" | "tangents" | "normalattrianglevertices" => 3,
                    "pyramids" => 6,
                    "prisms" => 7,
                    "hexahedra" => 9,
                    _ => {
                        return Err(Problem::at_line(
                            line,
                            format!("unknown keyword {}", crate::text::quote(keyword)),
                        ));
                    }
                };
                let n = count(&mut t)?;
                for _ in 0..n.saturating_mul(width) {
                    t.expect(&format!("{keyword} data"))?;
                }
                if n > 0 {
                    warnings.push(format!("skipped {n} {keyword} (line {line})"));
                }
            }
        }
    }
    if !seen_version {
        return Err(Problem::bad("empty file (expected MeshVersionFormatted)"));
    }
    Ok((m, warnings))
}

pub(crate) fn write(w: &mut dyn Write, m: &TetMesh) -> Result<(), Problem> {
    writeln!(
        w,
        "MeshVersionFormatted 2\n\nDimension 3\n\nVertices\n{}",
        m.positions.len()
    )?;
    for p in &m.positions {
        writeln!(w, "{} {} {} 0", Exact(p.x), Exact(p.y), Exact(p.z))?;
    }
    if !m.feature_edges.is_empty() {
        writeln!(w, "\nEdges\n{}", m.feature_edges.len())?;
        for ([a, b], c) in m.feature_edges.iter().zip(&m.feature_curves) {
            writeln!(w, "{} {} {}", a + 1, b + 1, c.0)?;
        }
    }
    if !m.boundary.is_empty() {
        writeln!(w, "\nTriangles\n{}", m.boundary.len())?;
        for ([a, b, c], p) in m.boundary.iter().zip(&m.boundary_patches) {
            writeln!(w, "{} {} {} {}", a + 1, b + 1, c + 1, p.0)?;
        }
    }
    if !m.tets.is_empty() {
        writeln!(w, "\nTetrahedra\n{}", m.tets.len())?;
        for ([a, b, c, d], s) in m.tets.iter().zip(&m.subdomains) {
            writeln!(w, "{} {} {} {} {}", a + 1, b + 1, c + 1, d + 1, s.0)?;
        }
    }
    writeln!(w, "\nEnd")?;
    Ok(())
}
