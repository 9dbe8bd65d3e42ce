//! OFF (Geomview Object File Format), hand-written: no maintained crate reads it. Accepts comments,
//! the `C`/`N`/`ST` header variants with extra per-vertex values, polygon faces and face colours.

use crate::error::Problem;
use crate::polygons::PolygonMesh;
use crate::text::{Exact, Tokens, as_text, capped};
use delamesh_core::mesh::{PatchId, SurfaceMesh};
use glam::DVec3;
use std::io::Write;

pub(crate) fn read(bytes: &[u8]) -> Result<SurfaceMesh, Problem> {
    read_polygons(bytes).map(|m| m.triangulated())
}

/// The polygons as written (a subdivision control mesh), one group.
pub(crate) fn read_polygons(bytes: &[u8]) -> Result<PolygonMesh, Problem> {
    let text = as_text(bytes)?;
    let mut t = Tokens::new(&text);
    let header = t.expect("the OFF header")?;
    let variant = header.strip_suffix("OFF").filter(|p| {
        let p = p.strip_prefix("ST").unwrap_or(p);
        matches!(p, "" | "C" | "N" | "NC" | "CN")
    });
    if variant.is_none() {
        return Err(Problem::at_line(
            t.line(),
            format!(
                "expected an OFF header, found {}",
                crate::text::quote(header)
            ),
        ));
    }
    let nv: usize = t.parse("the vertex count")?;
    let nf: usize = t.parse("the face count")?;
    let _edges: usize = t.parse("the edge count")?;
    t.skip_rest_of_line();
    let mut positions = Vec::with_capacity(capped(nv, bytes.len()));
    for _ in 0..nv {
        positions.push(DVec3::new(
            t.coordinate()?,
            t.coordinate()?,
            t.coordinate()?,
        ));
        t.skip_rest_of_line();
    }
    let mut faces = Vec::with_capacity(capped(nf, bytes.len()));
    for _ in 0..nf {
        let n: usize = t.parse("a face size")?;
        if n < 3 {
            return Err(Problem::at_line(
                t.line(),
                format!("face with {n} vertices"),
            ));
        }
        let mut polygon = Vec::with_capacity(capped(n, bytes.len()));
        for _ in 0..n {
            polygon.push(t.index_0based(nv)?);
        }
        t.skip_rest_of_line();
        faces.push(polygon);
    }
    Ok(PolygonMesh {
        positions,
        groups: vec![PatchId(0); faces.len()],
        faces,
        group_names: vec!["surface".into()],
    })
}

pub(crate) fn write(w: &mut dyn Write, mesh: &SurfaceMesh) -> Result<(), Problem> {
    writeln!(w, "OFF")?;
    writeln!(w, "{} {} 0", mesh.positions.len(), mesh.triangles.len())?;
    for p in &mesh.positions {
        writeln!(w, "{} {} {}", Exact(p.x), Exact(p.y), Exact(p.z))?;
    }
    for [a, b, c] in &mesh.triangles {
        writeln!(w, "3 {a} {b} {c}")?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_comments_colours_and_polygons() {
        let src = "# a quad and a triangle\nCOFF\n5 2 0\n0 0 0 1 0 0 1\n1 0 0 1 0 0 1\n1 1 0 0 0 0 1\n0 1 0 0 0 0 1\n0 0 1 0 0 0 1\n4 0 1 2 3 255 0 0\n3 0 1 4\n";
        let m = read(src.as_bytes()).unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 1, 4]]);
    }

    #[test]
    fn errors_name_the_line() {
        let e = read(b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n")
            .err()
            .map(|e| e.to_string());
        assert_eq!(
            e.as_deref(),
            Some("line 6: vertex index 7 out of range 0..3")
        );
        let e = read(b"OFF\n3 1 0\n0 0 0\n1 inf 0\n")
            .err()
            .map(|e| e.to_string());
        assert_eq!(e.as_deref(), Some("line 4: non-finite coordinate inf"));
        assert!(read(b"OFF\n300 1 0\n0 0 0\n").is_err());
        assert!(read(b"PLY\n").is_err());
        assert!(read(b"4OFF\n").is_err());
    }
}
