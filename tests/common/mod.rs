//! Closed test surfaces generated in code, so that tests need no data files.
#![allow(dead_code)]

use glam::DVec3;

/// A triangle surface: points and outward-oriented triangles.
#[derive(Clone)]
pub struct Surface {
    pub points: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
}

impl Surface {
    /// Append `other` (as another connected component).
    pub fn merge(mut self, other: Surface) -> Surface {
        let offset = self.points.len() as u32;
        self.points.extend(other.points);
        self.triangles
            .extend(other.triangles.iter().map(|t| t.map(|v| v + offset)));
        self
    }

    /// Write as an OFF file.
    pub fn to_off(&self) -> String {
        let mut s = format!("OFF\n{} {} 0\n", self.points.len(), self.triangles.len());
        for p in &self.points {
            s += &format!("{} {} {}\n", p.x, p.y, p.z);
        }
        for t in &self.triangles {
            s += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
        }
        s
    }
}

/// An icosphere: `subdivisions` splits of an icosahedron, projected on the sphere.
pub fn sphere(center: DVec3, radius: f64, subdivisions: usize) -> Surface {
    let m = delamesh::core::mesh::SurfaceMesh::icosphere(center, radius, subdivisions);
    Surface {
        points: m.positions,
        triangles: m.triangles,
    }
}

/// A torus around the z axis with major radius `r_major` and tube radius `r_minor`.
pub fn torus(r_major: f64, r_minor: f64, n_major: usize, n_minor: usize) -> Surface {
    let mut points = Vec::new();
    for i in 0..n_major {
        let u = i as f64 / n_major as f64 * std::f64::consts::TAU;
        for j in 0..n_minor {
            let v = j as f64 / n_minor as f64 * std::f64::consts::TAU;
            let r = r_major + r_minor * v.cos();
            points.push(DVec3::new(r * u.cos(), r * u.sin(), r_minor * v.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n_major) * n_minor + (j % n_minor)) as u32;
    let mut triangles = Vec::new();
    for i in 0..n_major {
        for j in 0..n_minor {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            triangles.push([a, b, c]);
            triangles.push([a, c, d]);
        }
    }
    Surface { points, triangles }
}

/// An axis-aligned box from `min` to `max`, two triangles per face.
pub fn cuboid(min: DVec3, max: DVec3) -> Surface {
    let m = delamesh::core::mesh::SurfaceMesh::cuboid(min, max);
    Surface {
        points: m.positions,
        triangles: m.triangles,
    }
}

/// The same surface with every triangle reversed (normals inward).
pub fn flipped(s: Surface) -> Surface {
    Surface {
        points: s.points,
        triangles: s.triangles.into_iter().map(|[a, b, c]| [a, c, b]).collect(),
    }
}

use delamesh::core::complex::MeshComplex;
use delamesh::core::refine::criteria::{CellCriteria, FacetCriteria, MeshCriteria, Sizing};
use delamesh::core::refine::{Limits, MeshOptions, mesh_domain};
use delamesh::polyhedral::PolyhedralOracle;

/// CGAL-style criteria with constant sizes.
pub fn criteria(angle: f64, size: f64, distance: f64, ratio: f64, cell_size: f64) -> MeshCriteria {
    MeshCriteria {
        edge_size: Sizing::Constant(size),
        edge_min_size: 0.0,
        facet: FacetCriteria {
            angle_deg: angle,
            size: Sizing::Constant(size),
            distance: Sizing::Constant(distance),
        },
        cell: CellCriteria {
            radius_edge_ratio: ratio,
            size: Sizing::Constant(cell_size),
        },
    }
}

/// Mesh a surface; panics (this is a test) when the oracle or the mesher fails.
pub fn mesh(surface: &Surface, criteria: MeshCriteria) -> (PolyhedralOracle, MeshComplex) {
    let oracle = PolyhedralOracle::new(&surface.points, &surface.triangles, None)
        .expect("valid test surface");
    let options = MeshOptions {
        criteria,
        limits: Limits {
            max_vertices: 200_000,
            ..Limits::default()
        },
        keep_partial: false,
        validity: Default::default(),
        optimize: delamesh_core::optimize::OptimizeOptions::none(),
    };
    let outcome = mesh_domain(&oracle, &options, &mut |_| {}).expect("refinement terminates");
    (oracle, outcome.complex)
}
