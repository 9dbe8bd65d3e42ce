//! Planar straight-line graphs from any 2D input: Triangle `.poly` files, OBJ polylines (`v` and
//! `l` lines) and VTK line cells (`.vtk`, `.vtu`, `.vtp`), the last two in the z = 0 plane. Every
//! vertex of the file is a PSLG point and every polyline edge a segment. OBJ and VTK cannot mark
//! holes or regions: the caller adds hole seeds (the CLI's `--hole`).
//!
//! OBJ is read here rather than through `tobj`, which turns an `l` line of three or more vertices
//! into a polygon face, indistinguishable from an `f` line.

use crate::error::{Error, Problem};
use crate::format::Format;
use crate::poly::{PolyError, read_poly};
use delamesh_core::mesh2d::{Point2, Pslg};
use std::path::Path;

/// Why a PSLG file could not be read.
#[derive(Debug, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum PslgReadError {
    #[error(transparent)]
    Poly(#[from] PolyError),
    #[error(transparent)]
    File(#[from] Error),
}

/// Reads and validates a planar straight-line graph; the format comes from the extension.
pub fn read_pslg(path: &Path) -> Result<Pslg, PslgReadError> {
    let is_poly = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("poly"));
    if is_poly {
        return Ok(read_poly(path)?);
    }
    let run = || -> Result<Pslg, Problem> {
        let format = Format::from_path(path).ok_or_else(|| {
            Problem::Unsupported(
                "a planar straight-line graph is read from .poly, .obj, .vtk, .vtu or .vtp".into(),
            )
        })?;
        let bytes = std::fs::read(path)?;
        let pslg = match format {
            Format::Obj => parse_obj(&bytes)?,
            Format::Vtk | Format::Vtu | Format::Vtp => from_vtk(&bytes, format)?,
            other => {
                return Err(Problem::Unsupported(format!(
                    "{other} files hold no planar straight-line graph: use .poly, .obj or VTK lines"
                )));
            }
        };
        pslg.validate()
            .map_err(|e| Problem::bad(format!("invalid planar straight-line graph: {e}")))?;
        Ok(pslg)
    };
    run().map_err(|p| Error::new(path, p).into())
}

/// The z = 0 check shared by both formats.
fn planar(index: usize, z: f64) -> Result<(), String> {
    if z == 0.0 {
        Ok(())
    } else {
        Err(format!(
            "vertex {index} has z = {z}: a planar straight-line graph lies in the z = 0 plane"
        ))
    }
}

fn from_vtk(bytes: &[u8], format: Format) -> Result<Pslg, Problem> {
    if bytes.is_empty() {
        return Err(Problem::bad("the file is empty"));
    }
    let (mesh, _warnings, _poly) = crate::vtk::read_cells(bytes, format)?;
    if mesh.feature_edges.is_empty() {
        return Err(Problem::bad("no line cells: nothing to mesh"));
    }
    let mut points = Vec::with_capacity(mesh.positions.len());
    for (i, p) in mesh.positions.iter().enumerate() {
        if !p.is_finite() {
            return Err(Problem::bad(format!(
                "vertex {i} has a non-finite coordinate"
            )));
        }
        planar(i, p.z).map_err(Problem::bad)?;
        points.push(p.truncate());
    }
    let segments = mesh.feature_edges;
    Ok(Pslg {
        points,
        segment_markers: vec![0; segments.len()],
        segments,
        ..Pslg::default()
    })
}

/// `v x y [z [w]]` and `l i j ...` lines (1-based or negative relative indices, `i/t` accepted);
/// faces are refused, other statements (groups, normals, materials...) ignored.
fn parse_obj(bytes: &[u8]) -> Result<Pslg, Problem> {
    let text = std::str::from_utf8(bytes).map_err(|e| Problem::bad(format!("not text: {e}")))?;
    let mut points: Vec<Point2> = Vec::new();
    let mut segments = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let line_no = n + 1;
        let content = line.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        let err = |m: String| Problem::at_line(line_no, m);
        match words.next() {
            Some("v") => {
                let c: Vec<f64> = words
                    .map(|w| w.parse::<f64>())
                    .collect::<Result<_, _>>()
                    .map_err(|e| err(format!("bad vertex coordinate: {e}")))?;
                if c.len() < 2 {
                    return Err(err("a vertex needs x and y".into()));
                }
                if c.iter().take(3).any(|x| !x.is_finite()) {
                    return Err(err(format!(
                        "vertex {} has a non-finite coordinate",
                        points.len() + 1
                    )));
                }
                if let Some(&z) = c.get(2) {
                    planar(points.len() + 1, z).map_err(err)?;
                }
                points.push(Point2::new(c[0], c[1]));
            }
            Some("l") => {
                let ids: Vec<u32> = words
                    .map(|w| obj_index(w, points.len()).map_err(&err))
                    .collect::<Result<_, _>>()?;
                if ids.len() < 2 {
                    return Err(err("a polyline needs at least two vertices".into()));
                }
                segments.extend(ids.windows(2).map(|w| [w[0], w[1]]));
            }
            Some("f") => {
                return Err(err(
                    "faces are not read: give the boundary as `l` polylines".into(),
                ));
            }
            _ => {}
        }
    }
    if segments.is_empty() {
        return Err(Problem::bad("no `l` polylines: nothing to mesh"));
    }
    Ok(Pslg {
        points,
        segment_markers: vec![0; segments.len()],
        segments,
        ..Pslg::default()
    })
}

/// 0-based index of an OBJ vertex reference among the `count` vertices read so far.
fn obj_index(word: &str, count: usize) -> Result<u32, String> {
    let head = word.split('/').next().unwrap_or("");
    let k: i64 = head
        .parse()
        .map_err(|_| format!("bad vertex index {}", crate::text::quote(word)))?;
    let index = if k > 0 { k - 1 } else { count as i64 + k };
    if k == 0 || index < 0 || index >= count as i64 {
        return Err(format!(
            "vertex index {k} out of range: {count} vertices so far"
        ));
    }
    u32::try_from(index).map_err(|_| format!("vertex index {k} too large"))
}

#[cfg(test)]
mod tests {
    use super::parse_obj;

    #[test]
    fn obj_polylines_become_segments() {
        let pslg = parse_obj(b"v 0 0\nv 1 0 0\nv 1 1\nl 1 2 3 -3\n").expect("reads");
        assert_eq!(pslg.points.len(), 3);
        assert_eq!(pslg.segments, vec![[0, 1], [1, 2], [2, 0]]);
    }

    #[test]
    fn obj_errors_name_the_line() {
        for (text, line) in [
            (&b"v 0 0\nv 1 0 1\n"[..], "line 2"),
            (b"v 0 0\nv nan 1\n", "line 2"),
            (b"v 0 0\nl 1 3\n", "line 2"),
            (b"v 0\n", "line 1"),
            (b"v 0 0\nv 1 0\nv 0 1\nf 1 2 3\n", "line 4"),
        ] {
            let e = parse_obj(text).expect_err("bad file").to_string();
            assert!(e.contains(line), "{e}");
        }
    }
}
