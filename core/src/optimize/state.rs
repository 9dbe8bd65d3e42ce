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

use super::SLIVER_DEG;
use crate::complex::{MeshComplex, VertexDimension};
use crate::kernel::{Point3, WeightedPoint3};
use crate::oracle::{CurveId, OUTSIDE, PatchId, SubdomainId};
use crate::quality::tet_volume;
use crate::refine::criteria::{MeshCriteria, Sizing};
use crate::refine::curves::Polyline;
use crate::refine::{facet_vertices, triangle_circumcenter};
use crate::triangulation::{CellId, MoveReport, Regular3, Triangulation, VertexId};
use rustc_hash::{FxHashMap, FxHashSet};

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
    /// Subdomain and [`min_dihedral_cos`] of each destroyed cell, in the order of
    /// `moved.removed` (an undo puts the cells back in that order).
    saved: Vec<(SubdomainId, f64)>,
    /// The cells the move destroyed and created (to put the old ones back on undo).
    moved: MoveReport,
}

/// The triangulation, its labels and the boundary, with the per-vertex data of the mesh.
pub(super) struct Workspace<'o> {
    pub rt: Regular3,
    /// Subdomain of each cell slot ([`OUTSIDE`] for infinite cells and cells outside).
    label: Vec<SubdomainId>,
    /// [`min_dihedral_cos`] of each finite cell slot, updated with every move: a sweep reads
    /// every cell's, which recomputed took a seventh of the phase.
    cos: Vec<f64>,
    boundary: FxHashMap<FacetKey, BoundaryFacet>,
    /// Dimension of each triangulation vertex.
    pub dimension: Vec<VertexDimension>,
    /// Feature edges (sorted triangulation vertex pairs): peeling may not flip them.
    feature_edges: FxHashSet<[u32; 2]>,
    /// Boundary facets made by peeling: a cell under one is not peeled, so the surface moves
    /// by one flat layer at most (peels would otherwise erode it step by step).
    peeled: FxHashSet<FacetKey>,
    /// The domain, for the optimisers that re-project surface vertices.
    pub oracle: &'o dyn crate::oracle::Oracle,
    /// The facet-distance criterion of refinement, which boundary facets changed by the
    /// optimisers must still meet.
    facet_distance: Sizing,
    /// The cell-size criterion of refinement: no move makes a cell larger than it allows (or
    /// than the cells it replaces, where refinement left larger ones).
    cell_size: Sizing,
    /// The facet-size criterion, which boundary facets changed by the optimisers must meet.
    facet_size: Sizing,
    /// The triangulation vertex of each mesh vertex.
    vertex_of: Vec<VertexId>,
    /// The feature curves of the domain, and the one each curve vertex inside a curve (two
    /// feature edges on it) moves along.
    curves: Vec<(CurveId, Polyline)>,
    curve_of: FxHashMap<u32, CurveVertex>,
    /// How far a feature edge may leave its curve ([`MeshCriteria::bend_tolerance`]), as
    /// protection placed them.
    bend_tolerance: f64,
    report: MoveReport,
}

/// A vertex inside a feature curve: the curve, and its two neighbours along it (the other ends
/// of its two feature edges), between which it may slide.
#[derive(Clone, Copy, Debug)]
struct CurveVertex {
    curve: usize,
    neighbours: [VertexId; 2],
}

/// A created cell inside the domain with a smallest dihedral angle below this (degrees) is
/// flat for every purpose of a mesh user, whatever the sign of its volume: a move making one is
/// refused.
const FLAT_DEG: f64 = 1e-3;

/// Two boundary facets whose normals make an angle below 30° (this cosine) are a smooth piece
/// of the surface: a cell under them may be peeled even next to a feature curve.
const COPLANAR_COS: f64 = 0.866;

/// The feature curves of `oracle` as polylines, and each curve vertex with exactly two
/// feature edges on one curve (by triangulation vertex).
fn curve_vertices(
    complex: &MeshComplex,
    vertex_of: &[VertexId],
    dimension: &[VertexDimension],
    oracle: &dyn crate::oracle::Oracle,
) -> (Vec<(CurveId, Polyline)>, FxHashMap<u32, CurveVertex>) {
    let mut curves = Vec::new();
    let mut index = FxHashMap::default();
    for c in oracle.feature_curves() {
        if let Some(p) = Polyline::new(&c.points, c.closed) {
            index.insert(c.id, curves.len());
            curves.push((c.id, p));
        }
    }
    // Per vertex: the other ends of its feature edges, and the curve if all are on one.
    let mut seen: FxHashMap<u32, (Vec<VertexId>, Option<usize>)> = FxHashMap::default();
    for (e, &id) in complex
        .feature_edges
        .iter()
        .zip(&complex.feature_edge_curve)
    {
        let curve = index.get(&id).copied();
        let (Some(&a), Some(&b)) = (vertex_of.get(e[0] as usize), vertex_of.get(e[1] as usize))
        else {
            continue;
        };
        for (v, other) in [(a, b), (b, a)] {
            let entry = seen.entry(v.0).or_insert((Vec::new(), curve));
            entry.0.push(other);
            if entry.1 != curve {
                entry.1 = None;
            }
        }
    }
    let curve_of = seen
        .into_iter()
        .filter(|(v, _)| dimension[*v as usize] == VertexDimension::Curve)
        .filter_map(|(v, (ends, c))| {
            let neighbours = <[VertexId; 2]>::try_from(ends).ok()?;
            Some((
                v,
                CurveVertex {
                    curve: c?,
                    neighbours,
                },
            ))
        })
        .collect();
    (curves, curve_of)
}

/// How far the [`frame`] lies outside the mesh, in diagonals of its bounding box.
const FRAME_DISTANCE: f64 = 100.0;

/// The corners of a cube far around `points`: fixed vertices outside the domain, so that no mesh
/// vertex is on the convex hull of the triangulation, where a vertex cannot move.
fn frame(points: &[Point3]) -> Vec<(Point3, f64)> {
    let (lo, hi) = points.iter().fold(
        (
            Point3::splat(f64::INFINITY),
            Point3::splat(f64::NEG_INFINITY),
        ),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    if !(lo.x <= hi.x && lo.y <= hi.y && lo.z <= hi.z) {
        return Vec::new();
    }
    let center = (lo + hi) * 0.5;
    let reach = FRAME_DISTANCE * hi.distance(lo).max(f64::MIN_POSITIVE.sqrt());
    (0..8)
        .map(|k| {
            let sign = |bit: usize| if k >> bit & 1 == 1 { reach } else { -reach };
            (center + Point3::new(sign(0), sign(1), sign(2)), 0.0)
        })
        .collect()
}

/// Sorted vertices of a cell.
fn quad_key(q: [VertexId; 4]) -> [u32; 4] {
    let mut k = q.map(|v| v.0);
    k.sort_unstable();
    k
}

/// The subdomains of destroyed cells (`saved`, in the order of `removed`) by their sorted
/// vertices, to label the same cells rebuilt in other slots.
fn by_vertices(
    removed: &[(CellId, [VertexId; 4])],
    saved: &[(SubdomainId, f64)],
) -> FxHashMap<[u32; 4], SubdomainId> {
    removed
        .iter()
        .zip(saved)
        .map(|(&(_, q), &(label, _))| (quad_key(q), label))
        .collect()
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

/// Gives created cell `k` the label `l` and queues it, unless it has one already; `None` when
/// that one differs (the labelling across facets is inconsistent).
fn label_once(
    labels: &mut [Option<SubdomainId>],
    stack: &mut Vec<usize>,
    k: usize,
    l: SubdomainId,
) -> Option<()> {
    match labels[k] {
        None => {
            labels[k] = Some(l);
            stack.push(k);
        }
        Some(m) if m != l => return None,
        Some(_) => {}
    }
    Some(())
}

/// A cell's vertices in the order of positive volume: the triangulation orders them so that
/// `orient3d` is positive, which is the opposite handedness of [`tet_volume`].
pub(super) fn positive(mut q: [VertexId; 4]) -> [VertexId; 4] {
    q.swap(0, 1);
    q
}

/// Smallest dihedral angle (degrees) of the tetrahedron; 0 when flat or inverted.
pub(super) fn min_dihedral(p: &[Point3; 4]) -> f64 {
    degrees(min_dihedral_cos(p))
}

/// The angle (degrees) of a cosine from [`min_dihedral_cos`].
fn degrees(cos: f64) -> f64 {
    cos.clamp(-1.0, 1.0).acos().to_degrees().max(0.0)
}

/// Cosine of the smallest dihedral angle of the tetrahedron; 1 when flat or inverted. The angle
/// at the edge shared by the faces opposite `k` and `l` is π minus the angle between their
/// outward normals, so the smallest is the arccosine of the largest `-n_k·n_l`: no arccosine
/// and no allocation (the optimisers evaluate it for every cell of every move they try, and
/// for every cell of the mesh at each sweep, where comparing cosines spares the arccosines).
fn min_dihedral_cos(p: &[Point3; 4]) -> f64 {
    if tet_volume(p) <= 0.0 {
        return 1.0;
    }
    const OTHERS: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];
    let normal = |k: usize| {
        let [a, b, c] = OTHERS[k].map(|m| p[m]);
        let n = (b - a).cross(c - a);
        let n = if n.dot(p[k] - a) > 0.0 { -n } else { n };
        n.normalize_or_zero()
    };
    let n = [normal(0), normal(1), normal(2), normal(3)];
    let mut largest = -1.0f64;
    for k in 0..4 {
        for l in k + 1..4 {
            largest = largest.max(-n[k].dot(n[l]));
        }
    }
    largest
}

impl<'o> Workspace<'o> {
    /// The workspace of `complex`, whose vertex `i` has weight `weights[i]` in the triangulation
    /// refinement built.
    pub fn new(
        complex: &MeshComplex,
        weights: &[f64],
        oracle: &'o dyn crate::oracle::Oracle,
        criteria: &MeshCriteria,
    ) -> Result<Self, WorkspaceError> {
        Self::build(complex, weights, oracle, criteria, true)
            .or_else(|_| Self::build(complex, weights, oracle, criteria, false))
    }

    /// The workspace, its triangulation with the [`frame`] around the mesh vertices or without
    /// (a mesh cell whose orthosphere reaches the frame is no longer regular with it).
    fn build(
        complex: &MeshComplex,
        weights: &[f64],
        oracle: &'o dyn crate::oracle::Oracle,
        criteria: &MeshCriteria,
        framed: bool,
    ) -> Result<Self, WorkspaceError> {
        let mut points: Vec<(Point3, f64)> = complex
            .points
            .iter()
            .zip(weights.iter().chain(std::iter::repeat(&0.0)))
            .map(|(&p, &w)| (p, w))
            .collect();
        if framed {
            points.extend(frame(&complex.points));
        }
        let (rt, mut vertex_of) =
            Regular3::from_weighted_points(&points).map_err(|_| WorkspaceError::Vertices)?;
        let frame_vertices = vertex_of.split_off(complex.points.len());
        let mut seen = vec![false; rt.num_vertices()];
        for &v in &vertex_of {
            if rt.is_hidden(v) || std::mem::replace(&mut seen[v.0 as usize], true) {
                return Err(WorkspaceError::Vertices);
            }
        }
        let mut cell_of: FxHashMap<[u32; 4], CellId> =
            FxHashMap::with_capacity_and_hasher(rt.num_cells(), Default::default());
        for c in rt.finite_cells() {
            cell_of.insert(quad_key(rt.cell(c)), c);
        }
        let mut label = vec![OUTSIDE; rt.cell_capacity()];
        for (t, &sub) in complex.tets.iter().zip(&complex.tet_subdomain) {
            let key = quad_key(t.map(|i| vertex_of[i as usize]));
            let c = cell_of.get(&key).ok_or(WorkspaceError::NotRegular)?;
            label[c.0 as usize] = sub;
        }
        let mut boundary =
            FxHashMap::with_capacity_and_hasher(complex.facets.len(), Default::default());
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
        for v in frame_vertices {
            dimension[v.0 as usize] = VertexDimension::Corner;
        }
        let feature_edges = complex
            .feature_edges
            .iter()
            .map(|e| {
                let (a, b) = (vertex_of[e[0] as usize].0, vertex_of[e[1] as usize].0);
                [a.min(b), a.max(b)]
            })
            .collect();
        let (curves, curve_of) = curve_vertices(complex, &vertex_of, &dimension, oracle);
        let mut cos = vec![1.0; rt.cell_capacity()];
        for c in rt.finite_cells() {
            cos[c.0 as usize] = min_dihedral_cos(&positive(rt.cell(c)).map(|v| rt.point(v)));
        }
        let ws = Workspace {
            curves,
            curve_of,
            rt,
            label,
            cos,
            boundary,
            dimension,
            feature_edges,
            peeled: FxHashSet::default(),
            oracle,
            facet_distance: criteria.facet.distance.clone(),
            cell_size: criteria.cell.size.clone(),
            facet_size: criteria.facet.size.clone(),
            bend_tolerance: criteria.bend_tolerance(),
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

    /// The feature curve vertex `v` may move along (its id and polyline), and its two
    /// neighbours along it: it is a curve vertex with exactly two feature edges, both on that
    /// curve (an end or a junction of curves stays).
    pub fn curve(&self, v: VertexId) -> Option<(CurveId, &Polyline, [VertexId; 2])> {
        self.curve_of.get(&v.0).map(|cv| {
            let (id, line) = &self.curves[cv.curve];
            (*id, line, cv.neighbours)
        })
    }

    /// How far a feature edge may leave its curve (see [`MeshCriteria::bend_tolerance`]).
    pub fn bend_tolerance(&self) -> f64 {
        self.bend_tolerance
    }

    /// The boundary facets around `v` with their area-weighted normals, oriented from the first
    /// of the two subdomains they separate to the second.
    pub fn boundary_normals(&self, v: VertexId) -> Vec<(FacetKey, Point3)> {
        let mut cells = Vec::new();
        self.rt.incident_cells(v, &mut cells);
        let mut out = Vec::new();
        for &c in &cells {
            if !self.inside(c) {
                continue;
            }
            let q = self.rt.cell(c);
            for i in 0..4 {
                let key = facet_key(q, i);
                let Some(b) = self.boundary.get(&key) else {
                    continue;
                };
                if q[i] == v {
                    continue;
                }
                let f: Vec<Point3> = (0..4)
                    .filter(|&m| m != i)
                    .map(|m| self.rt.point(q[m]))
                    .collect();
                let mut n = (f[1] - f[0]).cross(f[2] - f[0]);
                // Out of the cell, then from the first side to the second.
                if (n.dot(self.rt.point(q[i]) - f[0]) > 0.0) == (self.label(c) == b.sides[0]) {
                    n = -n;
                }
                out.push((key, n));
            }
        }
        out.sort_unstable_by_key(|&(k, _)| k);
        out.dedup_by_key(|&mut (k, _)| k);
        out
    }

    /// Whether every boundary facet of `before` (from [`Self::boundary_normals`] before a move
    /// of `v`) still faces the side it faced: a move that folds a facet over is refused even
    /// when the facet stays near the surface.
    pub fn none_folded(&self, v: VertexId, before: &[(FacetKey, Point3)]) -> bool {
        let after = self.boundary_normals(v);
        after.len() == before.len()
            && after
                .iter()
                .zip(before)
                .all(|((ka, na), (kb, nb))| ka == kb && na.dot(*nb) > 0.0)
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

    /// The two subdomains boundary facet `key` separates, sorted.
    pub fn sides(&self, key: &FacetKey) -> Option<[SubdomainId; 2]> {
        self.boundary.get(key).map(|b| b.sides)
    }

    /// The patch of boundary facet `key`.
    pub fn patch(&self, key: &FacetKey) -> Option<PatchId> {
        self.boundary.get(key).map(|b| b.patch)
    }

    /// The corner points of finite cell `c`, positively oriented.
    pub fn points(&self, c: CellId) -> [Point3; 4] {
        positive(self.rt.cell(c)).map(|v| self.rt.point(v))
    }

    /// Smallest dihedral angle of finite cell `c`.
    pub fn cell_min_dihedral(&self, c: CellId) -> f64 {
        degrees(self.cell_cos(c))
    }

    /// [`min_dihedral_cos`] of finite cell `c`.
    fn cell_cos(&self, c: CellId) -> f64 {
        self.cos.get(c.0 as usize).copied().unwrap_or(1.0)
    }

    /// Brings [`Self::cos`] up to date with the cells the last move created.
    fn refresh_cos(&mut self) {
        if self.cos.len() < self.rt.cell_capacity() {
            self.cos.resize(self.rt.cell_capacity(), 1.0);
        }
        for k in 0..self.report.created.len() {
            let c = self.report.created[k];
            if !self.rt.is_infinite_cell(c) {
                self.cos[c.0 as usize] = min_dihedral_cos(&self.points(c));
            }
        }
    }

    /// Moves `v` to `p` with weight `w`, and keeps the move when the triangulation accepted it,
    /// the boundary survived it and `keep(before, after)` holds for the smallest dihedral angles
    /// of the cells it destroyed and created inside the domain (`keep` must not decrease with
    /// `after`, so a move is refused at its first bad cell: most trial moves are). Otherwise the
    /// mesh is left as it was and `None` is returned.
    pub fn try_move(
        &mut self,
        v: VertexId,
        p: Point3,
        w: f64,
        keep: impl Fn(f64, f64) -> bool,
    ) -> Option<Change> {
        let old_point = self.rt.point(v);
        let old_weight = self.rt.weight(v);
        let moved = self.rt.move_vertex(v, p, w, &mut self.report);
        let saved = self.saved_cells();
        self.refresh_cos();
        if !moved.ok()? {
            self.restore(&by_vertices(&self.report.removed, &saved));
            return None;
        }
        let before = self.removed_angle(&saved);
        let after = self
            .relabel(|a| keep(before, a))
            .filter(|&after| keep(before, after) && self.sizes_kept(&saved, v, old_point));
        let change = Change {
            vertex: v,
            old_point,
            old_weight,
            saved,
            moved: std::mem::take(&mut self.report),
        };
        if after.is_some() {
            Some(change)
        } else {
            self.undo(change);
            None
        }
    }

    /// Puts the moved vertex back where it was, with the labels it had.
    pub fn undo(&mut self, mut change: Change) {
        // The old cells straight back, in their order; moving the vertex back is the fallback.
        if self.rt.undo_move(
            change.vertex,
            change.old_point,
            change.old_weight,
            &mut change.moved,
        ) {
            self.grow_labels();
            self.cos
                .resize(self.cos.len().max(self.rt.cell_capacity()), 1.0);
            for (&c, &(label, cos)) in change.moved.created.iter().zip(&change.saved) {
                self.label[c.0 as usize] = label;
                self.cos[c.0 as usize] = cos;
            }
            self.report = change.moved;
            return;
        }
        let back = self
            .rt
            .move_vertex_back(
                change.vertex,
                WeightedPoint3::new(change.old_point, change.old_weight),
                &mut self.report,
            )
            .unwrap_or(false);
        let saved = if back {
            // The cells are rebuilt as they were, in other slots: by their vertices.
            by_vertices(&change.moved.removed, &change.saved)
        } else {
            // The star of the old place could not be rebuilt: the move (which passed the
            // invariants) stays, and the refused undo rebuilt the same cells.
            by_vertices(&self.report.removed, &self.saved_cells())
        };
        self.refresh_cos();
        self.restore(&saved);
    }

    /// The subdomain and cached [`min_dihedral_cos`] of each cell the last move destroyed, read
    /// before any is overwritten.
    fn saved_cells(&self) -> Vec<(SubdomainId, f64)> {
        self.report
            .removed
            .iter()
            .map(|&(c, _)| (self.label(c), self.cell_cos(c)))
            .collect()
    }

    /// Labels the created cells of the last move from the subdomains `saved` by
    /// [`by_vertices`] (destroyed cells rebuilt), and the others as outside.
    fn restore(&mut self, saved: &FxHashMap<[u32; 4], SubdomainId>) {
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

    /// Smallest dihedral angle of the destroyed cells inside the domain.
    fn removed_angle(&self, saved: &[(SubdomainId, f64)]) -> f64 {
        let inf = self.rt.infinite_vertex();
        self.report
            .removed
            .iter()
            .zip(saved)
            .filter(|((_, q), (sub, _))| !q.contains(&inf) && *sub != OUTSIDE)
            .fold(180.0, |min, (_, (_, cos))| min.min(degrees(*cos)))
    }

    /// Whether no cell the last move created inside the domain has a [`Self::size_excess`]
    /// above 1 or above the largest of the destroyed cells (`v` at `old` in them). Checked last:
    /// a sizing field costs a search per cell.
    fn sizes_kept(&self, saved: &[(SubdomainId, f64)], v: VertexId, old: Point3) -> bool {
        let inf = self.rt.infinite_vertex();
        let mut bound = 1.0f64;
        for (&(_, q), &(sub, _)) in self.report.removed.iter().zip(saved) {
            if !q.contains(&inf) && sub != OUTSIDE {
                let p = positive(q).map(|x| if x == v { old } else { self.rt.point(x) });
                bound = bound.max(self.size_excess(&p, sub));
            }
        }
        self.report.created.iter().all(|&c| {
            let sub = self.label(c);
            sub == OUTSIDE || self.size_excess(&self.points(c), sub) <= bound
        })
    }

    /// [`size_excess`] under this workspace's cell size.
    fn size_excess(&self, p: &[Point3; 4], sub: SubdomainId) -> f64 {
        size_excess(&self.cell_size, p, sub)
    }

    /// Labels the created cells by crossing facets from the cells around them. Returns the
    /// smallest dihedral angle of the created cells inside the domain, or `None` when the
    /// boundary did not survive (no consistent labelling, a boundary facet gone), or a cell
    /// inside is flat or has an angle `acceptable` refuses.
    fn relabel(&mut self, acceptable: impl Fn(f64) -> bool) -> Option<f64> {
        self.grow_labels();
        let created = &self.report.created;
        let index: FxHashMap<u32, usize> =
            created.iter().enumerate().map(|(k, c)| (c.0, k)).collect();
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
                label_once(&mut new_label, &mut stack, k, l)?;
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
                label_once(&mut new_label, &mut stack, kn, l)?;
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
        // The angles first: they refuse most trial moves, and cost least.
        let mut after = 180.0f64;
        for (k, &c) in self.report.created.iter().enumerate() {
            if new_label[k]? != OUTSIDE {
                let a = self.cell_min_dihedral(c);
                if a < FLAT_DEG || !acceptable(a) {
                    return None;
                }
                after = after.min(a);
            }
        }
        // Every boundary facet of a destroyed cell must be a facet of a created one.
        let mut lost: Vec<FacetKey> = Vec::new();
        for &(_, q) in &self.report.removed {
            lost.extend(
                (0..4)
                    .map(|i| facet_key(q, i))
                    .filter(|k| self.is_boundary(k)),
            );
        }
        let mut found: Vec<FacetKey> = Vec::new();
        for &c in &self.report.created {
            let q = self.rt.cell(c);
            found.extend(
                (0..4)
                    .map(|i| facet_key(q, i))
                    .filter(|k| self.is_boundary(k)),
            );
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

    /// Peels a flat cell off the boundary: a cell with two nearly coplanar boundary facets on
    /// one patch, between its subdomain and the outside, becomes outside, and its two other
    /// facets take their place (the surface edge the two facets share flips to the opposite edge
    /// of the cell). Refused when the shared edge is a feature edge, when the opposite edge
    /// already lies on the surface (the flip would make it non-manifold), when a new facet would
    /// face the other way from the old ones, or when the cell is thicker than the facet distance
    /// and a new facet does not meet the facet-distance criterion (the surface would move by
    /// more). Returns whether the cell was peeled.
    pub fn peel(&mut self, c: CellId) -> bool {
        if !self.inside(c) {
            return false;
        }
        let q = self.rt.cell(c);
        let sub = self.label(c);
        let on_boundary: Vec<usize> = (0..4)
            .filter(|&i| self.is_boundary(&facet_key(q, i)))
            .collect();
        let &[i, j] = on_boundary.as_slice() else {
            return false;
        };
        if [i, j]
            .iter()
            .any(|&k| self.peeled.contains(&facet_key(q, k)))
        {
            return false;
        }
        let (old_i, old_j) = (
            self.boundary[&facet_key(q, i)],
            self.boundary[&facet_key(q, j)],
        );
        if old_i.patch != old_j.patch
            || old_i.sides != [OUTSIDE, sub]
            || old_j.sides != [OUTSIDE, sub]
        {
            return false;
        }
        // The facets opposite i and j share the edge (a, b); the new ones share (c, d) = (q[i], q[j]).
        let shared: Vec<u32> = (0..4)
            .filter(|&k| k != i && k != j)
            .map(|k| q[k].0)
            .collect();
        let (a, b) = (shared[0].min(shared[1]), shared[0].max(shared[1]));
        if self.feature_edges.contains(&[a, b]) || self.is_surface_edge(q[i], q[j]) {
            return false;
        }
        let normal = |k: usize| {
            let f: Vec<Point3> = (0..4)
                .filter(|&m| m != k)
                .map(|m| self.rt.point(q[m]))
                .collect();
            let n = (f[1] - f[0]).cross(f[2] - f[0]);
            // Outward from the cell.
            if n.dot(self.rt.point(q[k]) - f[0]) > 0.0 {
                -n
            } else {
                n
            }
        };
        // The new facets face the outside through the peeled cell: against their normal out of it.
        // Near a feature the two facets may lie on either side of a sharp edge with one patch
        // label: only a cell under two nearly coplanar facets is peeled.
        let (ni, nj) = (normal(i), normal(j));
        if ni.dot(nj) <= COPLANAR_COS * ni.length() * nj.length() {
            return false;
        }
        let old = ni + nj;
        let new: Vec<usize> = (0..4).filter(|&k| k != i && k != j).collect();
        if new.iter().any(|&k| normal(k).dot(old) >= 0.0) {
            return false;
        }
        // Every point of the new facets lies within the cell's thickness of the old ones (the
        // four vertices are on the old facets): the surface moves by at most that much.
        let p = self.points(c);
        let largest_face = (0..4)
            .map(|k| {
                let f: Vec<Point3> = (0..4).filter(|&m| m != k).map(|m| p[m]).collect();
                (f[1] - f[0]).cross(f[2] - f[0]).length() / 2.0
            })
            .fold(0.0, f64::max);
        let thickness = 3.0 * tet_volume(&p) / largest_face;
        let centroid = (p[0] + p[1] + p[2] + p[3]) / 4.0;
        let allowed = self.facet_distance.at(centroid, old_i.patch.0);
        // A thicker cell is still peeled when its new facets meet the facet-distance criterion
        // as refinement measures it (the surface then moves by no more than refinement allows).
        let near = || {
            new.iter().all(|&k| {
                let f: Vec<Point3> = (0..4).filter(|&m| m != k).map(|m| p[m]).collect();
                self.near_surface([f[0], f[1], f[2]], old_i.patch)
            })
        };
        if !(thickness <= allowed || !(allowed > 0.0 && allowed.is_finite()) || near()) {
            return false;
        }
        self.boundary.remove(&facet_key(q, i));
        self.boundary.remove(&facet_key(q, j));
        for k in new {
            let sides = [OUTSIDE, sub];
            self.peeled.insert(facet_key(q, k));
            self.boundary.insert(
                facet_key(q, k),
                BoundaryFacet {
                    patch: old_i.patch,
                    sides,
                },
            );
        }
        self.label[c.0 as usize] = OUTSIDE;
        true
    }

    /// Whether triangle `t` on `patch` meets the facet-distance criterion (its circumcentre lies
    /// within that distance of the surface along the triangle's normal) and the facet-size one
    /// (its circumradius is at most the size there).
    pub fn near_surface(&self, t: [Point3; 3], patch: PatchId) -> bool {
        let center = triangle_circumcenter(t[0], t[1], t[2]);
        if center.distance(t[0]) > self.facet_size.at(center, patch.0) {
            return false;
        }
        let d = self.facet_distance.at(center, patch.0);
        if !(d > 0.0 && d.is_finite()) {
            return true;
        }
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        if n.length() == 0.0 {
            return false;
        }
        let n = n.normalize() * d;
        self.oracle
            .first_segment_hit(center - n, center + n)
            .is_some()
    }

    /// Whether every boundary facet around `v` meets the facet-distance criterion.
    pub fn surface_near_around(&self, v: VertexId) -> bool {
        let mut cells = Vec::new();
        self.rt.incident_cells(v, &mut cells);
        cells.iter().filter(|&&c| self.inside(c)).all(|&c| {
            let q = self.rt.cell(c);
            (0..4).filter(|&i| q[i] != v).all(|i| {
                let Some(patch) = self.patch(&facet_key(q, i)) else {
                    return true;
                };
                let f: Vec<Point3> = (0..4)
                    .filter(|&m| m != i)
                    .map(|m| self.rt.point(q[m]))
                    .collect();
                self.near_surface([f[0], f[1], f[2]], patch)
            })
        })
    }

    /// Whether the edge `(u, v)` is an edge of a boundary facet.
    fn is_surface_edge(&self, u: VertexId, v: VertexId) -> bool {
        let mut cells = Vec::new();
        self.rt.incident_cells(u, &mut cells);
        cells.iter().any(|&c| {
            let q = self.rt.cell(c);
            q.contains(&v)
                && (0..4).any(|i| q[i] != u && q[i] != v && self.is_boundary(&facet_key(q, i)))
        })
    }

    /// The inside cells whose smallest dihedral angle is below `bound`, worst first (ties by
    /// sorted vertices, so the order does not depend on cell slots).
    pub fn slivers(&self, bound: f64) -> Vec<(f64, CellId, [VertexId; 4])> {
        let cos_bound = bound.to_radians().cos();
        let mut s: Vec<(f64, [u32; 4], CellId)> = self
            .rt
            .finite_cells()
            .filter(|&c| self.inside(c))
            .filter_map(|c| {
                let cos = self.cell_cos(c);
                (cos > cos_bound).then(|| (degrees(cos), quad_key(self.rt.cell(c)), c))
            })
            .collect();
        s.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        s.into_iter()
            .map(|(a, _, c)| (a, c, self.rt.cell(c)))
            .collect()
    }

    /// Sweeps over the slivers below `bound` degrees, worst first, trying `improve` on each
    /// (perturbation and exudation differ only in that step), until a sweep improves nothing,
    /// `max_sweeps` are done or the deadline passes. A cell `improve` could not help is not tried
    /// again while it exists. With `floor_margin` = `Some(m)`, a sweep whose worst cell could not
    /// be helped goes on only over the cells below [`SLIVER_DEG`] or `m` degrees above that worst
    /// one: the smallest angle cannot rise any more in it, and only moves near the floor (of the
    /// worst cell's neighbours) can free it in the next sweep. Returns the number of improvements
    /// kept.
    pub fn sweep_slivers(
        &mut self,
        bound: f64,
        deadline: &super::Deadline,
        max_sweeps: usize,
        floor_margin: Option<f64>,
        mut improve: impl FnMut(&mut Self, CellId) -> bool,
    ) -> usize {
        let mut kept = 0;
        let mut stuck = FxHashSet::default();
        for _ in 0..max_sweeps {
            let mut improved = 0;
            let slivers = self.slivers(bound);
            let worst = slivers.first().map_or(0.0, |s| s.0);
            // Once a cell at the sweep's smallest angle cannot be improved, that angle is the
            // mesh's for this sweep: the rest of it works only on the slivers proper.
            let mut floor_fixed = false;
            for (angle, c, cell) in slivers {
                if deadline.passed() {
                    return kept + improved;
                }
                if floor_fixed && floor_margin.is_some_and(|m| angle >= SLIVER_DEG.max(worst + m)) {
                    break;
                }
                let gone = !self.rt.is_live(c) || self.rt.cell(c) != cell;
                if !gone && !stuck.contains(&cell) && improve(self, c) {
                    improved += 1;
                } else if !gone {
                    stuck.insert(cell);
                    floor_fixed |= angle <= worst;
                }
            }
            kept += improved;
            if improved == 0 {
                break;
            }
        }
        kept
    }

    /// Smallest dihedral angle of the mesh (180 without a cell).
    pub fn min_dihedral(&self) -> f64 {
        self.rt
            .finite_cells()
            .filter(|&c| self.inside(c))
            .map(|c| self.cell_cos(c))
            .reduce(f64::max)
            .map_or(180.0, degrees)
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
            complex
                .tets
                .push(positive(cell).map(|v| mesh_index[v.0 as usize]));
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
                    .push(self.patch(&facet_key(cell, i)).unwrap_or(PatchId(0)));
                complex.facet_subdomains.push([sub, other]);
            }
        }
        complex
    }
}

/// Circumradius of tetrahedron `p` of subdomain `sub` over the cell size at its circumcentre,
/// as refinement measures it, or at its centroid where the size there is not a positive number
/// (a sliver's circumcentre may lie far outside the domain, where a sizing field is not
/// defined); 0 without a bound.
pub(super) fn size_excess(cell_size: &Sizing, p: &[Point3; 4], sub: SubdomainId) -> f64 {
    let Some(center) = crate::quality::tet_circumcenter(p) else {
        return f64::INFINITY;
    };
    let defined = |s: f64| s > 0.0 && s.is_finite();
    let mut size = cell_size.at(center, sub.0);
    if !defined(size) {
        size = cell_size.at((p[0] + p[1] + p[2] + p[3]) * 0.25, sub.0);
    }
    if defined(size) {
        center.distance(p[0]) / size
    } else {
        0.0
    }
}
