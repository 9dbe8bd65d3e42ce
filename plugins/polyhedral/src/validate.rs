//! Checks that a triangle surface bounds a volume: closed, edge-manifold, consistently oriented,
//! without self-intersections.

use crate::predicates::{Crossing, orient, segment_crossing};
use crate::tree::TriangleTree;
use delamesh_core::union_find::UnionFind;
use glam::DVec3;

/// What prevents a triangle surface from bounding a volume. All counts zero: it does.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct SurfaceDefects {
    /// Edges used by one triangle only.
    pub border_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Manifold edges whose two triangles traverse them in the same direction.
    pub inconsistent_edges: usize,
    /// Triangles with a repeated vertex index.
    pub degenerate_triangles: usize,
    /// One pair of triangles that cross each other, if any.
    pub first_intersection: Option<(usize, usize)>,
}

impl SurfaceDefects {
    pub fn is_empty(&self) -> bool {
        *self == SurfaceDefects::default()
    }
}

/// Directed-edge bookkeeping and self-intersection search (AABB tree + exact predicates).
pub fn surface_defects(points: &[DVec3], triangles: &[[u32; 3]]) -> SurfaceDefects {
    let geometry: Vec<[DVec3; 3]> = triangles
        .iter()
        .map(|t| t.map(|v| points[v as usize]))
        .collect();
    surface_defects_in(triangles, &geometry, &TriangleTree::new(&geometry))
}

/// [`surface_defects`] with the triangles' points and their tree already built (the oracle keeps
/// both for its queries).
pub(crate) fn surface_defects_in(
    triangles: &[[u32; 3]],
    geometry: &[[DVec3; 3]],
    tree: &TriangleTree,
) -> SurfaceDefects {
    let mut d = SurfaceDefects::default();
    // Every directed edge as (min, max, traversed min→max), sorted: the uses of an edge are
    // consecutive.
    let mut edges: Vec<(u32, u32, bool)> = Vec::with_capacity(3 * triangles.len());
    for t in triangles {
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
            d.degenerate_triangles += 1;
            continue;
        }
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), a < b));
        }
    }
    edges.sort_unstable();
    for uses in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let forward = uses.iter().filter(|e| e.2).count();
        match uses.len() {
            1 => d.border_edges += 1,
            2 if forward != 1 => d.inconsistent_edges += 1,
            2 => {}
            _ => d.non_manifold_edges += 1,
        }
    }
    d.first_intersection = first_intersection(triangles, geometry, tree);
    d
}

/// A pair of triangles whose interiors meet (shared vertices and edges do not count).
fn first_intersection(
    triangles: &[[u32; 3]],
    geometry: &[[DVec3; 3]],
    tree: &TriangleTree,
) -> Option<(usize, usize)> {
    let mut first = None;
    crossing_pairs(triangles, geometry, tree, |i, j| {
        first = Some((i, j));
        false
    });
    first
}

/// Which triangles are crossed by another one.
pub(crate) fn crossed_triangles(
    triangles: &[[u32; 3]],
    geometry: &[[DVec3; 3]],
    tree: &TriangleTree,
) -> Vec<bool> {
    let mut crossed = vec![false; triangles.len()];
    crossing_pairs(triangles, geometry, tree, |i, j| {
        crossed[i] = true;
        crossed[j] = true;
        true
    });
    crossed
}

/// Calls `found(i, j)`, i < j, for the crossing pairs of triangles in order of `i`, while it
/// returns true.
fn crossing_pairs(
    triangles: &[[u32; 3]],
    geometry: &[[DVec3; 3]],
    tree: &TriangleTree,
    mut found: impl FnMut(usize, usize) -> bool,
) {
    let plane = flat_regions(triangles, geometry);
    let mut partners = Vec::new();
    for (i, t) in triangles.iter().enumerate() {
        let g = &geometry[i];
        let (min, max) = (g[0].min(g[1]).min(g[2]), g[0].max(g[1]).max(g[2]));
        partners.clear();
        tree.for_each_near_box(min, max, |j| {
            let j = j as usize;
            if j > i && plane[i] != plane[j] && triangles_cross(t, g, &triangles[j], &geometry[j]) {
                partners.push(j);
            }
        });
        partners.sort_unstable();
        for &j in &partners {
            if !found(i, j) {
                return;
            }
        }
    }
}

/// The flat regions of the surface: triangles joined through edges to neighbours exactly in
/// their plane share a number. Two triangles of one region lie in one plane and never cross; a
/// fan over a polygonal cap makes all pairs of its long thin triangles candidates, and settling
/// each by exact orientations (all of them zero, the dearest case) cost seconds.
fn flat_regions(triangles: &[[u32; 3]], geometry: &[[DVec3; 3]]) -> Vec<u32> {
    let mut edges: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), i as u32));
        }
    }
    edges.sort_unstable();
    let mut regions = UnionFind::new(triangles.len());
    for uses in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        for pair in uses.windows(2) {
            let (i, j) = (pair[0].2 as usize, pair[1].2 as usize);
            let [a, b, c] = geometry[i];
            if geometry[j]
                .iter()
                .all(|&p| orient(a, b, c, p) == std::cmp::Ordering::Equal)
            {
                regions.union(i as u32, j as u32);
            }
        }
    }
    (0..triangles.len() as u32)
        .map(|i| regions.find(i))
        .collect()
}

/// Do two triangles cross? Triangles sharing an edge never do (a fold onto itself is not
/// detected); triangles sharing a vertex cross when the edge opposite the shared vertex of one
/// passes through the other.
///
/// Vertices are shared when their indices or their coordinates are equal, so that closed components
/// touching along a common face (each with its own copy of the face, as the piecewise-smooth
/// plugin gives two subdomains sharing an interface) are not mistaken for crossing ones. Coincident
/// triangles share all three vertices and never cross.
fn triangles_cross(ti: &[u32; 3], gi: &[DVec3; 3], tj: &[u32; 3], gj: &[DVec3; 3]) -> bool {
    let shared = (0..3)
        .filter(|&a| (0..3).any(|b| ti[a] == tj[b] || gi[a] == gj[b]))
        .count();
    let hits = |edge: (DVec3, DVec3), g: &[DVec3; 3], strict: bool| {
        // A common point lies in both bounding boxes (exact comparisons): most neighbours fail
        // this before any orientation test, among them the coplanar ones of flat regions whose
        // exact orientations are the dearest.
        let (lo, hi) = (g[0].min(g[1]).min(g[2]), g[0].max(g[1]).max(g[2]));
        if edge.0.min(edge.1).cmpgt(hi).any() || edge.0.max(edge.1).cmplt(lo).any() {
            return false;
        }
        // Long thin triangles have boxes that overlap nearly everything; most pairs are then
        // coplanar (a fan over a cap), where the exact orientations are dearest.
        if separated(edge, g) {
            return false;
        }
        match segment_crossing(edge.0, edge.1, g) {
            Crossing::Proper { .. } => true,
            Crossing::Degenerate => !strict,
            Crossing::None | Crossing::Coplanar => false,
        }
    };
    // One triangle on one side of the other's plane (or both in one plane, where edges count
    // as no crossing) settles the pair with three orientations instead of up to thirty.
    if one_side(gi, gj, ti, tj) || one_side(gj, gi, tj, ti) {
        return false;
    }
    match shared {
        0 => (0..3).any(|k| {
            hits((gi[k], gi[(k + 1) % 3]), gj, false) || hits((gj[k], gj[(k + 1) % 3]), gi, false)
        }),
        1 => {
            let opposite = |t: &[u32; 3], g: &[DVec3; 3], other: &[u32; 3], og: &[DVec3; 3]| {
                let k = (0..3)
                    .find(|&k| other.contains(&t[k]) || og.contains(&g[k]))
                    .unwrap_or(0);
                (g[(k + 1) % 3], g[(k + 2) % 3])
            };
            hits(opposite(ti, gi, tj, gj), gj, true) || hits(opposite(tj, gj, ti, gi), gi, true)
        }
        _ => false,
    }
}

/// Are the vertices of `gj` not shared with `gi` all strictly on one side of the plane of `gi`, or
/// all in it? Then the triangles meet at most at shared vertices, or are coplanar.
fn one_side(gi: &[DVec3; 3], gj: &[DVec3; 3], ti: &[u32; 3], tj: &[u32; 3]) -> bool {
    let mut sides = (0..3)
        .filter(|&b| !(0..3).any(|a| ti[a] == tj[b] || gi[a] == gj[b]))
        .map(|b| orient(gi[0], gi[1], gi[2], gj[b]));
    let Some(first) = sides.next() else {
        return true;
    };
    sides.all(|s| s == first)
}

/// Is the segment certainly apart from the triangle? A floating-point separating-axis test on the
/// triangle's normal and its three in-plane edge normals, trusted only beyond a margin far above
/// the rounding error, so that it never hides a crossing the exact predicates would find.
fn separated(edge: (DVec3, DVec3), g: &[DVec3; 3]) -> bool {
    let origin = g[0];
    let local = [g[0] - origin, g[1] - origin, g[2] - origin];
    let (p, q) = (edge.0 - origin, edge.1 - origin);
    let reach = local
        .iter()
        .chain([&p, &q])
        .map(|v| v.abs().max_element())
        .fold(0.0, f64::max);
    let normal = (local[1] - local[0]).cross(local[2] - local[0]);
    let axes = [
        normal,
        normal.cross(local[1] - local[0]),
        normal.cross(local[2] - local[1]),
        normal.cross(local[0] - local[2]),
    ];
    axes.iter().any(|axis| {
        let margin = 1e-9 * axis.abs().max_element() * reach;
        let t = local.map(|v| axis.dot(v));
        let (tlo, thi) = (t[0].min(t[1]).min(t[2]), t[0].max(t[1]).max(t[2]));
        let (sp, sq) = (axis.dot(p), axis.dot(q));
        sp.min(sq) > thi + margin || sp.max(sq) < tlo - margin
    })
}
