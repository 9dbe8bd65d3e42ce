//! MEDIT `.sol` solutions (ASCII), the values MMG and Inria's tools attach to a `.mesh`: the
//! scalar `SolAtVertices` fields, for background meshes of sizing fields.

use crate::error::Problem;
use crate::text::{Tokens, as_text, capped};
use delamesh_core::mesh::CellField;

/// MEDIT solution types: scalar, vector, symmetric tensor, and their value counts in 3D.
const SCALAR: u32 = 1;
fn width(kind: u32) -> Option<usize> {
    match kind {
        1 => Some(1),
        2 => Some(3),
        3 => Some(6),
        _ => None,
    }
}

/// The scalar fields of the `SolAtVertices` section, named `1`, `2`... by their position among
/// the section's solutions (vectors and tensors count, and are skipped).
pub(crate) fn read(bytes: &[u8]) -> Result<Vec<CellField>, Problem> {
    let text = as_text(bytes)?;
    let mut t = Tokens::new(&text);
    let mut fields = Vec::new();
    while let Some(keyword) = t.next_token() {
        let lower = keyword.to_ascii_lowercase();
        match lower.as_str() {
            "meshversionformatted" => {
                t.expect("the format version")?;
            }
            "dimension" => {
                let d: u32 = t.parse("the dimension")?;
                if d != 3 {
                    return Err(Problem::at_line(
                        t.line(),
                        format!("dimension {d} solutions are not supported (only 3)"),
                    ));
                }
            }
            "solatvertices" => fields = sol_at_vertices(&mut t, bytes.len())?,
            "end" => break,
            _ => {
                return Err(Problem::at_line(
                    t.line(),
                    format!(
                        "unknown keyword {} (a .sol file with SolAtVertices is read)",
                        crate::text::quote(keyword)
                    ),
                ));
            }
        }
    }
    if fields.is_empty() {
        return Err(Problem::bad("no scalar SolAtVertices solution"));
    }
    Ok(fields)
}

fn sol_at_vertices(t: &mut Tokens, file_len: usize) -> Result<Vec<CellField>, Problem> {
    let n: usize = t.parse("the vertex count")?;
    let kinds: usize = t.parse("the number of solutions")?;
    let mut widths = Vec::with_capacity(kinds.min(16));
    for _ in 0..kinds {
        let kind: u32 = t.parse("a solution type")?;
        let w = width(kind).ok_or_else(|| {
            Problem::at_line(
                t.line(),
                format!("unknown solution type {kind} (1, 2 or 3)"),
            )
        })?;
        widths.push((kind, w));
    }
    let mut fields: Vec<CellField> = widths
        .iter()
        .enumerate()
        .filter(|(_, (kind, _))| *kind == SCALAR)
        .map(|(k, _)| CellField {
            name: (k + 1).to_string(),
            values: Vec::with_capacity(capped(n, file_len)),
        })
        .collect();
    for _ in 0..n {
        let mut scalar = 0;
        for &(kind, w) in &widths {
            for _ in 0..w {
                let v: f64 = t.parse("a solution value")?;
                if kind == SCALAR {
                    fields[scalar].values.push(v);
                }
            }
            scalar += usize::from(kind == SCALAR);
        }
    }
    Ok(fields)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scalar_solutions_are_read_by_position() {
        let text = "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n2\n2 2 1\n\
                    1 2 3 0.5\n4 5 6 0.25\nEnd\n";
        let fields = read(text.as_bytes()).expect("read");
        assert_eq!(fields.len(), 1);
        assert_eq!(fields[0].name, "2");
        assert_eq!(fields[0].values, vec![0.5, 0.25]);
        let e = read(b"MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n1\n1 2\n1 2 3\nEnd")
            .expect_err("no scalar")
            .to_string();
        assert!(e.contains("no scalar"), "{e}");
        let e = read(b"MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n2\n1 1\n0.5\n")
            .expect_err("short")
            .to_string();
        assert!(e.contains("end of file"), "{e}");
    }
}
