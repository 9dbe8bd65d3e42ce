//! The Delaunay tetrahedralisation of a point set as a tet mesh (`delamesh delaunay`, the
//! bindings' `delaunay`): the kernel alone, without refinement.

use crate::error::Error;
use delamesh_core::Point3;
use delamesh_core::mesh::{PatchId, SubdomainId, TetMesh};
use delamesh_core::triangulation::{Delaunay3, Triangulation};

/// The tetrahedralisation of a point set, with the way back to the input points.
pub struct Tetrahedralization {
    /// The distinct points, the finite cells as tets of subdomain 1 (positive: det[b-a, c-a,
    /// d-a] > 0, as the file formats want) and the convex hull as boundary triangles of patch 0,
    /// oriented outwards.
    pub mesh: TetMesh,
    /// For each input point, its vertex in `mesh` (duplicates share one).
    pub vertex_of_point: Vec<u32>,
}

/// Triangulates `points`; `name` (the file, or "points") names them in errors. Fewer than four
/// distinct points, or all of them in a plane, give an error: there is no tetrahedron.
pub fn delaunay(name: &str, points: &[Point3]) -> Result<Tetrahedralization, Error> {
    let mut dt = Delaunay3::new();
    let vertices = dt
        .insert_points(points)
        .map_err(|source| Error::Triangulation {
            name: name.to_string(),
            source,
        })?;
    if dt.num_finite_cells() == 0 {
        return Err(Error::Flat {
            name: name.to_string(),
            distinct: dt.num_vertices(),
        });
    }
    Ok(Tetrahedralization {
        mesh: tet_mesh_of(&dt),
        vertex_of_point: vertices.iter().map(|v| v.0).collect(),
    })
}

/// The finite cells as tets of subdomain 1 and the hull facets (finite facets of infinite cells,
/// oriented outwards) as boundary patch 0.
fn tet_mesh_of(dt: &Delaunay3) -> TetMesh {
    let positions = dt.vertices().map(|v| dt.point(v)).collect();
    let mut tets = Vec::with_capacity(dt.num_finite_cells());
    let mut boundary = Vec::new();
    for c in dt.cells() {
        let [a, b, c3, d] = dt.cell(c);
        if !dt.is_infinite_cell(c) {
            // Cells are positive in Shewchuk's orient3d convention; files want the opposite one
            // (VTK, MEDIT, Gmsh: det[b-a, c-a, d-a] > 0), hence the swap.
            tets.push([a.0, b.0, d.0, c3.0]);
            continue;
        }
        let vs = [a, b, c3, d];
        let Some(i) = vs.iter().position(|&v| dt.is_infinite_vertex(v)) else {
            continue;
        };
        // Read this way, facet i of a cell positive in Shewchuk's convention has its normal pointing
        // away from vertex i; that vertex is the infinite one, so the normal points into the hull
        // and the reversed order below points outwards.
        let f = FACETS[i];
        boundary.push([vs[f[0]].0, vs[f[2]].0, vs[f[1]].0]);
    }
    let n_tets = tets.len();
    let n_bnd = boundary.len();
    TetMesh {
        positions,
        tets,
        subdomains: vec![SubdomainId(1); n_tets],
        boundary,
        boundary_patches: vec![PatchId(0); n_bnd],
        ..TetMesh::default()
    }
}

/// Vertex indices of facet i of a cell (the facet opposite vertex i).
const FACETS: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [0, 3, 1], [0, 1, 2]];
