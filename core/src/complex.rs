//! The result of refinement: the tetrahedra of the restricted Delaunay triangulation with their
//! subdomains, the boundary facets with their surface patches, and each vertex's dimension.

use crate::kernel::Point3;
use crate::mesh::{CellField, TetMesh};
use crate::oracle::{CurveId, OUTSIDE, PatchId, SubdomainId};
use crate::quality;
use crate::refine::cells::CellLevel;
use crate::refine::facets::SurfaceLevel;
use crate::refine::guard::CurveLevel;
use crate::triangulation::{CellId, Triangulation, VertexId};

/// The facets `i` of finite cell `c` (subdomain `sub`) that a complex records, with the subdomain
/// on their other side (`subdomain_of` the neighbour, `OUTSIDE` past the hull): those where it is
/// smaller than `sub`, so that a facet between two subdomains is recorded once.
pub(crate) fn facets_to_smaller<T: Triangulation>(
    tr: &T,
    c: CellId,
    sub: SubdomainId,
    subdomain_of: impl Fn(CellId) -> SubdomainId,
) -> impl Iterator<Item = (usize, SubdomainId)> {
    (0..4).filter_map(move |i| {
        let n = tr.neighbor(c, i);
        let other = if tr.is_infinite_cell(n) {
            OUTSIDE
        } else {
            subdomain_of(n)
        };
        (other < sub).then_some((i, other))
    })
}

/// Where a vertex lies: on a corner, a feature curve, the boundary surfaces or inside a subdomain
/// (the dimension of the feature, as CGAL's `in_dimension`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum VertexDimension {
    /// A corner of the input: never moved.
    Corner = 0,
    /// On a feature curve: moves only along it.
    Curve = 1,
    /// On a boundary surface: moves only on its patch.
    Surface = 2,
    /// Inside a subdomain.
    Volume = 3,
}

/// A mesh complex with compact vertex numbering (vertices of no tetrahedron are dropped).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MeshComplex {
    /// Vertex positions.
    pub points: Vec<Point3>,
    /// One entry per vertex: the feature it lies on.
    pub vertex_dimension: Vec<VertexDimension>,
    /// Positively oriented tetrahedra (signed volume > 0).
    pub tets: Vec<[u32; 4]>,
    /// One subdomain per tetrahedron.
    pub tet_subdomain: Vec<SubdomainId>,
    /// Facets between tetrahedra of different subdomains (or a tetrahedron and the outside),
    /// oriented so that the normal points to the side with the smaller subdomain id.
    pub facets: Vec<[u32; 3]>,
    /// Patch of each facet's surface Delaunay ball; 0 for a facet the surface level did not
    /// find restricted (the thesis shows none are left for a fine enough mesh).
    pub facet_patch: Vec<PatchId>,
    /// The subdomains on the two sides of each facet: `[behind the normal, in front]`.
    pub facet_subdomains: Vec<[SubdomainId; 2]>,
    /// Restricted curve edges: consecutive protecting balls along a curve whose vertices are
    /// joined by an edge of the mesh.
    pub feature_edges: Vec<[u32; 2]>,
    /// Curve of each feature edge.
    pub feature_edge_curve: Vec<CurveId>,
    /// The corners of the domain (input positions) and the vertex placed on each, if it is in
    /// the mesh.
    pub corners: Vec<(Point3, Option<u32>)>,
}

impl MeshComplex {
    /// Collect the complex from a refined triangulation and the levels that refined it.
    pub(crate) fn from_refinement<T: Triangulation<Point = Point3>>(
        tr: &T,
        surface: &SurfaceLevel<'_>,
        cells: &CellLevel<'_>,
        curves: Option<&CurveLevel>,
    ) -> Self {
        let mut complex = MeshComplex::default();
        // Number vertices in `VertexId` order so the output does not depend on cell order.
        let mut used: Vec<VertexId> = Vec::new();
        for c in tr.finite_cells() {
            if cells.subdomain(c) != OUTSIDE {
                used.extend_from_slice(tr.cell(c).as_ref());
            }
        }
        used.sort_unstable();
        used.dedup();
        let mut new_index = vec![u32::MAX; used.last().map_or(0, |v| v.0 as usize + 1)];
        for (i, &v) in used.iter().enumerate() {
            new_index[v.0 as usize] = i as u32;
            complex.points.push(tr.point(v));
            complex.vertex_dimension.push(if surface.is_on_surface(v) {
                VertexDimension::Surface
            } else {
                VertexDimension::Volume
            });
        }
        if let Some(curves) = curves {
            for b in 0..curves.protection().balls.len() {
                if let Some(i) = curves.ball_vertex(b).and_then(|v| compact(&new_index, v)) {
                    complex.vertex_dimension[i as usize] = match curves.ball_feature(b).0 {
                        0 => VertexDimension::Corner,
                        _ => VertexDimension::Curve,
                    };
                }
            }
            complex.add_features(tr, curves, &new_index);
        }
        let index_of = |v: VertexId| new_index[v.0 as usize];
        for c in tr.finite_cells() {
            let sub = cells.subdomain(c);
            if sub == OUTSIDE {
                continue;
            }
            let cell = crate::refine::cell_vertices(tr, c);
            let p = cell.map(|v| tr.point(v));
            let mut tet = cell.map(index_of);
            if signed_volume(&p) < 0.0 {
                tet.swap(0, 1);
            }
            complex.tets.push(tet);
            complex.tet_subdomain.push(sub);
            for (i, other) in facets_to_smaller(tr, c, sub, |n| cells.subdomain(n)) {
                let mut f = crate::refine::facet_vertices(&cell, i);
                let [a, b, d] = f.map(|v| tr.point(v));
                if (b - a).cross(d - a).dot(p[i] - a) > 0.0 {
                    f.swap(0, 1);
                }
                complex.facets.push(f.map(index_of));
                complex
                    .facet_patch
                    .push(surface.ball(c, i).map_or(PatchId(0), |b| b.patch));
                complex.facet_subdomains.push([sub, other]);
            }
        }
        complex
    }

    /// Feature edges (links of consecutive balls that are mesh edges) and corner vertices.
    fn add_features<T: Triangulation<Point = Point3>>(
        &mut self,
        tr: &T,
        curves: &CurveLevel,
        new_index: &[u32],
    ) {
        let protection = curves.protection();
        let mut incident = Vec::new();
        for chain in &protection.chains {
            for (a, b) in chain.links() {
                let (Some(va), Some(vb)) = (curves.ball_vertex(a), curves.ball_vertex(b)) else {
                    continue;
                };
                let (Some(ia), Some(ib)) = (compact(new_index, va), compact(new_index, vb)) else {
                    continue;
                };
                tr.incident_cells(va, &mut incident);
                if incident.iter().any(|&c| tr.cell(c).as_ref().contains(&vb)) {
                    self.feature_edges.push([ia, ib]);
                    self.feature_edge_curve.push(chain.curve);
                }
            }
        }
        self.corners = protection
            .corners
            .iter()
            .enumerate()
            .map(|(k, &p)| (p, curves.ball_vertex(k).and_then(|v| compact(new_index, v))))
            .collect();
    }

    /// The number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.points.len()
    }

    /// The mesh as the formats crate writes it: subdomain per tet, patch per boundary facet, and
    /// the cell fields `min_dihedral_deg` and `radius_edge` that ParaView users colour by.
    pub fn to_tet_mesh(&self) -> TetMesh {
        let (min_dihedral, radius_edge): (Vec<f64>, Vec<f64>) = (0..self.tets.len())
            .map(|t| {
                let p = self.tet_points(t);
                let min = quality::dihedral_angles_deg(&p)
                    .into_iter()
                    .fold(f64::INFINITY, f64::min);
                (min, quality::radius_edge_ratio(&p))
            })
            .unzip();
        TetMesh {
            positions: self.points.clone(),
            tets: self.tets.clone(),
            subdomains: self.tet_subdomain.clone(),
            boundary: self.facets.clone(),
            boundary_patches: self.facet_patch.clone(),
            feature_edges: self.feature_edges.clone(),
            feature_curves: self.feature_edge_curve.clone(),
            cell_fields: vec![
                CellField {
                    name: "min_dihedral_deg".into(),
                    values: min_dihedral,
                },
                CellField {
                    name: "radius_edge".into(),
                    values: radius_edge,
                },
            ],
        }
    }

    /// The corner points of tetrahedron `t`.
    pub fn tet_points(&self, t: usize) -> [Point3; 4] {
        self.tets[t].map(|v| self.points[v as usize])
    }

    /// The corner points of boundary facet `f`.
    pub fn facet_points(&self, f: usize) -> [Point3; 3] {
        self.facets[f].map(|v| self.points[v as usize])
    }
}

/// The compact index of triangulation vertex `v`, if it is a vertex of the complex.
fn compact(new_index: &[u32], v: VertexId) -> Option<u32> {
    new_index
        .get(v.0 as usize)
        .copied()
        .filter(|&i| i != u32::MAX)
}

/// Six times the signed volume of a tetrahedron, positive when `p[0] p[1] p[2]` turn
/// counterclockwise seen from `p[3]`. The sign is exact (robust predicates).
pub fn signed_volume(p: &[Point3; 4]) -> f64 {
    let c = |q: Point3| robust::Coord3D {
        x: q.x,
        y: q.y,
        z: q.z,
    };
    -robust::orient3d(c(p[0]), c(p[1]), c(p[2]), c(p[3]))
}
