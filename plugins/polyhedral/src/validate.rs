//! Checks that a triangle surface bounds a volume: closed, edge-manifold, consistently oriented,
//! without self-intersections.

use crate::predicates::{Crossing, orient, orient2d_all_zero, segment_crossing};
use crate::tree::TriangleTree;
use delamesh_core::union_find::UnionFind;
use glam::DVec3;
use std::cmp::Ordering;

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
    /// Whether no defect was found.
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
    crossing_pairs(triangles, geometry, tree)
        .pairs
        .first()
        .copied()
}

/// Which triangles are crossed by another one.
pub(crate) fn crossed_triangles(
    triangles: &[[u32; 3]],
    geometry: &[[DVec3; 3]],
    tree: &TriangleTree,
) -> Vec<bool> {
    let mut crossed = vec![false; triangles.len()];
    for (i, j) in crossing_pairs(triangles, geometry, tree).pairs {
        crossed[i] = true;
        crossed[j] = true;
    }
    crossed
}

/// The crossing pairs of triangles and what finding them cost.
pub(crate) struct Crossings {
    /// `(i, j)`, i < j, sorted.
    pub(crate) pairs: Vec<(usize, usize)>,
    /// Candidates examined: triangle pairs, and triangles weighed against a whole flat region.
    /// Tests bound it to show the search stays near-linear on fans of long thin triangles.
    work: usize,
}

/// Flat regions of at least this many triangles are weighed as one piece against each other
/// triangle (see [`FlatRegion`]); smaller ones pair triangle by triangle.
const LARGE_REGION: usize = 8;

/// A flat region taken whole. The box of a long thin triangle overlaps the boxes of nearly all
/// its fan neighbours and of the triangles along the fan's rim, so pairing a fan over a polygon
/// of n sides triangle by triangle costs n² candidates, each settled as no crossing. Taken
/// whole, a triangle meets the region's plane in a point, a segment, or not at all, and cannot
/// cross the region when that is one of the region's vertices or edges (the region being a
/// planar triangulation: its triangles meet at shared vertices and edges only; coplanar
/// overlaps never count as crossings).
struct FlatRegion {
    triangles: Vec<u32>,
    /// A triangle of the region (none has zero area): its plane is the region's.
    plane: [DVec3; 3],
    /// Corner coordinates, sorted (vertices are shared when their coordinates are equal).
    vertices: Vec<[u64; 3]>,
    /// Edges as sorted pairs of corner coordinates, sorted.
    edges: Vec<([u64; 3], [u64; 3])>,
    min: DVec3,
    max: DVec3,
    /// Over `triangles`, in their order.
    tree: TriangleTree,
}

/// Exact coordinates as a sortable key (−0 and +0 alike, as `==` has them).
fn key(p: DVec3) -> [u64; 3] {
    (p + DVec3::ZERO).to_array().map(f64::to_bits)
}

fn edge_key(p: DVec3, q: DVec3) -> ([u64; 3], [u64; 3]) {
    let (a, b) = (key(p), key(q));
    (a.min(b), a.max(b))
}

fn bounds(g: &[DVec3; 3]) -> (DVec3, DVec3) {
    (g[0].min(g[1]).min(g[2]), g[0].max(g[1]).max(g[2]))
}

impl FlatRegion {
    fn new(triangles: Vec<u32>, geometry: &[[DVec3; 3]]) -> Self {
        let corners = || triangles.iter().map(|&t| &geometry[t as usize]);
        let plane = geometry[triangles[0] as usize];
        let mut vertices: Vec<[u64; 3]> = corners().flatten().map(|&p| key(p)).collect();
        vertices.sort_unstable();
        vertices.dedup();
        let mut edges: Vec<_> = corners()
            .flat_map(|g| (0..3).map(move |k| edge_key(g[k], g[(k + 1) % 3])))
            .collect();
        edges.sort_unstable();
        edges.dedup();
        let (min, max) = corners().map(bounds).fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), (a, b)| (lo.min(a), hi.max(b)),
        );
        let tree = TriangleTree::new(&corners().copied().collect::<Vec<_>>());
        FlatRegion {
            triangles,
            plane,
            vertices,
            edges,
            min,
            max,
            tree,
        }
    }

    /// Can the triangle `g` (of another region) cross a triangle of this region? Not when it
    /// keeps to one side of the plane, lies in it, or meets it only in a vertex or an edge of
    /// the region.
    fn may_cross(&self, g: &[DVec3; 3]) -> bool {
        let [a, b, c] = self.plane;
        let sides = g.map(|p| orient(a, b, c, p));
        let off: Vec<Ordering> = sides.into_iter().filter(|s| s.is_ne()).collect();
        if off.windows(2).any(|w| w[0] != w[1]) {
            return true;
        }
        let on: Vec<DVec3> = (0..3).filter(|&k| sides[k].is_eq()).map(|k| g[k]).collect();
        match on[..] {
            [p] => self.vertices.binary_search(&key(p)).is_err(),
            [p, q] => self.edges.binary_search(&edge_key(p, q)).is_err(),
            _ => false,
        }
    }

    /// Calls `found(t)` for the triangles of the region that cross triangle `i`.
    fn crossings(
        &self,
        i: usize,
        triangles: &[[u32; 3]],
        geometry: &[[DVec3; 3]],
        work: &mut usize,
        mut found: impl FnMut(usize),
    ) {
        let (ids, g) = (&triangles[i], &geometry[i]);
        *work += 1;
        if !self.may_cross(g) {
            return;
        }
        let (min, max) = bounds(g);
        self.tree.for_each_near_box(min, max, |k| {
            *work += 1;
            let t = self.triangles[k as usize] as usize;
            if triangles_cross(ids, g, &triangles[t], &geometry[t]) {
                found(t);
            }
        });
    }
}

/// All crossing pairs of triangles: triangles of small flat regions pair through the tree,
/// large flat regions are weighed whole against the triangles near them (see [`FlatRegion`]).
pub(crate) fn crossing_pairs(
    triangles: &[[u32; 3]],
    geometry: &[[DVec3; 3]],
    tree: &TriangleTree,
) -> Crossings {
    let region = flat_regions(triangles, geometry);
    let mut members: Vec<(u32, u32)> = (0..triangles.len() as u32)
        .map(|t| (region[t as usize], t))
        .collect();
    members.sort_unstable();
    let mut small = Vec::new();
    let mut large = Vec::new();
    for run in members.chunk_by(|x, y| x.0 == y.0) {
        let ids = run.iter().map(|m| m.1);
        if run.len() >= LARGE_REGION {
            large.push(FlatRegion::new(ids.collect(), geometry));
        } else {
            small.extend(ids);
        }
    }
    small.sort_unstable();
    let small_tree;
    let small_tree = if large.is_empty() {
        tree
    } else {
        let g: Vec<[DVec3; 3]> = small.iter().map(|&t| geometry[t as usize]).collect();
        small_tree = TriangleTree::new(&g);
        &small_tree
    };
    let mut c = Crossings {
        pairs: Vec::new(),
        work: 0,
    };
    let mut push = |i: usize, j: usize| c.pairs.push((i.min(j), i.max(j)));
    for &i in &small {
        let i = i as usize;
        let (min, max) = bounds(&geometry[i]);
        small_tree.for_each_near_box(min, max, |j| {
            c.work += 1;
            let j = small[j as usize] as usize;
            if j > i
                && region[i] != region[j]
                && triangles_cross(&triangles[i], &geometry[i], &triangles[j], &geometry[j])
            {
                push(i, j);
            }
        });
    }
    for r in &large {
        let mut near = Vec::new();
        small_tree.for_each_near_box(r.min, r.max, |j| near.push(small[j as usize] as usize));
        for i in near {
            r.crossings(i, triangles, geometry, &mut c.work, |t| push(i, t));
        }
    }
    // Large regions near each other, found through a tree whose "triangles" span their boxes.
    let boxes: Vec<[DVec3; 3]> = large.iter().map(|r| [r.min, r.max, r.max]).collect();
    let region_tree = TriangleTree::new(&boxes);
    for (a, r) in large.iter().enumerate() {
        region_tree.for_each_near_box(r.min, r.max, |b| {
            let other = &large[b as usize];
            if b as usize > a {
                for &i in &r.triangles {
                    let i = i as usize;
                    other.crossings(i, triangles, geometry, &mut c.work, |t| push(i, t));
                }
            }
        });
    }
    c.pairs.sort_unstable();
    c.pairs.dedup();
    c
}

/// The flat regions of the surface: triangles joined through edges to neighbours exactly in
/// their plane share a number. Two triangles of one region lie in one plane and never cross.
/// Triangles of zero area stay alone: every point is in their "plane", and joining through
/// them would merge regions of different planes.
fn flat_regions(triangles: &[[u32; 3]], geometry: &[[DVec3; 3]]) -> Vec<u32> {
    let mut edges: Vec<(u32, u32, u32)> = Vec::with_capacity(3 * triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((a.min(b), a.max(b), i as u32));
        }
    }
    edges.sort_unstable();
    let flat: Vec<bool> = geometry
        .iter()
        .map(|g| orient2d_all_zero(g[0], g[1], g[2]))
        .collect();
    let mut regions = UnionFind::new(triangles.len());
    for uses in edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        for pair in uses.windows(2) {
            let (i, j) = (pair[0].2 as usize, pair[1].2 as usize);
            if flat[i] || flat[j] {
                continue;
            }
            let [a, b, c] = geometry[i];
            if geometry[j]
                .iter()
                .all(|&p| orient(a, b, c, p) == Ordering::Equal)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A closed prism over a regular `n`-gon, each cap a fan of long thin triangles from one
    /// corner, plus the `extra` triangles.
    fn fan_prism(n: usize, extra: &[[DVec3; 3]]) -> (Vec<[u32; 3]>, Vec<[DVec3; 3]>) {
        let mut points = Vec::new();
        for z in [0.0, 1.0] {
            for i in 0..n {
                let a = std::f64::consts::TAU * i as f64 / n as f64;
                points.push(DVec3::new(a.cos(), a.sin(), z));
            }
        }
        let n = n as u32;
        let mut triangles = Vec::new();
        for i in 0..n {
            let j = (i + 1) % n;
            triangles.push([i, j, n + j]);
            triangles.push([i, n + j, n + i]);
        }
        for i in 1..n - 1 {
            triangles.push([0, i + 1, i]);
            triangles.push([n, n + i, n + i + 1]);
        }
        for g in extra {
            let first = points.len() as u32;
            points.extend(g);
            triangles.push([first, first + 1, first + 2]);
        }
        let geometry = triangles
            .iter()
            .map(|t| t.map(|v| points[v as usize]))
            .collect();
        (triangles, geometry)
    }

    fn pairs_of(triangles: &[[u32; 3]], geometry: &[[DVec3; 3]]) -> Crossings {
        crossing_pairs(triangles, geometry, &TriangleTree::new(geometry))
    }

    #[test]
    fn fans_cost_a_few_candidates_per_triangle() {
        let n = 2000;
        let (triangles, geometry) = fan_prism(n, &[]);
        let c = pairs_of(&triangles, &geometry);
        assert!(c.pairs.is_empty());
        // Pairing the fans triangle by triangle examines about n² / 2 candidates.
        assert!(c.work < 40 * n, "{} candidates for {n} sides", c.work);
    }

    #[test]
    fn regions_taken_whole_find_the_pairs_of_every_triangle_pair() {
        let p = |x: f64, y: f64, z: f64| DVec3::new(x, y, z);
        let extras = [
            // Through the bottom cap's interior, across many of its slivers.
            [p(-0.5, -0.2, -0.5), p(0.3, 0.4, 0.5), p(0.5, -0.3, 0.2)],
            // A corner on the bottom cap inside it, the rest above.
            [p(0.1, 0.1, 0.0), p(0.2, 0.1, 0.5), p(0.1, 0.3, 0.5)],
            // An edge in the bottom cap, across its slivers.
            [p(-0.3, -0.3, 0.0), p(0.4, 0.3, 0.0), p(0.0, 0.0, 0.6)],
            // Along a rim edge of the bottom cap, outside the prism: touches only.
            [p(1.0, 0.0, 0.0), p(0.5, 0.0, -0.5), p(1.5, 0.0, -0.5)],
        ];
        for extra in extras {
            let (triangles, geometry) = fan_prism(24, &[extra]);
            let region = flat_regions(&triangles, &geometry);
            let mut expected = Vec::new();
            for i in 0..triangles.len() {
                for j in i + 1..triangles.len() {
                    if region[i] != region[j]
                        && triangles_cross(&triangles[i], &geometry[i], &triangles[j], &geometry[j])
                    {
                        expected.push((i, j));
                    }
                }
            }
            assert_eq!(pairs_of(&triangles, &geometry).pairs, expected, "{extra:?}");
        }
    }
}
