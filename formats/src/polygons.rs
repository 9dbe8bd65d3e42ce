//! Polygon meshes as written in the file (not triangulated): the control meshes of subdivision
//! surfaces. OBJ (groups as patches), OFF and PLY (the `patch` face property); the triangle
//! readers of these formats are these readers followed by [`PolygonMesh::triangulated`].

use crate::error::{Error, Problem};
use crate::format::Format;
use delamesh_core::mesh::{PatchId, SurfaceMesh, weld_exact_indices};
use glam::DVec3;
use std::path::Path;

/// Polygons of any size over shared vertices, each in a group.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PolygonMesh {
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Each face's vertices in order (three or more).
    pub faces: Vec<Vec<u32>>,
    /// One entry per face: an index into `group_names`.
    pub groups: Vec<PatchId>,
    /// Indexed by `PatchId`.
    pub group_names: Vec<String>,
}

impl PolygonMesh {
    /// Fan triangulation of every face (exact for the convex faces writers emit), groups as
    /// patches.
    pub fn triangulated(&self) -> SurfaceMesh {
        let mut m = SurfaceMesh {
            positions: self.positions.clone(),
            patch_names: self.group_names.clone(),
            ..SurfaceMesh::default()
        };
        for (face, &group) in self.faces.iter().zip(&self.groups) {
            for k in 1..face.len().saturating_sub(1) {
                m.triangles.push([face[0], face[k], face[k + 1]]);
                m.patches.push(group);
            }
        }
        m
    }

    /// Merges vertices at bit-identical positions (OBJ groups each carry their own copy).
    pub(crate) fn weld(&mut self) {
        let mut flat: Vec<u32> = self.faces.concat();
        if weld_exact_indices(&mut self.positions, &mut flat) > 0 {
            let mut rest = &flat[..];
            for face in &mut self.faces {
                let (head, tail) = rest.split_at(face.len());
                face.copy_from_slice(head);
                rest = tail;
            }
        }
    }

    /// Finite coordinates, indices in range, faces of three or more vertices, something there.
    fn validate(&self) -> Result<(), Problem> {
        if let Some(v) = self.positions.iter().position(|p| !p.is_finite()) {
            return Err(Problem::bad(format!(
                "vertex {v} has a non-finite coordinate"
            )));
        }
        if self.faces.is_empty() {
            return Err(Problem::bad("the mesh has no faces"));
        }
        let n = self.positions.len();
        for (f, face) in self.faces.iter().enumerate() {
            if face.len() < 3 {
                return Err(Problem::bad(format!(
                    "face {f} has {} vertices",
                    face.len()
                )));
            }
            if let Some(&v) = face.iter().find(|&&v| v as usize >= n) {
                return Err(Problem::bad(format!(
                    "face {f} refers to vertex {v}, there are {n} vertices"
                )));
            }
        }
        Ok(())
    }
}

/// Reads the polygons of an OBJ, OFF or PLY file as written (format from the extension unless
/// given), with the reader's warnings.
pub fn read_polygons(
    path: &Path,
    format: Option<Format>,
) -> crate::Result<(PolygonMesh, Vec<String>)> {
    let run = || -> Result<(PolygonMesh, Vec<String>), Problem> {
        let format = crate::resolve(path, format)?;
        let bytes = std::fs::read(path)?;
        read_polygon_bytes(&bytes, format)
    };
    run().map_err(|p| Error::new(path, p))
}

/// [`read_polygons`] of file contents already in memory.
pub fn read_polygon_bytes(
    bytes: &[u8],
    format: Format,
) -> Result<(PolygonMesh, Vec<String>), Problem> {
    if bytes.is_empty() {
        return Err(Problem::bad("the file is empty"));
    }
    let bytes = crate::text::strip_bom(bytes);
    let (mesh, warnings) = match format {
        Format::Obj => crate::obj::read_polygons(bytes)?,
        Format::Off => (crate::off::read_polygons(bytes)?, Vec::new()),
        Format::Ply => (crate::ply::read_polygons(bytes)?, Vec::new()),
        other => {
            return Err(Problem::Unsupported(format!(
                "{other} files hold no polygon control mesh (use OBJ, OFF or PLY)"
            )));
        }
    };
    mesh.validate()?;
    Ok((mesh, warnings))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn obj_polygons_keep_their_arity_and_groups() {
        let src = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\ng a\nf 1 2 3 4\ng b\nf 1 2 5\n";
        let (m, _) = read_polygon_bytes(src.as_bytes(), Format::Obj).unwrap();
        assert_eq!(m.positions.len(), 5);
        assert_eq!(m.faces, vec![vec![0, 1, 2, 3], vec![0, 1, 4]]);
        assert_eq!(m.groups, vec![PatchId(0), PatchId(1)]);
        assert_eq!(m.triangulated().triangles.len(), 3);
    }

    #[test]
    fn off_polygons_as_written() {
        let src = "OFF\n5 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n0 0 1\n4 0 1 2 3\n3 0 1 4\n";
        let (m, _) = read_polygon_bytes(src.as_bytes(), Format::Off).unwrap();
        assert_eq!(m.faces, vec![vec![0, 1, 2, 3], vec![0, 1, 4]]);
        assert!(read_polygon_bytes(b"solid x\n", Format::Stl).is_err());
    }
}
