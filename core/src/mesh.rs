//! Mesh data model shared by formats, plugins and the mesher: surfaces, tet meshes, images.
//!
//! Connectivity is stored as plain `u32` vertex indices (`[u32; 3]` triangles, `[u32; 4]` tets) because
//! that is what every file format and the refinement engine exchange in bulk; the labels that carry
//! meaning (patch, subdomain, curve) are newtypes so they cannot be mixed up.

mod coplanar;
mod topology;
mod weld;

pub use coplanar::{CoplanarFlips, flip_coplanar};
pub use topology::{
    Topology, component_euler_characteristics, count_phrases, non_manifold_elements,
    surface_topology,
};
pub use weld::{weld_exact, weld_exact_indices};

use glam::DVec3;
use std::fmt;

/// Surface patch label of a boundary triangle (an index into `SurfaceMesh::patch_names` for surfaces).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct PatchId(pub u32);

/// Subdomain label of a tetrahedron (0 is reserved for "outside" by the oracle, so real subdomains are ≥ 1).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct SubdomainId(pub u32);

/// Feature-curve label of a constrained edge.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
#[repr(transparent)]
pub struct CurveId(pub u32);

// The labels print as their numbers, as files and messages give them.
impl fmt::Display for PatchId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl fmt::Display for SubdomainId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

impl fmt::Display for CurveId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        self.0.fmt(f)
    }
}

/// A structural defect found by a `validate` method: the model forbids it, whatever the file said.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum MeshError {
    #[error("vertex {vertex} has a non-finite coordinate ({x}, {y}, {z})")]
    NonFinite {
        vertex: usize,
        x: f64,
        y: f64,
        z: f64,
    },
    #[error("{element} {index} refers to vertex {vertex}, but there are only {count} vertices")]
    IndexOutOfRange {
        element: &'static str,
        index: usize,
        vertex: u32,
        count: usize,
    },
    #[error("{what} has {got} entries, expected {expected} (one per {per})")]
    LengthMismatch {
        what: String,
        got: usize,
        expected: usize,
        per: &'static str,
    },
    #[error("patch id {patch} of triangle {triangle} has no name (only {names} patch names)")]
    UnnamedPatch {
        triangle: usize,
        patch: u32,
        names: usize,
    },
    #[error("the mesh is empty: {0}")]
    Empty(&'static str),
}

/// A triangulated surface with a patch label per triangle.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SurfaceMesh {
    /// Vertex coordinates.
    pub positions: Vec<DVec3>,
    /// Vertex indices of each triangle, counter-clockwise seen from outside on a closed surface.
    pub triangles: Vec<[u32; 3]>,
    /// One entry per triangle.
    pub patches: Vec<PatchId>,
    /// Indexed by `PatchId`; a file without named parts gets a single patch.
    pub patch_names: Vec<String>,
}

/// A named scalar per tetrahedron, e.g. `min_dihedral_deg` or `radius_edge`.
#[derive(Clone, Debug, PartialEq)]
pub struct CellField {
    /// The name written to the file (a VTK array name, for instance).
    pub name: String,
    /// One value per tetrahedron.
    pub values: Vec<f64>,
}

/// A tetrahedral mesh with its boundary triangles and optional feature edges.
///
/// Tets are positively oriented as VTK, MEDIT and Gmsh expect: `det[b-a, c-a, d-a] > 0` (the
/// opposite of Shewchuk's `orient3d` sign used inside the triangulations). Boundary triangles of a
/// closed boundary are oriented with outward normals.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TetMesh {
    /// Vertex coordinates.
    pub positions: Vec<DVec3>,
    /// Vertex indices of each tetrahedron, positively oriented.
    pub tets: Vec<[u32; 4]>,
    /// One entry per tet.
    pub subdomains: Vec<SubdomainId>,
    /// Boundary triangles: between two subdomains or a subdomain and the outside.
    pub boundary: Vec<[u32; 3]>,
    /// One entry per boundary triangle.
    pub boundary_patches: Vec<PatchId>,
    /// Mesh edges along the input's feature curves, written as line cells.
    pub feature_edges: Vec<[u32; 2]>,
    /// One entry per feature edge.
    pub feature_curves: Vec<CurveId>,
    /// Per-tet scalar fields, written as cell data next to `subdomain`.
    pub cell_fields: Vec<CellField>,
}

/// Voxel labels of a 3D image, stored x fastest, then y, then z.
#[derive(Clone, Debug, PartialEq)]
pub enum Labels {
    /// Labels stored in one byte each.
    U8(Vec<u8>),
    /// Labels stored in two bytes each (images with more than 256 labels).
    U16(Vec<u16>),
}

impl Labels {
    /// The number of voxels.
    pub fn len(&self) -> usize {
        match self {
            Labels::U8(v) => v.len(),
            Labels::U16(v) => v.len(),
        }
    }

    /// Whether the image has no voxel.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A labelled 3D image: voxel `(i, j, k)` has its centre at `origin + spacing * (i, j, k)`.
#[derive(Clone, Debug, PartialEq)]
pub struct LabelledImage {
    /// Voxel counts along x, y and z.
    pub dims: [usize; 3],
    /// Distance between voxel centres along each axis.
    pub spacing: DVec3,
    /// Centre of voxel `(0, 0, 0)`.
    pub origin: DVec3,
    /// One label per voxel, x fastest.
    pub labels: Labels,
}

impl LabelledImage {
    /// The label of voxel `(i, j, k)`, or `None` outside the image.
    pub fn label(&self, i: usize, j: usize, k: usize) -> Option<u16> {
        let [nx, ny, nz] = self.dims;
        if i >= nx || j >= ny || k >= nz {
            return None;
        }
        let at = i + nx * (j + ny * k);
        match &self.labels {
            Labels::U8(v) => v.get(at).map(|&l| u16::from(l)),
            Labels::U16(v) => v.get(at).copied(),
        }
    }

    /// Checks that there is one label per voxel and that the spacing is positive and finite,
    /// so that the oracle built on the image can index it without checks.
    pub fn validate(&self) -> Result<(), MeshError> {
        let expected = self.dims.iter().product::<usize>();
        if expected == 0 {
            return Err(MeshError::Empty("the image has no voxels"));
        }
        check_len("labels", self.labels.len(), expected, "voxel")
    }
}

/// Axis-aligned bounding box of a point set.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    /// The corner with the smallest coordinates.
    pub min: DVec3,
    /// The corner with the largest coordinates.
    pub max: DVec3,
}

impl Aabb {
    /// `None` for an empty point set.
    pub fn of(points: &[DVec3]) -> Option<Aabb> {
        let first = *points.first()?;
        Some(points.iter().fold(
            Aabb {
                min: first,
                max: first,
            },
            |b, &p| Aabb {
                min: b.min.min(p),
                max: b.max.max(p),
            },
        ))
    }
}

impl fmt::Display for Aabb {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "[{}, {}, {}] .. [{}, {}, {}]",
            self.min.x, self.min.y, self.min.z, self.max.x, self.max.y, self.max.z
        )
    }
}

/// Names `"patch {label}"` for patch labels read from a file, making `patches` valid indices into
/// them. Labels stay the patch ids when the name table they index is no longer than the triangle list
/// (always the case for meshes delamesh writes); otherwise they are renumbered densely in increasing
/// order, so that a hostile label of 4 billion cannot make us allocate 4 billion names.
pub fn name_patch_labels(patches: &mut [PatchId]) -> Vec<String> {
    let max = patches.iter().map(|p| p.0 as usize).max().unwrap_or(0);
    if max <= patches.len().max(64) {
        return (0..=max).map(|p| format!("patch {p}")).collect();
    }
    let mut labels: Vec<u32> = patches.iter().map(|p| p.0).collect();
    labels.sort_unstable();
    labels.dedup();
    for p in patches.iter_mut() {
        p.0 = labels.binary_search(&p.0).map_or(0, |i| i as u32);
    }
    labels.iter().map(|l| format!("patch {l}")).collect()
}

fn check_positions(positions: &[DVec3]) -> Result<(), MeshError> {
    match positions.iter().position(|p| !p.is_finite()) {
        Some(vertex) => {
            let p = positions[vertex];
            Err(MeshError::NonFinite {
                vertex,
                x: p.x,
                y: p.y,
                z: p.z,
            })
        }
        None => Ok(()),
    }
}

fn check_indices<const N: usize>(
    element: &'static str,
    cells: &[[u32; N]],
    count: usize,
) -> Result<(), MeshError> {
    match first_out_of_range(cells, count) {
        Some((index, vertex)) => Err(MeshError::IndexOutOfRange {
            element,
            index,
            vertex,
            count,
        }),
        None => Ok(()),
    }
}

/// Newell's normal of the polygon `face` (its corners in order, indexing `positions`): twice its
/// area along its unit normal when it is planar, the normal of best fit when it is not, zero when
/// its corners are all on one line. Its direction follows the polygon's turning.
///
/// ```
/// use delamesh_core::mesh::newell_normal;
/// use glam::DVec3;
/// let square = [DVec3::ZERO, DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Y];
/// assert_eq!(newell_normal(&square, &[0, 1, 2, 3]), DVec3::new(0.0, 0.0, 2.0));
/// ```
pub fn newell_normal(positions: &[DVec3], face: &[u32]) -> DVec3 {
    let n = face.len();
    let p = |k: usize| positions[face[k % n] as usize];
    (0..n).map(|k| p(k).cross(p(k + 1))).sum()
}

/// The first cell naming a vertex `>= count`, as `(cell, vertex)`: the bounds check every reader
/// of indexed cells makes before it looks positions up.
pub fn first_out_of_range<const N: usize>(
    cells: &[[u32; N]],
    count: usize,
) -> Option<(usize, u32)> {
    cells
        .iter()
        .enumerate()
        .find_map(|(i, cell)| cell.iter().find(|&&v| v as usize >= count).map(|&v| (i, v)))
}

fn check_len(what: &str, got: usize, expected: usize, per: &'static str) -> Result<(), MeshError> {
    if got == expected {
        Ok(())
    } else {
        Err(MeshError::LengthMismatch {
            what: what.to_owned(),
            got,
            expected,
            per,
        })
    }
}

impl SurfaceMesh {
    /// A surface of one unnamed patch from vertex positions and triangles (indices into
    /// `positions`), as a caller that built it in memory has it.
    pub fn from_triangles(positions: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> SurfaceMesh {
        SurfaceMesh {
            patches: vec![PatchId(0); triangles.len()],
            positions,
            triangles,
            patch_names: vec![String::new()],
        }
    }

    /// An icosphere: `subdivisions` splits of an icosahedron (each triangle into four), projected
    /// on the sphere, in one patch: the smooth closed test domain that tests and benches share.
    pub fn icosphere(center: DVec3, radius: f64, subdivisions: usize) -> SurfaceMesh {
        let t = (1.0 + 5f64.sqrt()) / 2.0;
        let mut points: Vec<DVec3> = [
            (-1.0, t, 0.0),
            (1.0, t, 0.0),
            (-1.0, -t, 0.0),
            (1.0, -t, 0.0),
            (0.0, -1.0, t),
            (0.0, 1.0, t),
            (0.0, -1.0, -t),
            (0.0, 1.0, -t),
            (t, 0.0, -1.0),
            (t, 0.0, 1.0),
            (-t, 0.0, -1.0),
            (-t, 0.0, 1.0),
        ]
        .iter()
        .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
        .collect();
        let mut triangles: Vec<[u32; 3]> = vec![
            [0, 11, 5],
            [0, 5, 1],
            [0, 1, 7],
            [0, 7, 10],
            [0, 10, 11],
            [1, 5, 9],
            [5, 11, 4],
            [11, 10, 2],
            [10, 7, 6],
            [7, 1, 8],
            [3, 9, 4],
            [3, 4, 2],
            [3, 2, 6],
            [3, 6, 8],
            [3, 8, 9],
            [4, 9, 5],
            [2, 4, 11],
            [6, 2, 10],
            [8, 6, 7],
            [9, 8, 1],
        ];
        for _ in 0..subdivisions {
            let mut mid = std::collections::BTreeMap::new();
            let mut midpoint = |a: u32, b: u32, points: &mut Vec<DVec3>| {
                *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                    points.push(((points[a as usize] + points[b as usize]) / 2.0).normalize());
                    points.len() as u32 - 1
                })
            };
            let mut next = Vec::new();
            for [a, b, c] in triangles {
                let (ab, bc, ca) = (
                    midpoint(a, b, &mut points),
                    midpoint(b, c, &mut points),
                    midpoint(c, a, &mut points),
                );
                next.extend([[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
            }
            triangles = next;
        }
        let patches = vec![PatchId(0); triangles.len()];
        SurfaceMesh {
            positions: points.into_iter().map(|p| center + radius * p).collect(),
            triangles,
            patches,
            patch_names: vec!["sphere".to_string()],
        }
    }

    /// The axis-aligned box from `min` to `max` as 12 outward-oriented triangles in one patch: the
    /// smallest closed test domain, and the one tests across the workspace share.
    pub fn cuboid(min: DVec3, max: DVec3) -> SurfaceMesh {
        let positions = (0..8)
            .map(|i| {
                DVec3::new(
                    if i & 1 == 0 { min.x } else { max.x },
                    if i & 2 == 0 { min.y } else { max.y },
                    if i & 4 == 0 { min.z } else { max.z },
                )
            })
            .collect();
        let quads = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        let triangles = quads
            .iter()
            .flat_map(|&[a, b, c, d]| [[a, b, c], [a, c, d]])
            .collect();
        SurfaceMesh {
            positions,
            triangles,
            patches: vec![PatchId(0); 12],
            patch_names: vec!["box".to_string()],
        }
    }

    /// Finite coordinates, indices in range, one patch per triangle, every patch named, not empty.
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.triangles.is_empty() {
            return Err(MeshError::Empty("no triangles"));
        }
        check_positions(&self.positions)?;
        check_indices("triangle", &self.triangles, self.positions.len())?;
        check_len(
            "patch ids",
            self.patches.len(),
            self.triangles.len(),
            "triangle",
        )?;
        let names = self.patch_names.len();
        if let Some((triangle, p)) = self
            .patches
            .iter()
            .enumerate()
            .find(|(_, p)| p.0 as usize >= names)
        {
            return Err(MeshError::UnnamedPatch {
                triangle,
                patch: p.0,
                names,
            });
        }
        Ok(())
    }

    /// The box around the vertices, or `None` for an empty mesh.
    pub fn bounding_box(&self) -> Option<Aabb> {
        Aabb::of(&self.positions)
    }

    /// Closedness, manifoldness, Euler characteristic, orientation, volume (see [`Topology`]).
    pub fn topology(&self) -> Topology {
        surface_topology(&self.positions, &self.triangles)
    }

    /// The triangles' patches numbered from 1, as the oracles number them: the readers number
    /// them from 0, and 0 marks facets of no patch in a mesh.
    pub fn oracle_patches(&self) -> Vec<PatchId> {
        self.patches.iter().map(|p| PatchId(p.0 + 1)).collect()
    }
}

impl TetMesh {
    /// Finite coordinates, indices in range, one label per element, one value per tet in every field.
    pub fn validate(&self) -> Result<(), MeshError> {
        if self.tets.is_empty() && self.boundary.is_empty() {
            return Err(MeshError::Empty("no tetrahedra and no boundary triangles"));
        }
        check_positions(&self.positions)?;
        let n = self.positions.len();
        check_indices("tetrahedron", &self.tets, n)?;
        check_indices("boundary triangle", &self.boundary, n)?;
        check_indices("feature edge", &self.feature_edges, n)?;
        check_len(
            "subdomain ids",
            self.subdomains.len(),
            self.tets.len(),
            "tetrahedron",
        )?;
        check_len(
            "patch ids",
            self.boundary_patches.len(),
            self.boundary.len(),
            "boundary triangle",
        )?;
        check_len(
            "curve ids",
            self.feature_curves.len(),
            self.feature_edges.len(),
            "feature edge",
        )?;
        for field in &self.cell_fields {
            check_len(
                &format!("cell field {:?}", field.name),
                field.values.len(),
                self.tets.len(),
                "tetrahedron",
            )?;
        }
        Ok(())
    }

    /// The box around the vertices, or `None` for an empty mesh.
    pub fn bounding_box(&self) -> Option<Aabb> {
        Aabb::of(&self.positions)
    }

    /// Signed volume of tet `t`: positive for the right-handed orientation `(b-a)×(c-a)·(d-a) > 0`.
    pub fn tet_volume(&self, t: usize) -> f64 {
        let [a, b, c, d] = self.tets[t].map(|v| self.positions[v as usize]);
        (b - a).cross(c - a).dot(d - a) / 6.0
    }

    /// The boundary triangles as a surface, patches named after their labels (see
    /// [`name_patch_labels`]).
    pub fn boundary_surface(&self) -> SurfaceMesh {
        let mut patches = self.boundary_patches.clone();
        let patch_names = name_patch_labels(&mut patches);
        SurfaceMesh {
            positions: self.positions.clone(),
            triangles: self.boundary.clone(),
            patches,
            patch_names,
        }
    }

    /// Faces of the tets that belong to exactly one tet, oriented outward (seen from outside they are
    /// counter-clockwise) for positively oriented tets; used when a file carries tets but no boundary.
    pub fn exterior_faces(&self) -> Vec<[u32; 3]> {
        let mut faces: Vec<([u32; 3], [u32; 3])> = Vec::with_capacity(self.tets.len() * 4);
        for &[a, b, c, d] in &self.tets {
            for f in [[b, c, d], [a, d, c], [a, b, d], [a, c, b]] {
                let mut key = f;
                key.sort_unstable();
                faces.push((key, f));
            }
        }
        faces.sort_unstable();
        faces
            .chunk_by(|x, y| x.0 == y.0)
            .filter_map(|run| match run {
                [(_, f)] => Some(*f),
                _ => None,
            })
            .collect()
    }
}

impl From<SurfaceMesh> for TetMesh {
    /// A mesh with no tets whose boundary is the surface, so volume formats can carry surfaces too.
    fn from(s: SurfaceMesh) -> TetMesh {
        TetMesh {
            positions: s.positions,
            boundary: s.triangles,
            boundary_patches: s.patches,
            ..TetMesh::default()
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tet() -> TetMesh {
        TetMesh {
            positions: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            tets: vec![[0, 1, 2, 3]],
            subdomains: vec![SubdomainId(1)],
            ..TetMesh::default()
        }
    }

    #[test]
    fn exterior_faces_of_a_tet_point_outward() {
        let m = tet();
        assert!(m.tet_volume(0) > 0.0);
        let faces = m.exterior_faces();
        assert_eq!(faces.len(), 4);
        let s = SurfaceMesh {
            positions: m.positions.clone(),
            patches: vec![PatchId(0); faces.len()],
            triangles: faces,
            patch_names: vec!["all".into()],
        };
        let t = s.topology();
        assert!(t.closed && t.manifold && t.orientation_consistent);
        assert!((t.signed_volume - m.tet_volume(0)).abs() < 1e-15);
    }

    #[test]
    fn validate_rejects_bad_indices_nan_and_length_mismatch() {
        let mut m = tet();
        assert!(m.validate().is_ok());
        m.tets[0][3] = 7;
        assert!(matches!(
            m.validate(),
            Err(MeshError::IndexOutOfRange { vertex: 7, .. })
        ));
        let mut m = tet();
        m.positions[2].y = f64::NAN;
        assert!(matches!(
            m.validate(),
            Err(MeshError::NonFinite { vertex: 2, .. })
        ));
        let mut m = tet();
        m.cell_fields.push(CellField {
            name: "q".into(),
            values: vec![],
        });
        assert!(matches!(
            m.validate(),
            Err(MeshError::LengthMismatch { .. })
        ));
        assert!(TetMesh::default().validate().is_err());
    }

    #[test]
    fn huge_patch_labels_are_renumbered_not_allocated() {
        let mut small = vec![PatchId(3), PatchId(1)];
        assert_eq!(name_patch_labels(&mut small).len(), 4);
        assert_eq!(small, vec![PatchId(3), PatchId(1)]);
        let mut huge = vec![PatchId(4_000_000_000), PatchId(7), PatchId(4_000_000_000)];
        let names = name_patch_labels(&mut huge);
        assert_eq!(
            names,
            vec!["patch 7".to_string(), "patch 4000000000".to_string()]
        );
        assert_eq!(huge, vec![PatchId(1), PatchId(0), PatchId(1)]);
    }

    #[test]
    fn image_labels_are_x_fastest() {
        let img = LabelledImage {
            dims: [2, 3, 1],
            spacing: DVec3::ONE,
            origin: DVec3::ZERO,
            labels: Labels::U8(vec![0, 1, 2, 3, 4, 5]),
        };
        assert!(img.validate().is_ok());
        assert_eq!(img.label(1, 2, 0), Some(5));
        assert_eq!(img.label(2, 0, 0), None);
    }
}
