//! The mesh the optimisers work on: the regular triangulation of the mesh vertices (with the
//! weights refinement gave them), the subdomain of every cell, and the boundary facets with the
//! subdomains they separate and their patches.
//!
//! Every vertex move and weight change goes through [`Workspace::try_move`], which keeps two
//! invariants whatever the optimiser asks: the triangulation is the regular triangulation of the
//! current weighted points, and the boundary facets are exactly the input's (same triangles,
//! same patches, same subdomains on each side). New cells get their subdomain by crossing facets
//! from the cells around them; a move after which no consistent labelling exists, or after
//! which a boundary facet is no longer a facet, is undone.

use crate::complex::{MeshComplex, VertexDimension};
use crate::kernel::Point3;
use crate::oracle::{OUTSIDE, PatchId, SubdomainId};
use crate::quality::{dihedral_angles_deg, tet_volume};
use crate::refine::facet_vertices;
use crate::triangulation::{CellId, MoveReport, Regular3, Triangulation, VertexId};
use std::collections::HashMap;

/// Why the optimisers cannot start from a complex (they then leave it as it is).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum WorkspaceError {
    /// Two mesh vertices share a position, or one is hidden by the weights.
    #[error("the mesh vertices are not the vertices of one regular triangulation")]
    Vertices,
    /// A tetrahedron of the mesh is not a cell of the regular triangulation of its vertices.
    #[error("the mesh is not a subcomplex of the regular triangulation of its vertices")]
    NotRegular,
    /// The subdomains and the boundary facets do not agree.
    #[error("the boundary facets do not separate the subdomains")]
    Boundary,
}

/// A facet key: its three vertices, sorted.
pub(super) type FacetKey = [u32; 3];

/// A boundary facet: its patch and the two subdomains it separates, sorted.
#[derive(Clone, Copy, Debug)]
struct BoundaryFacet {
    patch: PatchId,
    sides: [SubdomainId; 2],
}

/// A move that passed the invariants: what it did, to compare or undo.
#[derive(Clone, Debug)]
pub(super) struct Change {
    vertex: VertexId,
    old_point: Point3,
    old_weight: f64,
    /// Subdomains of the destroyed cells, by sorted vertices (to restore them on undo).
    saved: HashMap<[u32; 4], SubdomainId>,
    /// Smallest dihedral angle of the destroyed cells inside the domain.
    pub before: f64,
    /// Smallest dihedral angle of the created cells inside the domain.
    pub after: f64,
}

/// The triangulation, its labels and the boundary, with the per-vertex data of the mesh.
pub(super) struct Workspace<'o> {
    pub rt: Regular3,
    /// Subdomain of each cell slot ([`OUTSIDE`] for infinite cells and cells outside).
    label: Vec<SubdomainId>,
    boundary: HashMap<FacetKey, BoundaryFacet>,
    /// Dimension of each triangulation vertex.
    pub dimension: Vec<VertexDimension>,
    /// The domain, for the optimisers that re-project surface vertices.
    pub oracle: &'o dyn crate::oracle::Oracle,
    /// The triangulation vertex of each mesh vertex.
    vertex_of: Vec<VertexId>,
    report: MoveReport,
}

/// Sorted vertices of a cell.
fn quad_key(q: [VertexId; 4]) -> [u32; 4] {
    let mut k = q.map(|v| v.0);
    k.sort_unstable();
    k
}

/// Sorted vertices of facet `i` of cell `q`.
fn facet_key(q: [VertexId; 4], i: usize) -> FacetKey {
    let mut k = [0u32; 3];
    let mut n = 0;
    for (j, v) in q.iter().enumerate() {
        if j != i {
            k[n] = v.0;
            n += 1;
        }
    }
    k.sort_unstable();
    k
}

/// Smallest dihedral angle (degrees) of the tetrahedron; 0 when flat or inverted.
pub(super) fn min_dihedral(p: &[Point3; 4]) -> f64 {
    if tet_volume(p) <= 0.0 {
        return 0.0;
    }
    dihedral_angles_deg(p)
        .into_iter()
        .fold(f64::INFINITY, f64::min)
        .max(0.0)
}

impl<'o> Workspace<'o> {
    /// The workspace of `complex`, whose vertex `i` has weight `weights[i]` in the triangulation
    /// refinement built.
    pub fn new(
        complex: &MeshComplex,
        weights: &[f64],
        oracle: &'o dyn crate::oracle::Oracle,
    ) -> Result<Self, WorkspaceError> {
        let points: Vec<(Point3, f64)> = complex
            .points
            .iter()
            .zip(weights.iter().chain(std::iter::repeat(&0.0)))
            .map(|(&p, &w)| (p, w))
            .collect();
        let (rt, vertex_of) =
            Regular3::from_weighted_points(&points).map_err(|_| WorkspaceError::Vertices)?;
        let mut seen = vec![false; rt.num_vertices()];
        for &v in &vertex_of {
            if rt.is_hidden(v) || std::mem::replace(&mut seen[v.0 as usize], true) {
                return Err(WorkspaceError::Vertices);
            }
        }
        let mut cell_of: HashMap<[u32; 4], CellId> = HashMap::with_capacity(rt.num_cells());
        for c in rt.finite_cells() {
            cell_of.insert(quad_key(rt.cell(c)), c);
        }
        let mut label = vec![OUTSIDE; rt.cell_capacity()];
        for (t, &sub) in complex.tets.iter().zip(&complex.tet_subdomain) {
            let key = quad_key(t.map(|i| vertex_of[i as usize]));
            let c = cell_of.get(&key).ok_or(WorkspaceError::NotRegular)?;
            label[c.0 as usize] = sub;
        }
        let mut boundary = HashMap::with_capacity(complex.facets.len());
        for (k, f) in complex.facets.iter().enumerate() {
            let mut key = f.map(|i| vertex_of[i as usize].0);
            key.sort_unstable();
            let mut sides = complex.facet_subdomains[k];
            sides.sort_unstable();
            let patch = complex.facet_patch[k];
            boundary.insert(key, BoundaryFacet { patch, sides });
        }
        let mut dimension = vec![VertexDimension::Volume; rt.num_vertices()];
        for (i, &v) in vertex_of.iter().enumerate() {
            dimension[v.0 as usize] = complex.vertex_dimension[i];
        }
        let ws = Workspace {
            rt,
            label,
            boundary,
            dimension,
            oracle,
            vertex_of,
            report: MoveReport::default(),
        };
        let consistent = ws.rt.finite_cells().all(|c| {
            (0..4).all(|i| {
                let n = ws.rt.neighbor(c, i);
                ws.across(facet_key(ws.rt.cell(c), i), ws.label(c)) == Some(ws.label(n))
            })
        });
        if !consistent {
            return Err(WorkspaceError::Boundary);
        }
        Ok(ws)
    }

    /// Subdomain of live cell `c`.
    pub fn label(&self, c: CellId) -> SubdomainId {
        self.label.get(c.0 as usize).copied().unwrap_or(OUTSIDE)
    }

    /// Whether live cell `c` is a tetrahedron of the mesh.
    pub fn inside(&self, c: CellId) -> bool {
        self.label(c) != OUTSIDE && !self.rt.is_infinite_cell(c)
    }

    /// The subdomain across facet `key` from a cell of subdomain `from`; `None` when `key` is a
    /// boundary facet that does not bound `from`.
    fn across(&self, key: FacetKey, from: SubdomainId) -> Option<SubdomainId> {
        match self.boundary.get(&key) {
            None => Some(from),
            Some(b) if b.sides[0] == from => Some(b.sides[1]),
            Some(b) if b.sides[1] == from => Some(b.sides[0]),
            Some(_) => None,
        }
    }

    /// Whether `key` is a boundary facet.
    pub fn is_boundary(&self, key: &FacetKey) -> bool {
        self.boundary.contains_key(key)
    }

    /// The patch of boundary facet `key`.
    pub fn patch(&self, key: &FacetKey) -> Option<PatchId> {
        self.boundary.get(key).map(|b| b.patch)
    }

    /// The corner points of finite cell `c`.
    pub fn points(&self, c: CellId) -> [Point3; 4] {
        self.rt.cell(c).map(|v| self.rt.point(v))
    }

    /// Smallest dihedral angle of finite cell `c`.
    pub fn cell_min_dihedral(&self, c: CellId) -> f64 {
        min_dihedral(&self.points(c))
    }

    /// Moves `v` to `p` with weight `w`. `Some` when the triangulation accepted the move and the
    /// boundary survived it; otherwise the mesh is left as it was and `None` is returned.
    pub fn try_move(&mut self, v: VertexId, p: Point3, w: f64) -> Option<Change> {
        let old_point = self.rt.point(v);
        let old_weight = self.rt.weight(v);
        let moved = self.rt.move_vertex(v, p, w, &mut self.report).ok()?;
        let saved = self.saved_labels();
        if !moved {
            self.restore(&saved);
            return None;
        }
        let before = self.removed_min_dihedral(&saved, v, old_point);
        match self.relabel() {
            Some(after) => Some(Change {
                vertex: v,
                old_point,
                old_weight,
                saved,
                before,
                after,
            }),
            None => {
                self.undo(Change {
                    vertex: v,
                    old_point,
                    old_weight,
                    saved,
                    before,
                    after: 0.0,
                });
                None
            }
        }
    }

    /// Puts the moved vertex back where it was, with the labels it had.
    pub fn undo(&mut self, change: Change) {
        let back = self
            .rt
            .move_vertex(
                change.vertex,
                change.old_point,
                change.old_weight,
                &mut self.report,
            )
            .unwrap_or(false);
        if back {
            self.restore(&change.saved);
        } else {
            // The old place lies on a facet of the new triangulation: the move (which passed the
            // invariants) stays, and the refused undo rebuilt the same cells.
            let saved = self.saved_labels();
            self.restore(&saved);
        }
    }

    /// The subdomains of the cells the last move destroyed, read before any is overwritten.
    fn saved_labels(&self) -> HashMap<[u32; 4], SubdomainId> {
        self.report
            .removed
            .iter()
            .map(|&(c, q)| (quad_key(q), self.label(c)))
            .collect()
    }

    /// Labels the created cells of the last move from `saved` (cells rebuilt as they were).
    fn restore(&mut self, saved: &HashMap<[u32; 4], SubdomainId>) {
        self.grow_labels();
        for k in 0..self.report.created.len() {
            let c = self.report.created[k];
            let key = quad_key(self.rt.cell(c));
            self.label[c.0 as usize] = if self.rt.is_infinite_cell(c) {
                OUTSIDE
            } else {
                saved.get(&key).copied().unwrap_or(OUTSIDE)
            };
        }
    }

    fn grow_labels(&mut self) {
        if self.label.len() < self.rt.cell_capacity() {
            self.label.resize(self.rt.cell_capacity(), OUTSIDE);
        }
    }

    /// Smallest dihedral angle of the destroyed cells inside the domain, `v` at `old`.
    fn removed_min_dihedral(
        &self,
        saved: &HashMap<[u32; 4], SubdomainId>,
        v: VertexId,
        old: Point3,
    ) -> f64 {
        let inf = self.rt.infinite_vertex();
        let mut min = 180.0f64;
        for &(_, q) in &self.report.removed {
            if q.contains(&inf) || saved.get(&quad_key(q)).copied().unwrap_or(OUTSIDE) == OUTSIDE {
                continue;
            }
            let p = q.map(|x| if x == v { old } else { self.rt.point(x) });
            min = min.min(min_dihedral(&p));
        }
        min
    }

    /// Labels the created cells by crossing facets from the cells around them. Returns the
    /// smallest dihedral angle of the created cells inside the domain, or `None` when the
    /// boundary did not survive (no consistent labelling, a boundary facet gone, or a flat
    /// cell inside).
    fn relabel(&mut self) -> Option<f64> {
        self.grow_labels();
        let created = &self.report.created;
        let index: HashMap<u32, usize> = created
            .iter()
            .enumerate()
            .map(|(k, c)| (c.0, k))
            .collect();
        let mut new_label: Vec<Option<SubdomainId>> = vec![None; created.len()];
        let mut stack = Vec::new();
        for (k, &c) in created.iter().enumerate() {
            if self.rt.is_infinite_cell(c) {
                new_label[k] = Some(OUTSIDE);
                stack.push(k);
                continue;
            }
            let q = self.rt.cell(c);
            for i in 0..4 {
                let n = self.rt.neighbor(c, i);
                if index.contains_key(&n.0) {
                    continue;
                }
                let l = self.across(facet_key(q, i), self.label(n))?;
                match new_label[k] {
                    None => {
                        new_label[k] = Some(l);
                        stack.push(k);
                    }
                    Some(m) if m != l => return None,
                    Some(_) => {}
                }
            }
        }
        while let Some(k) = stack.pop() {
            let c = created[k];
            let from = new_label[k]?;
            let q = self.rt.cell(c);
            for i in 0..4 {
                let n = self.rt.neighbor(c, i);
                let Some(&kn) = index.get(&n.0) else {
                    continue;
                };
                let l = self.across(facet_key(q, i), from)?;
                match new_label[kn] {
                    None => {
                        new_label[kn] = Some(l);
                        stack.push(kn);
                    }
                    Some(m) if m != l => return None,
                    Some(_) => {}
                }
            }
        }
        if self
            .report
            .created
            .iter()
            .zip(&new_label)
            .any(|(&c, l)| self.rt.is_infinite_cell(c) && *l != Some(OUTSIDE))
        {
            return None;
        }
        // Every boundary facet of a destroyed cell must be a facet of a created one.
        let mut lost: Vec<FacetKey> = Vec::new();
        for &(_, q) in &self.report.removed {
            lost.extend((0..4).map(|i| facet_key(q, i)).filter(|k| self.is_boundary(k)));
        }
        let mut found: Vec<FacetKey> = Vec::new();
        let mut after = 180.0f64;
        for (k, &c) in self.report.created.iter().enumerate() {
            let q = self.rt.cell(c);
            found.extend((0..4).map(|i| facet_key(q, i)).filter(|k| self.is_boundary(k)));
            if new_label[k]? != OUTSIDE {
                let a = self.cell_min_dihedral(c);
                if a <= 0.0 {
                    return None;
                }
                after = after.min(a);
            }
        }
        lost.sort_unstable();
        lost.dedup();
        found.sort_unstable();
        found.dedup();
        if lost != found {
            return None;
        }
        for (k, &c) in self.report.created.iter().enumerate() {
            self.label[c.0 as usize] = new_label[k].unwrap_or(OUTSIDE);
        }
        Some(after)
    }

    /// The inside cells whose smallest dihedral angle is below `bound`, worst first (ties by
    /// sorted vertices, so the order does not depend on cell slots).
    pub fn slivers(&self, bound: f64) -> Vec<(f64, CellId, [VertexId; 4])> {
        let mut s: Vec<(f64, [u32; 4], CellId)> = self
            .rt
            .finite_cells()
            .filter(|&c| self.inside(c))
            .filter_map(|c| {
                let a = self.cell_min_dihedral(c);
                (a < bound).then(|| (a, quad_key(self.rt.cell(c)), c))
            })
            .collect();
        s.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        s.into_iter()
            .map(|(a, _, c)| (a, c, self.rt.cell(c)))
            .collect()
    }

    /// Smallest dihedral angle of every tetrahedron of the mesh, in cell order.
    pub fn min_dihedrals(&self) -> Vec<f64> {
        self.rt
            .finite_cells()
            .filter(|&c| self.inside(c))
            .map(|c| self.cell_min_dihedral(c))
            .collect()
    }

    /// The optimised mesh: `complex` with the new positions, tetrahedra and boundary facets (the
    /// same facets, in the order and orientation the tetrahedra give them).
    pub fn into_complex(self, mut complex: MeshComplex) -> MeshComplex {
        let mut mesh_index = vec![u32::MAX; self.rt.num_vertices()];
        for (i, &v) in self.vertex_of.iter().enumerate() {
            mesh_index[v.0 as usize] = i as u32;
            complex.points[i] = self.rt.point(v);
        }
        complex.tets.clear();
        complex.tet_subdomain.clear();
        complex.facets.clear();
        complex.facet_patch.clear();
        complex.facet_subdomains.clear();
        for c in self.rt.finite_cells() {
            let sub = self.label(c);
            if sub == OUTSIDE {
                continue;
            }
            let cell = self.rt.cell(c);
            complex.tets.push(cell.map(|v| mesh_index[v.0 as usize]));
            complex.tet_subdomain.push(sub);
            for (i, &apex) in cell.iter().enumerate() {
                let other = self.label(self.rt.neighbor(c, i));
                if other >= sub {
                    continue;
                }
                let mut f = facet_vertices(&cell, i);
                let [a, b, d] = f.map(|v| self.rt.point(v));
                if (b - a).cross(d - a).dot(self.rt.point(apex) - a) > 0.0 {
                    f.swap(0, 1);
                }
                complex.facets.push(f.map(|v| mesh_index[v.0 as usize]));
                complex
                    .facet_patch
                    .push(self.patch(&facet_key(cell, i)).unwrap_or(0));
                complex.facet_subdomains.push([sub, other]);
            }
        }
        complex
    }
}
