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
    let Some(keyword) = t.next_token() else {
        return Err(Problem::bad("empty file (expected MeshVersionFormatted)"));
    };
    read_version(&mut t, keyword)?;
    while let Some(keyword) = t.next_token() {
        if keyword.eq_ignore_ascii_case("end") {
            break;
        }
        if let Some(warning) = read_section(&mut t, &mut m, keyword, bytes.len())? {
            warnings.push(warning);
        }
    }
    Ok((m, warnings))
}

/// The `MeshVersionFormatted` header, which must come first.
fn read_version(t: &mut Tokens, keyword: &str) -> Result<(), Problem> {
    let line = t.line();
    if !keyword.eq_ignore_ascii_case("MeshVersionFormatted") {
        return Err(Problem::at_line(
            line,
            format!(
                "expected MeshVersionFormatted, found {} (not a MEDIT .mesh file)",
                crate::text::quote(keyword)
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
    Ok(())
}

/// One section after its keyword; returns a warning for a section read but not kept.
fn read_section(
    t: &mut Tokens,
    m: &mut TetMesh,
    keyword: &str,
    file_len: usize,
) -> Result<Option<String>, Problem> {
    let line = t.line();
    let nv = m.positions.len();
    let lower = keyword.to_ascii_lowercase();
    if lower == "dimension" {
        let d: u32 = t.parse("the dimension")?;
        if d != 3 {
            return Err(Problem::at_line(
                line,
                format!("dimension {d} meshes are not supported (only 3)"),
            ));
        }
        return Ok(None);
    }
    let skipped_width = match lower.as_str() {
        "vertices" | "edges" | "triangles" | "quadrilaterals" | "tetrahedra" => None,
        // Sections we do not keep, with the number of tokens per entry.
        "corners" | "requiredvertices" | "ridges" | "requirededges" | "requiredtriangles" => {
            Some(1)
        }
        "normalatvertices" | "tangentatvertices" => Some(2),
        "normals" | "tangents" | "normalattrianglevertices" => Some(3),
        "pyramids" => Some(6),
        "prisms" => Some(7),
        "hexahedra" => Some(9),
        _ => {
            return Err(Problem::at_line(
                line,
                format!("unknown keyword {}", crate::text::quote(keyword)),
            ));
        }
    };
    let n: usize = t.parse("an element count")?;
    if let Some(width) = skipped_width {
        for _ in 0..n.saturating_mul(width) {
            t.expect(&format!("{keyword} data"))?;
        }
        return Ok((n > 0).then(|| format!("skipped {n} {keyword} (line {line})")));
    }
    let reserve = capped(n, file_len);
    match lower.as_str() {
        "vertices" => {
            m.positions.reserve(reserve);
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
            for _ in 0..n {
                let ([a, b], curve) = element::<2>(t, nv, "an edge reference")?;
                m.feature_edges.push([a, b]);
                m.feature_curves.push(CurveId(curve));
            }
        }
        "triangles" => {
            for _ in 0..n {
                let (tri, patch) = element::<3>(t, nv, "a triangle reference")?;
                m.boundary.push(tri);
                m.boundary_patches.push(PatchId(patch));
            }
        }
        "quadrilaterals" => {
            for _ in 0..n {
                let (q, patch) = element::<4>(t, nv, "a quadrilateral reference")?;
                m.boundary.extend([[q[0], q[1], q[2]], [q[0], q[2], q[3]]]);
                m.boundary_patches.extend([PatchId(patch); 2]);
            }
        }
        _ => {
            m.tets.reserve(reserve);
            for _ in 0..n {
                let (tet, subdomain) = element::<4>(t, nv, "a tetrahedron reference")?;
                m.tets.push(tet);
                m.subdomains.push(SubdomainId(subdomain));
            }
        }
    }
    Ok(None)
}

/// One element: `K` 1-based vertex indices among `nv` vertices, then its reference.
fn element<const K: usize>(
    t: &mut Tokens,
    nv: usize,
    reference: &str,
) -> Result<([u32; K], u32), Problem> {
    let mut ids = [0; K];
    for id in &mut ids {
        *id = t.index_1based(nv)?;
    }
    Ok((ids, t.parse(reference)?))
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
