//! Wavefront OBJ through `tobj` (f64 build): groups / objects become patches, polygons are
//! triangulated as the other polygon formats' (`polygons::polygon_triangles`), negative (relative) indices resolved by tobj. tobj gives each group its own vertex
//! array, so the caller welds the groups back together by exact position.

use crate::error::{Problem, contain_panics};
use crate::polygons::{PolygonMesh, polygon_triangles};
use crate::text::Exact;
use delamesh_core::mesh::{PatchId, SurfaceMesh};
use glam::DVec3;
use std::io::{Cursor, Write};

/// The file's groups as tobj reads them, polygons as written, and the warnings.
fn load(bytes: &[u8]) -> Result<(Vec<tobj::Model>, Vec<String>), Problem> {
    let text = crate::text::as_text(bytes)?;
    let (text, skipped) = faces_only(&text)?;
    let mut warnings = Vec::new();
    if skipped > 0 {
        warnings.push(format!(
            "skipped {skipped} point and line elements (`p`, `l`)"
        ));
    }
    let options = tobj::LoadOptions {
        triangulate: false,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
    };
    // Materials are irrelevant to meshing: never open .mtl files.
    let (models, _materials) = contain_panics(|| {
        tobj::load_obj_buf(&mut Cursor::new(text.as_bytes()), &options, |_| {
            Err(tobj::LoadError::OpenFileFailed)
        })
    })
    .map_err(|why| Problem::bad(format!("not a readable OBJ file: {why}")))?
    .map_err(|e| Problem::bad(format!("not a readable OBJ file: {e}")))?;
    Ok((models, warnings))
}

/// The patch of a group named `name` (groups of the same name share one).
fn group_patch(names: &mut Vec<String>, model: &tobj::Model) -> u32 {
    let name = if model.name.is_empty() {
        "surface".to_owned()
    } else {
        model.name.clone()
    };
    match names.iter().position(|n| *n == name) {
        Some(p) => p as u32,
        None => {
            names.push(name);
            names.len() as u32 - 1
        }
    }
}

/// Appends the vertices of `mesh`; returns the index of its first one and its vertex count.
fn append_positions(positions: &mut Vec<DVec3>, mesh: &tobj::Mesh) -> (u32, usize) {
    let base = positions.len() as u32;
    positions.extend(
        mesh.positions
            .chunks_exact(3)
            .map(|c| DVec3::new(c[0], c[1], c[2])),
    );
    (base, mesh.positions.len() / 3)
}

/// What an OBJ file is read into, group by group and face by face: a surface or a polygon
/// (subdivision control) mesh, so that one loop serves both.
pub(crate) trait ObjMesh: Default {
    /// The patch names and the positions, which each group extends.
    fn names_and_positions(&mut self) -> (&mut Vec<String>, &mut Vec<DVec3>);
    /// Adds a face of patch `patch`, its corners indexing the positions.
    fn add_face(&mut self, patch: u32, face: &[u32]) -> Result<(), Problem>;
}

impl ObjMesh for SurfaceMesh {
    fn names_and_positions(&mut self) -> (&mut Vec<String>, &mut Vec<DVec3>) {
        (&mut self.patch_names, &mut self.positions)
    }

    fn add_face(&mut self, patch: u32, face: &[u32]) -> Result<(), Problem> {
        polygon_triangles(&self.positions, face, &mut self.triangles);
        self.patches.resize(self.triangles.len(), PatchId(patch));
        Ok(())
    }
}

impl ObjMesh for PolygonMesh {
    fn names_and_positions(&mut self) -> (&mut Vec<String>, &mut Vec<DVec3>) {
        (&mut self.group_names, &mut self.positions)
    }

    fn add_face(&mut self, patch: u32, face: &[u32]) -> Result<(), Problem> {
        self.faces.push(face.to_vec());
        self.groups.push(PatchId(patch));
        Ok(())
    }
}

/// The faces of the non-empty groups, each group a patch with its own vertex array appended,
/// and the warnings. Groups are not welded.
pub(crate) fn read<M: ObjMesh>(bytes: &[u8]) -> Result<(M, Vec<String>), Problem> {
    let (models, warnings) = load(bytes)?;
    let mut m = M::default();
    let mut corners = Vec::new();
    for model in &models {
        let mesh = &model.mesh;
        if mesh.indices.is_empty() {
            continue;
        }
        let (names, positions) = m.names_and_positions();
        let patch = group_patch(names, model);
        let (base, n) = append_positions(positions, mesh);
        let mut rest = &mesh.indices[..];
        // tobj leaves `face_arities` empty when every face is a triangle.
        let arities: Vec<u32> = if mesh.face_arities.is_empty() {
            vec![3; mesh.indices.len() / 3]
        } else {
            mesh.face_arities.clone()
        };
        for arity in arities {
            let Some((face, tail)) = rest.split_at_checked(arity as usize) else {
                return Err(Problem::bad("face list shorter than its arities"));
            };
            rest = tail;
            if let Some(&bad) = face.iter().find(|&&v| v as usize >= n) {
                return Err(Problem::bad(format!("face refers to vertex {bad} of {n}")));
            }
            corners.clear();
            corners.extend(face.iter().map(|&v| base + v));
            m.add_face(patch, &corners)?;
        }
    }
    Ok((m, warnings))
}

/// The polygons of an OBJ file as written (a subdivision control mesh), groups as patches,
/// welded by exact position.
pub(crate) fn read_polygons(bytes: &[u8]) -> Result<(PolygonMesh, Vec<String>), Problem> {
    let (mut m, warnings) = read::<PolygonMesh>(bytes)?;
    m.weld();
    Ok((m, warnings))
}

/// The text with point and line elements blanked (tobj's `ignore_lines` still hands polylines
/// over as polygons, which `info` then counted as triangle fans), and how many there were; a face
/// of fewer than three vertices (which tobj drops silently) is an error at its line. Faces keep
/// only their position indices: meshing needs no texture coordinates or normals, and tobj
/// indexes those arrays unchecked.
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
                out.push('f');
                for corner in content.split_whitespace().skip(1) {
                    out.push(' ');
                    out.push_str(corner.split('/').next().unwrap_or(corner));
                }
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

#[cfg(test)]
mod tests {
    /// Texture and normal indices that point nowhere (found by fuzzing: tobj indexed them
    /// unchecked) are dropped with the rest of them: meshing reads positions only.
    #[test]
    fn faces_keep_only_their_position_indices() {
        let text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1/5/7 2/9/-3 3//4\n";
        let (mesh, _) = super::read::<super::SurfaceMesh>(text).unwrap();
        assert_eq!(mesh.triangles.len(), 1);
        assert_eq!(mesh.positions.len(), 3);
    }
}
