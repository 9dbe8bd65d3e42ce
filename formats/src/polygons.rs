//! Polygon meshes as written in the file (not triangulated): the control meshes of subdivision
//! surfaces. OBJ (groups as patches), OFF and PLY (the `patch` face property); the triangle
//! readers of these formats are these readers followed by [`PolygonMesh::triangulated`].

use crate::error::{Error, Problem};
use crate::format::Format;
use delamesh_core::kernel::{Sign, orient2d};
use delamesh_core::mesh::{PatchId, SurfaceMesh, newell_normal, weld_exact_indices};
use glam::{DVec2, DVec3};
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
    /// Every face cut into triangles (see [`polygon_triangles`]), groups as patches.
    pub fn triangulated(&self) -> SurfaceMesh {
        let mut m = SurfaceMesh {
            positions: self.positions.clone(),
            patch_names: self.group_names.clone(),
            ..SurfaceMesh::default()
        };
        for (face, &group) in self.faces.iter().zip(&self.groups) {
            polygon_triangles(&self.positions, face, &mut m.triangles);
            m.patches.resize(m.triangles.len(), group);
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

/// Polygons with more vertices than this are cut as a fan: ear clipping takes time quadratic in
/// the vertex count (cubic at worst).
const MAX_CLIPPED: usize = 1024;

/// Appends the triangles of polygon `face` (its vertices in order) to `out`, turning as it
/// turns. A convex polygon (every turn the same way about its Newell normal: what writers
/// emit) is cut as a fan from its first vertex; a non-convex one (an L-shaped face, a dart),
/// whose fan would fold triangles over one another, by ear clipping in the plane across its
/// normal's largest coordinate.
pub(crate) fn polygon_triangles(positions: &[DVec3], face: &[u32], out: &mut Vec<[u32; 3]>) {
    let point = |v: u32| positions[v as usize];
    let n = face.len();
    let normal = newell_normal(positions, face);
    let turn =
        |a: u32, b: u32, c: u32| (point(b) - point(a)).cross(point(c) - point(b)).dot(normal);
    let convex = (0..n).all(|k| turn(face[k], face[(k + 1) % n], face[(k + 2) % n]) >= 0.0);
    if n == 3 || convex || n > MAX_CLIPPED || !normal.is_finite() {
        out.extend((1..n.saturating_sub(1)).map(|k| [face[0], face[k], face[k + 1]]));
        return;
    }
    // Coordinates in the plane across the normal's largest coordinate, oriented so that the
    // polygon turns counter-clockwise.
    let axis = normal.abs().max_position();
    let (i, j) = ((axis + 1) % 3, (axis + 2) % 3);
    let flip = normal[axis] < 0.0;
    let flat = |v: u32| {
        let p = point(v);
        if flip {
            DVec2::new(p[j], p[i])
        } else {
            DVec2::new(p[i], p[j])
        }
    };
    let right = |a, b, c| orient2d(a, b, c) == Sign::Negative;
    let mut left: Vec<u32> = face.to_vec();
    // The search for the next ear starts where the last one was cut: ears cluster, and a
    // search from the start again would make clipping cubic in the vertex count.
    let mut from = 0;
    while left.len() > 3 {
        let m = left.len();
        let ear = (0..m).map(|s| (from + s) % m).find(|&k| {
            let (a, b, c) = (left[(k + m - 1) % m], left[k], left[(k + 1) % m]);
            let (pa, pb, pc) = (flat(a), flat(b), flat(c));
            orient2d(pa, pb, pc) == Sign::Positive
                && left.iter().all(|&v| {
                    v == a || v == b || v == c || {
                        let q = flat(v);
                        right(pa, pb, q) || right(pb, pc, q) || right(pc, pa, q)
                    }
                })
        });
        // No ear where rounding or a self-crossing polygon leaves none: the rest as a fan.
        let Some(k) = ear else { break };
        out.push([left[(k + m - 1) % m], left[k], left[(k + 1) % m]]);
        left.remove(k);
        from = k.saturating_sub(1);
    }
    out.extend((1..left.len().saturating_sub(1)).map(|k| [left[0], left[k], left[k + 1]]));
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

    /// The triangles of a face cover it once: their area vectors sum to the polygon's, and each
    /// turns as the polygon does (no triangle folded over another).
    fn assert_covers(positions: &[DVec3], face: &[u32]) {
        let mut triangles = Vec::new();
        polygon_triangles(positions, face, &mut triangles);
        assert_eq!(triangles.len(), face.len() - 2);
        let p = |v: u32| positions[v as usize];
        let area = newell_normal(positions, face);
        let mut sum = DVec3::ZERO;
        for [a, b, c] in triangles {
            let t = (p(b) - p(a)).cross(p(c) - p(a));
            assert!(t.dot(area) > 0.0, "triangle {a} {b} {c} folded");
            sum += t;
        }
        assert!(
            (sum - area).length() < 1e-12 * area.length(),
            "{sum} against {area}"
        );
    }

    #[test]
    fn non_convex_faces_are_cut_by_ear_clipping_and_convex_ones_as_fans() {
        // An L-shaped hexagon, a dart (its reflex vertex first, where a fan folds), both in a
        // tilted plane and in both turning directions.
        let tilt = |x: f64, y: f64| DVec3::new(x, y, 0.3 * x - 0.2 * y);
        let l = [
            (0.0, 0.0),
            (2.0, 0.0),
            (2.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let dart = [(1.0, 0.8), (0.0, 2.0), (1.0, 0.0), (2.0, 2.0)];
        for shape in [&l[..], &dart[..]] {
            let positions: Vec<DVec3> = shape.iter().map(|&(x, y)| tilt(x, y)).collect();
            let mut face: Vec<u32> = (0..shape.len() as u32).collect();
            for _ in 0..face.len() {
                face.rotate_left(1);
                assert_covers(&positions, &face);
                let reversed: Vec<u32> = face.iter().rev().copied().collect();
                assert_covers(&positions, &reversed);
            }
        }
        let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
        let mut triangles = Vec::new();
        polygon_triangles(&square, &[0, 1, 2, 3], &mut triangles);
        assert_eq!(triangles, vec![[0, 1, 2], [0, 2, 3]]);
    }
}
