//! Wavefront OBJ through `tobj` (f64 build): groups / objects become patches, polygons are
//! triangulated, negative (relative) indices resolved by tobj. tobj gives each group its own vertex
//! array, so the caller welds the groups back together by exact position.

use crate::error::Problem;
use crate::text::Exact;
use delamesh_core::mesh::{PatchId, SurfaceMesh};
use glam::DVec3;
use std::io::{Cursor, Write};

pub(crate) fn read(bytes: &[u8]) -> Result<(SurfaceMesh, Vec<String>), Problem> {
    let text = crate::text::as_text(bytes)?;
    let (text, skipped) = faces_only(&text)?;
    let mut warnings = Vec::new();
    if skipped > 0 {
        warnings.push(format!(
            "skipped {skipped} point and line elements (`p`, `l`)"
        ));
    }
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are irrelevant to meshing: never open .mtl files.
    let (models, _materials) =
        tobj::load_obj_buf(&mut Cursor::new(text.as_bytes()), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
        .map_err(|e| Problem::bad(format!("not a readable OBJ file: {e}")))?;
    let mut m = SurfaceMesh::default();
    for model in models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let name = if model.name.is_empty() {
            "surface".to_owned()
        } else {
            model.name.clone()
        };
        let patch = match m.patch_names.iter().position(|n| *n == name) {
            Some(p) => p,
            None => {
                m.patch_names.push(name);
                m.patch_names.len() - 1
            }
        };
        let base = m.positions.len() as u32;
        let n = mesh.positions.len() / 3;
        m.positions.extend(
            mesh.positions
                .chunks_exact(3)
                .map(|c| DVec3::new(c[0], c[1], c[2])),
        );
        for tri in mesh.indices.chunks_exact(3) {
            if let Some(&bad) = tri.iter().find(|&&v| v as usize >= n) {
                return Err(Problem::bad(format!("face refers to vertex {bad} of {n}")));
            }
            m.triangles
                .push([base + tri[0], base + tri[1], base + tri[2]]);
            m.patches.push(PatchId(patch as u32));
        }
    }
    Ok((m, warnings))
}

/// The text with point and line elements blanked (tobj's `ignore_lines` still hands polylines
/// over as polygons, which `info` then counted as triangle fans), and how many there were; a face
/// of fewer than three vertices (which tobj drops silently) is an error at its line.
fn faces_only(text: &str) -> Result<(String, usize), Problem> {
    let mut out = String::with_capacity(text.len());
    let mut skipped = 0;
    for (i, line) in text.lines().enumerate() {
        let content = line.split('#').next().unwrap_or("");
        let mut words = content.split_whitespace();
        match words.next() {
            Some("p" | "l") => skipped += 1,
            Some("f") => {
                let corners = words.count();
                if corners < 3 {
                    return Err(Problem::at_line(
                        i + 1,
                        format!("face with {corners} vertices (a face needs 3 or more)"),
                    ));
                }
                out.push_str(line);
            }
            _ => out.push_str(line),
        }
        out.push('\n');
    }
    Ok((out, skipped))
}

/// Number of `v` lines: what the file holds before tobj splits it into groups.
pub(crate) fn vertex_count(bytes: &[u8]) -> usize {
    bytes
        .split(|&b| b == b'\n')
        .filter(|l| matches!(l.trim_ascii_start(), [b'v', b' ' | b'\t', ..]))
        .count()
}

/// One `g` group per run of triangles of the same patch.
pub(crate) fn write(w: &mut dyn Write, m: &SurfaceMesh) -> Result<(), Problem> {
    writeln!(w, "# written by delamesh")?;
    for p in &m.positions {
        writeln!(w, "v {} {} {}", Exact(p.x), Exact(p.y), Exact(p.z))?;
    }
    let mut current = None;
    for (t, p) in m.triangles.iter().zip(&m.patches) {
        if current != Some(*p) {
            let name = m
                .patch_names
                .get(p.0 as usize)
                .map_or("surface", String::as_str);
            // OBJ group names end at whitespace.
            writeln!(
                w,
                "g {}",
                name.split_whitespace().collect::<Vec<_>>().join("_")
            )?;
            current = Some(*p);
        }
        writeln!(w, "f {} {} {}", t[0] + 1, t[1] + 1, t[2] + 1)?;
    }
    Ok(())
}
