//! The feature curves of a labelled image, as CGAL 6's `Detect_features_in_image` and
//! `Detect_features_on_image_bbox` find them: the curves where three or more classes meet (triple
//! lines), and where the labels meet the border of the image (the box faces cut the interfaces
//! there at an angle, and the box edges are creases). Protected like CAD features, they come out
//! as mesh edges instead of being rounded off by the surface facets.
//!
//! Found on the grid whose nodes are the voxel centres (index space): the class at any point is
//! the interpolation of its cube's eight voxels, so a curve where three classes meet crosses a
//! grid face only where the face's four voxels have three classes or more, and inside a cube it
//! joins the crossings of the cube's faces. On the image border, the curves of the box faces
//! cross the grid edges where their two voxels differ, and run along the box edges where the
//! label is not the background. The nodes of this graph are chained into polylines between the
//! points where other than two curves meet.

use crate::grid::{BLOCK, Class, ClassGrid, Interpolation, MIXED};
use crate::walk::changes;
use delamesh_core::refine::curves::point_segment_distance;
use delamesh_core::union_find::UnionFind;
use delamesh_piecewise_smooth::{Chains, chain};
use glam::DVec3;
use std::collections::{BTreeMap, BTreeSet};

/// Halvings of a grid face in the search for the point where three classes meet on it: the
/// point is found to 2⁻¹⁰ voxel.
const JUNCTION_DEPTH: usize = 10;
/// Curves shorter than this (index space: voxels) are the voxels' noise at a junction, unless
/// the image is so small that its voxels are the structure (see [`short`]).
const SHORT: f64 = 2.0;
/// Rounds of cleaning (each removes every short curve of the graph it starts with).
const CLEAN_ROUNDS: usize = 8;

/// Feature curves and corners in index space, before simplification.
pub(crate) struct Features {
    /// Polylines, each with whether its last point joins its first.
    pub curves: Vec<(Vec<DVec3>, bool)>,
    /// Points where other than two curves meet (curve ends among them).
    pub corners: Vec<DVec3>,
}

/// A node of the feature graph, by the grid element it lies on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Node {
    /// Where three classes meet on a grid face: the face's normal axis and lower corner.
    Face(usize, [usize; 3]),
    /// Where the curves through a cube's faces meet inside it (lower corner).
    Cube([usize; 3]),
    /// The change of class along a grid edge on the image border: its axis and lower corner.
    Edge(usize, [usize; 3]),
    /// A voxel centre on an edge of the image box.
    Voxel([usize; 3]),
}

/// Nodes with positions and the segments between them, in a deterministic order.
#[derive(Default)]
struct Graph {
    ids: BTreeMap<Node, u32>,
    positions: Vec<DVec3>,
    edges: BTreeSet<[u32; 2]>,
}

impl Graph {
    fn node(&mut self, n: Node, position: impl FnOnce() -> DVec3) -> u32 {
        if let Some(&id) = self.ids.get(&n) {
            return id;
        }
        let id = self.positions.len() as u32;
        self.positions.push(position());
        self.ids.insert(n, id);
        id
    }

    fn link(&mut self, a: u32, b: u32) {
        if a != b {
            self.edges.insert([a.min(b), a.max(b)]);
        }
    }

    /// The curves between the nodes where other than two segments meet (no corner from
    /// turning: a node of degree two continues its curve).
    fn chains(&self) -> Chains {
        let edges: Vec<[u32; 2]> = self.edges.iter().copied().collect();
        chain(&self.positions, &edges, &[], 180.0)
    }

    /// Removes what the voxels make of a curve's junctions at their own scale: spurs (curves
    /// that end nowhere, shorter than `short`) are dropped, curves that short between two
    /// junctions are contracted into one junction (at the mean of their nodes), loops that small
    /// are dropped. A triple line ends only where it meets other curves or the border, so what
    /// is left is the curves' structure seen at a few voxels.
    fn clean(&mut self, short: f64) {
        for _ in 0..CLEAN_ROUNDS {
            let chains = self.chains();
            let mut degrees = vec![0usize; self.positions.len()];
            for e in &self.edges {
                degrees[e[0] as usize] += 1;
                degrees[e[1] as usize] += 1;
            }
            let degree = |v: u32| degrees[v as usize];
            let mut merge = UnionFind::new(self.positions.len());
            let mut dropped: BTreeSet<[u32; 2]> = BTreeSet::new();
            let mut changed = false;
            for c in &chains.curves {
                let p = |i: usize| self.positions[c.vertices[i] as usize];
                let mut length: f64 = (1..c.vertices.len()).map(|i| p(i).distance(p(i - 1))).sum();
                if c.closed {
                    length += p(0).distance(p(c.vertices.len() - 1));
                }
                let (first, last) = (c.vertices[0], c.vertices[c.vertices.len() - 1]);
                let spur = !c.closed && (degree(first) == 1 || degree(last) == 1);
                if length >= short || (!c.closed && !spur && first == last) {
                    continue;
                }
                changed = true;
                if c.closed || spur {
                    for w in c.vertices.windows(2) {
                        dropped.insert([w[0].min(w[1]), w[0].max(w[1])]);
                    }
                    if c.closed {
                        dropped.insert([first.min(last), first.max(last)]);
                    }
                } else {
                    for &v in &c.vertices[1..] {
                        merge.union(c.vertices[0], v);
                    }
                }
            }
            if !changed {
                return;
            }
            self.rebuild(&mut merge, &dropped);
        }
    }

    /// The graph with each group of `merge` as one node at the mean of its nodes, without the
    /// `dropped` segments.
    fn rebuild(&mut self, merge: &mut UnionFind, dropped: &BTreeSet<[u32; 2]>) {
        let n = self.positions.len();
        let mut sum = vec![(DVec3::ZERO, 0usize); n];
        for v in 0..n as u32 {
            let r = merge.find(v) as usize;
            sum[r].0 += self.positions[v as usize];
            sum[r].1 += 1;
        }
        let mut renumber = vec![u32::MAX; n];
        let mut positions = Vec::new();
        for v in 0..n {
            let r = merge.find(v as u32) as usize;
            if renumber[r] == u32::MAX {
                renumber[r] = positions.len() as u32;
                positions.push(sum[r].0 / sum[r].1 as f64);
            }
            renumber[v] = renumber[r];
        }
        let edges = std::mem::take(&mut self.edges);
        self.positions = positions;
        self.ids.clear();
        for e in edges {
            if !dropped.contains(&e) {
                self.link(renumber[e[0] as usize], renumber[e[1] as usize]);
            }
        }
    }
}

/// The unit vector of `axis`.
fn unit(axis: usize) -> [usize; 3] {
    let mut e = [0; 3];
    e[axis] = 1;
    e
}

fn add(a: [usize; 3], b: [usize; 3]) -> [usize; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}

fn point(a: [usize; 3]) -> DVec3 {
    DVec3::new(a[0] as f64, a[1] as f64, a[2] as f64)
}

/// The number of distinct values among `c`.
fn distinct(c: &[u32]) -> usize {
    (0..c.len()).filter(|&i| !c[..i].contains(&c[i])).count()
}

/// The corners of the grid face of normal `axis` at `lower`, in cyclic order.
fn face_corners(axis: usize, lower: [usize; 3]) -> [[usize; 3]; 4] {
    let (u, v) = (unit((axis + 1) % 3), unit((axis + 2) % 3));
    [lower, add(lower, u), add(add(lower, u), v), add(lower, v)]
}

/// The feature curves of the classes of `g`. Only the trilinear interpolation has interfaces
/// that meet along curves crossing the grid faces; the nearest-voxel staircase has none here.
pub(crate) fn detect<C: Class>(g: &ClassGrid<C>) -> Features {
    let mut graph = Graph::default();
    if g.interpolation == Interpolation::Trilinear && g.dims.iter().all(|&n| n >= 2) {
        triple_lines(g, &mut graph);
        border_curves(g, &mut graph);
        box_edges(g, &mut graph);
    }
    graph.clean(short(g.dims));
    let chains = graph.chains();
    let at = |v: &u32| graph.positions[*v as usize];
    Features {
        curves: chains
            .curves
            .iter()
            .map(|c| (c.vertices.iter().map(at).collect(), c.closed))
            .collect(),
        corners: chains.corners.iter().map(at).collect(),
    }
}

/// The length under which curves are noise: [`SHORT`], or an eighth of the image's smallest
/// extent in a tiny image (a 2 × 2 × 2 image is one junction).
pub(crate) fn short(dims: [usize; 3]) -> f64 {
    let extent = dims.iter().map(|&n| n.saturating_sub(1)).min().unwrap_or(0);
    SHORT.min(extent as f64 / 8.0)
}

fn class<C: Class>(g: &ClassGrid<C>, v: [usize; 3]) -> u32 {
    g.voxel(v[0], v[1], v[2]).index()
}

/// Where three classes meet on the grid face of normal `axis` at `lower`: halving the face
/// towards a quarter whose corners and centre still show three classes.
fn face_junction<C: Class>(g: &ClassGrid<C>, axis: usize, lower: [usize; 3]) -> DVec3 {
    let (u, v) = (point(unit((axis + 1) % 3)), point(unit((axis + 2) % 3)));
    let (mut origin, mut size) = (point(lower), 1.0);
    // Every sample is on the face, so one cell's corners give its class (`class_at` there: on
    // the face's far edges only the face's own corners weigh, from either cell).
    let cell = g.cell_of(origin);
    let corners = g.cell_corners(cell);
    let base = point(cell);
    let class_at = |q: DVec3| g.pick(&corners, (q - base).clamp(DVec3::ZERO, DVec3::ONE));
    for _ in 0..JUNCTION_DEPTH {
        let half = 0.5 * size;
        let quarter = [(0.0, 0.0), (half, 0.0), (half, half), (0.0, half)]
            .into_iter()
            .map(|(a, b)| origin + a * u + b * v)
            .find(|&o| {
                let samples = [
                    o,
                    o + half * u,
                    o + half * (u + v),
                    o + half * v,
                    o + 0.5 * half * (u + v),
                ]
                .map(class_at);
                distinct(&samples) >= 3
            });
        match quarter {
            Some(o) => (origin, size) = (o, half),
            None => break,
        }
    }
    origin + 0.5 * size * (u + v)
}

/// The triple lines: through the faces of every cube with three classes or more.
fn triple_lines<C: Class>(g: &ClassGrid<C>, graph: &mut Graph) {
    let [bx, by, bz] = g.blocks();
    let mut faces = Vec::with_capacity(6);
    for kb in 0..bz {
        for jb in 0..by {
            for ib in 0..bx {
                let b = [ib, jb, kb];
                // The cubes whose lower corner is in the block (each cube in one block) have
                // their corners among the block's voxels: a block of two classes has none.
                let range = |a: usize| b[a] * BLOCK..((b[a] + 1) * BLOCK).min(g.dims[a] - 1);
                if g.block_summary(b) != MIXED || !three_classes(g, range) {
                    continue;
                }
                for k in range(2) {
                    for j in range(1) {
                        for i in range(0) {
                            let lower = [i, j, k];
                            let corners: [u32; 8] = std::array::from_fn(|n| {
                                class(g, add(lower, [n & 1, (n >> 1) & 1, n >> 2]))
                            });
                            if distinct(&corners) < 3 {
                                continue;
                            }
                            faces.clear();
                            for axis in 0..3 {
                                for face in [lower, add(lower, unit(axis))] {
                                    let c = face_corners(axis, face).map(|v| class(g, v));
                                    if distinct(&c) >= 3 {
                                        let f = graph.node(Node::Face(axis, face), || {
                                            face_junction(g, axis, face)
                                        });
                                        faces.push(f);
                                    }
                                }
                            }
                            match faces[..] {
                                // One face alone: a curve through a face of four classes (two
                                // lines there, a junction of their own).
                                [] | [_] => {}
                                [a, b] => graph.link(a, b),
                                _ => {
                                    let centre = faces
                                        .iter()
                                        .map(|&f| graph.positions[f as usize])
                                        .sum::<DVec3>()
                                        / faces.len() as f64;
                                    let c = graph.node(Node::Cube(lower), || centre);
                                    for &f in &faces {
                                        graph.link(c, f);
                                    }
                                }
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Whether the voxels of the box `range(0) × range(1) × range(2)` grown by one on each upper
/// side have three classes or more.
fn three_classes<C: Class>(
    g: &ClassGrid<C>,
    range: impl Fn(usize) -> std::ops::Range<usize>,
) -> bool {
    let grown = |a: usize| {
        let r = range(a);
        r.start..=r.end
    };
    let mut seen: [Option<u32>; 2] = [None; 2];
    for k in grown(2) {
        for j in grown(1) {
            for i in grown(0) {
                let c = Some(class(g, [i, j, k]));
                if seen[0] == c || seen[1] == c {
                    continue;
                }
                if seen[0].is_none() {
                    seen[0] = c;
                } else if seen[1].is_none() {
                    seen[1] = c;
                } else {
                    return true;
                }
            }
        }
    }
    false
}

/// The node where the class changes along the grid edge of `axis` from `lower`.
fn edge_node<C: Class>(g: &ClassGrid<C>, graph: &mut Graph, axis: usize, lower: [usize; 3]) -> u32 {
    graph.node(Node::Edge(axis, lower), || {
        let (a, b) = (point(lower), point(add(lower, unit(axis))));
        let mut found = Vec::new();
        changes(g, a, b, &mut found);
        a + found.first().map_or(0.5, |c| c.t) * (b - a)
    })
}

/// The curves on the faces of the image box: across each grid face lying on the box, between
/// the changes of class on its edges.
fn border_curves<C: Class>(g: &ClassGrid<C>, graph: &mut Graph) {
    for axis in 0..3 {
        let (ua, va) = ((axis + 1) % 3, (axis + 2) % 3);
        for side in [0, g.dims[axis] - 1] {
            for t in 0..g.dims[va] - 1 {
                for s in 0..g.dims[ua] - 1 {
                    let mut lower = [0; 3];
                    (lower[axis], lower[ua], lower[va]) = (side, s, t);
                    border_face(g, graph, axis, lower);
                }
            }
        }
    }
}

fn border_face<C: Class>(g: &ClassGrid<C>, graph: &mut Graph, axis: usize, lower: [usize; 3]) {
    let corners = face_corners(axis, lower);
    let c = corners.map(|v| class(g, v));
    let count = distinct(&c);
    if count < 2 {
        return;
    }
    // Edge `e` of the face joins corners `e` and `e + 1`.
    let (ua, va) = ((axis + 1) % 3, (axis + 2) % 3);
    let edge_of = |e: usize| -> (usize, [usize; 3]) {
        match e {
            0 => (ua, corners[0]),
            1 => (va, corners[1]),
            2 => (ua, corners[3]),
            _ => (va, corners[0]),
        }
    };
    let crossing: Vec<Option<u32>> = (0..4)
        .map(|e| {
            (c[e] != c[(e + 1) % 4]).then(|| {
                let (a, l) = edge_of(e);
                edge_node(g, graph, a, l)
            })
        })
        .collect();
    if count >= 3 {
        let f = graph.node(Node::Face(axis, lower), || face_junction(g, axis, lower));
        for x in crossing.iter().flatten() {
            graph.link(f, *x);
        }
        return;
    }
    let present: Vec<u32> = crossing.iter().flatten().copied().collect();
    match present[..] {
        [a, b] => graph.link(a, b),
        [_, _, _, _] => {
            // A saddle of two classes: the class at the centre joins its two corners, and each
            // corner of the other class is cut off by its two edges' crossings.
            let o = point(lower) + 0.5 * (point(unit(ua)) + point(unit(va)));
            let centre = g.class_at(o);
            for e in 0..4 {
                if c[e] != centre {
                    if let (Some(a), Some(b)) = (crossing[(e + 3) % 4], crossing[e]) {
                        graph.link(a, b);
                    }
                }
            }
        }
        _ => {}
    }
}

/// The edges of the image box, where their voxels are not background.
fn box_edges<C: Class>(g: &ClassGrid<C>, graph: &mut Graph) {
    for axis in 0..3 {
        let (ua, va) = ((axis + 1) % 3, (axis + 2) % 3);
        for a in [0, g.dims[ua] - 1] {
            for b in [0, g.dims[va] - 1] {
                for s in 0..g.dims[axis] - 1 {
                    let mut lower = [0; 3];
                    (lower[axis], lower[ua], lower[va]) = (s, a, b);
                    let upper = add(lower, unit(axis));
                    let (ca, cb) = (class(g, lower), class(g, upper));
                    let voxel = |graph: &mut Graph, v| graph.node(Node::Voxel(v), || point(v));
                    if ca == cb {
                        if ca != 0 {
                            let (p, q) = (voxel(graph, lower), voxel(graph, upper));
                            graph.link(p, q);
                        }
                        continue;
                    }
                    let x = edge_node(g, graph, axis, lower);
                    if ca != 0 {
                        let p = voxel(graph, lower);
                        graph.link(p, x);
                    }
                    if cb != 0 {
                        let q = voxel(graph, upper);
                        graph.link(x, q);
                    }
                }
            }
        }
    }
}

/// Douglas–Peucker simplification of a polyline to within `tolerance`, ends kept; a closed one is
/// cut at its first point and the point farthest from it.
pub(crate) fn simplify(points: &[DVec3], closed: bool, tolerance: f64) -> Vec<DVec3> {
    if points.len() < 3 {
        return points.to_vec();
    }
    if closed {
        let far = (1..points.len())
            .max_by(|&a, &b| {
                let d = |i: usize| points[i].distance_squared(points[0]);
                d(a).total_cmp(&d(b)).then(b.cmp(&a))
            })
            .unwrap_or(1);
        let mut first = simplify(&points[..=far], false, tolerance);
        let mut rest = points[far..].to_vec();
        rest.push(points[0]);
        let second = simplify(&rest, false, tolerance);
        first.extend_from_slice(&second[1..second.len() - 1]);
        return first;
    }
    let mut keep = vec![false; points.len()];
    keep[0] = true;
    keep[points.len() - 1] = true;
    // An explicit stack: the recursion depth would follow the input.
    let mut stack = vec![(0, points.len() - 1)];
    while let Some((a, b)) = stack.pop() {
        let (p, q) = (points[a], points[b]);
        let far = (a + 1..b)
            .map(|i| (i, point_segment_distance(points[i], p, q)))
            .max_by(|x, y| x.1.total_cmp(&y.1).then(y.0.cmp(&x.0)));
        if let Some((i, _)) = far.filter(|&(_, d)| d > tolerance) {
            keep[i] = true;
            stack.push((a, i));
            stack.push((i, b));
        }
    }
    points
        .iter()
        .zip(&keep)
        .filter_map(|(&p, &k)| k.then_some(p))
        .collect()
}
