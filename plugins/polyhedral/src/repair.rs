//! Turns the triangles users actually have (duplicated, degenerate, inconsistently oriented,
//! open, non-manifold) into a closed 2-chain whose winding number defines the domain.
//!
//! A set of oriented triangles is a 2-chain; where its boundary (the 1-chain of edges whose uses
//! do not cancel) is empty, the winding number of a point — the signed count of triangles a ray
//! from it crosses — does not depend on the ray. So the repaired surface is closed *as a chain*:
//! each connected loop of boundary edges is capped by a fan from its centroid. Caps fill holes
//! the way a user expects (a cube missing a face gets the face back), leave non-manifold edges
//! whose uses cancel alone, and never need the surface to be a manifold.

use crate::predicates::orient2d_all_zero;
use delamesh_core::mesh::count_phrases;
use delamesh_core::union_find::UnionFind;
use glam::DVec3;
use std::collections::HashMap;

/// What was repaired or reinterpreted in the input surface. All zero: it bounded a volume as it
/// was.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Repairs {
    /// Triangles with a repeated vertex or three collinear vertices, dropped.
    pub degenerate_dropped: usize,
    /// Triangles on the same three vertices as an earlier one, dropped.
    pub duplicates_dropped: usize,
    /// Triangles re-oriented so that each connected component is consistent and faces outwards.
    pub flipped: usize,
    /// Edges used by a single triangle; the loops they form are capped.
    pub border_edges: usize,
    /// Edges used by more than two triangles.
    pub non_manifold_edges: usize,
    /// Triangles added to cap the holes.
    pub cap_triangles: usize,
    /// Triangles crossed by another triangle (self-intersections and overlaps).
    pub crossing_triangles: usize,
}

impl Repairs {
    /// Did the input need no repair at all?
    pub fn is_empty(&self) -> bool {
        *self == Repairs::default()
    }

    /// Does the domain need the winding-number definition (rather than one subdomain per closed
    /// component)? Dropped and flipped triangles alone leave a surface that bounds a volume.
    pub fn needs_winding_domain(&self) -> bool {
        self.border_edges > 0 || self.non_manifold_edges > 0 || self.crossing_triangles > 0
    }

    /// One phrase per repair, for warnings and reports.
    pub fn describe(&self) -> Vec<String> {
        count_phrases([
            (self.degenerate_dropped, "zero-area triangles dropped"),
            (self.duplicates_dropped, "duplicate triangles dropped"),
            (self.flipped, "triangles re-oriented"),
            (self.border_edges, "border edges (holes capped)"),
            (
                self.non_manifold_edges,
                "non-manifold edges (inside by winding number)",
            ),
            (
                self.crossing_triangles,
                "self-intersecting triangles (inside by winding number)",
            ),
        ])
    }
}

/// The repaired surface: triangles over `points` (the input's followed by the caps' centres),
/// and for each triangle the input triangle it comes from (`None` for caps).
pub(crate) struct Repaired {
    pub points: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    pub source: Vec<Option<usize>>,
    pub repairs: Repairs,
}

/// Drops degenerate and duplicate triangles, orients each component consistently and caps the
/// boundary loops. Indices must be in range (checked by the caller).
pub(crate) fn repair(points: &[DVec3], triangles: &[[u32; 3]]) -> Repaired {
    let mut repairs = Repairs::default();
    let mut kept: Vec<[u32; 3]> = Vec::with_capacity(triangles.len());
    let mut source: Vec<Option<usize>> = Vec::with_capacity(triangles.len());
    // Copies of a triangle (same three vertices) by orientation: opposite copies cancel as a
    // chain (a wall between two solids, whose union remains); of the rest, one copy stays.
    let mut net: HashMap<[u32; 3], (i64, bool)> = HashMap::new();
    let mut valid: Vec<usize> = Vec::with_capacity(triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        let [a, b, c] = t.map(|v| points[v as usize]);
        if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] || orient2d_all_zero(a, b, c) {
            repairs.degenerate_dropped += 1;
            continue;
        }
        let (key, even) = canonical(t);
        net.entry(key).or_insert((0, false)).0 += if even { 1 } else { -1 };
        valid.push(i);
    }
    for i in valid {
        let (key, even) = canonical(&triangles[i]);
        let keep = net.get_mut(&key).is_some_and(|(count, taken)| {
            let keep = *count != 0 && (*count > 0) == even && !*taken;
            *taken |= keep;
            keep
        });
        if keep {
            kept.push(triangles[i]);
            source.push(Some(i));
        } else {
            repairs.duplicates_dropped += 1;
        }
    }
    repairs.flipped = orient(points, &mut kept);
    let (border, non_manifold) = edge_counts(&kept);
    repairs.border_edges = border;
    repairs.non_manifold_edges = non_manifold;
    let mut points = points.to_vec();
    let before = kept.len();
    cap_boundary(&mut points, &mut kept);
    repairs.cap_triangles = kept.len() - before;
    source.resize(kept.len(), None);
    Repaired {
        points,
        triangles: kept,
        source,
        repairs,
    }
}

/// The sorted vertices of a triangle, and whether the triangle lists them in an even permutation.
fn canonical(t: &[u32; 3]) -> ([u32; 3], bool) {
    let mut key = *t;
    key.sort_unstable();
    // A rotation of the sorted order is even; a rotation of its reverse is odd.
    let even = [[0, 1, 2], [1, 2, 0], [2, 0, 1]]
        .iter()
        .any(|r| [key[r[0]], key[r[1]], key[r[2]]] == *t);
    (key, even)
}

/// Every use of every edge as (low vertex, high vertex, triangle, traversed low→high), sorted so
/// that the uses of an edge are consecutive.
pub(crate) fn edge_uses(triangles: &[[u32; 3]]) -> Vec<(u32, u32, u32, bool)> {
    let mut uses = Vec::with_capacity(3 * triangles.len());
    for (i, t) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            uses.push((a.min(b), a.max(b), i as u32, a < b));
        }
    }
    uses.sort_unstable();
    uses
}

fn edge_counts(triangles: &[[u32; 3]]) -> (usize, usize) {
    let uses = edge_uses(triangles);
    let (mut border, mut non_manifold) = (0, 0);
    for e in uses.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        match e.len() {
            1 => border += 1,
            2 => {}
            _ => non_manifold += 1,
        }
    }
    (border, non_manifold)
}

/// Orients the triangles of each component (triangles joined by edges with exactly two uses) so
/// that neighbours traverse their common edge in opposite directions, and turns a component that
/// needed this outwards (positive signed volume). Components consistent as given keep their
/// orientation: an inward one is a deliberate hollow. Returns the number of triangles flipped.
fn orient(points: &[DVec3], triangles: &mut [[u32; 3]]) -> usize {
    let n = triangles.len();
    // neighbours[t]: (other triangle, must the two have opposite flip states?)
    let mut neighbours: Vec<Vec<(u32, bool)>> = vec![Vec::new(); n];
    for e in edge_uses(triangles).chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if let [u, w] = e {
            neighbours[u.2 as usize].push((w.2, u.3 == w.3));
            neighbours[w.2 as usize].push((u.2, u.3 == w.3));
        }
    }
    let mut flip: Vec<Option<bool>> = vec![None; n];
    let mut flipped = 0;
    let mut stack = Vec::new();
    let mut members = Vec::new();
    for seed in 0..n {
        if flip[seed].is_some() {
            continue;
        }
        flip[seed] = Some(false);
        stack.push(seed as u32);
        members.clear();
        let mut needed = false;
        while let Some(t) = stack.pop() {
            members.push(t);
            let f = flip[t as usize].unwrap_or(false);
            for &(u, differ) in &neighbours[t as usize] {
                let want = f ^ differ;
                needed |= differ;
                // Already set: on a non-orientable component the edge stays inconsistent, and
                // its uses do not cancel in the chain (it gets capped like a border).
                if flip[u as usize].is_none() {
                    flip[u as usize] = Some(want);
                    stack.push(u);
                }
            }
        }
        if !needed {
            continue;
        }
        let state = |t: u32| flip[t as usize].unwrap_or(false);
        let centre = members
            .iter()
            .map(|&t| points[triangles[t as usize][0] as usize])
            .sum::<DVec3>()
            / members.len() as f64;
        let volume: f64 = members
            .iter()
            .map(|&t| {
                let [a, b, c] = triangles[t as usize].map(|v| points[v as usize] - centre);
                let v = a.dot(b.cross(c));
                if state(t) { -v } else { v }
            })
            .sum();
        for &t in &members {
            if state(t) != (volume < 0.0) {
                triangles[t as usize].swap(1, 2);
                flipped += 1;
            }
        }
    }
    flipped
}

/// Closes the chain: the edges whose uses do not cancel form a 1-cycle (the boundary of a
/// boundary is empty); each connected part of it is coned from its centroid, reversed, so that
/// the cone's boundary cancels it.
fn cap_boundary(points: &mut Vec<DVec3>, triangles: &mut Vec<[u32; 3]>) {
    // Directed boundary edges a → b, each with its multiplicity.
    let mut boundary: Vec<(u32, u32)> = Vec::new();
    for e in edge_uses(triangles).chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        let net: i64 = e.iter().map(|u| if u.3 { 1 } else { -1 }).sum();
        let (lo, hi) = (e[0].0, e[0].1);
        let edge = if net > 0 { (lo, hi) } else { (hi, lo) };
        boundary.extend(std::iter::repeat_n(edge, net.unsigned_abs() as usize));
    }
    if boundary.is_empty() {
        return;
    }
    let mut sets = UnionFind::new(points.len());
    for &(a, b) in &boundary {
        sets.union(a, b);
    }
    // Centroid of each part's vertices, in order of the part's first edge.
    let mut part_of: HashMap<u32, usize> = HashMap::new();
    let mut sums: Vec<(DVec3, f64, Vec<u32>)> = Vec::new();
    for &(a, _) in &boundary {
        let root = sets.find(a);
        let k = *part_of.entry(root).or_insert_with(|| {
            sums.push((DVec3::ZERO, 0.0, Vec::new()));
            sums.len() - 1
        });
        sums[k].2.push(a);
    }
    let first_cap = points.len() as u32;
    for (_, _, vertices) in &mut sums {
        vertices.sort_unstable();
        vertices.dedup();
        let c = vertices.iter().map(|&v| points[v as usize]).sum::<DVec3>() / vertices.len() as f64;
        points.push(c);
    }
    for &(a, b) in &boundary {
        let k = part_of[&sets.find(a)];
        triangles.push([first_cap + k as u32, b, a]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube() -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let m = delamesh_core::mesh::SurfaceMesh::cuboid(DVec3::ZERO, DVec3::ONE);
        (m.positions, m.triangles)
    }

    fn signed_volume(p: &[DVec3], t: &[[u32; 3]]) -> f64 {
        t.iter()
            .map(|f| {
                let [a, b, c] = f.map(|v| p[v as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn shuffled_cube_is_reoriented_outwards() {
        let (p, mut t) = cube();
        for (i, f) in t.iter_mut().enumerate() {
            if i % 3 != 1 {
                f.swap(0, 1);
            }
        }
        let r = repair(&p, &t);
        assert!(r.repairs.flipped > 0);
        assert_eq!(edge_counts(&r.triangles), (0, 0));
        assert!((signed_volume(&r.points, &r.triangles) - 1.0).abs() < 1e-12);
        assert!(!r.repairs.needs_winding_domain());
    }

    #[test]
    fn a_missing_face_is_capped_and_the_chain_closes() {
        let (p, mut t) = cube();
        t.truncate(10);
        let r = repair(&p, &t);
        assert_eq!(r.repairs.border_edges, 4);
        assert_eq!(r.repairs.cap_triangles, 4);
        assert!((signed_volume(&r.points, &r.triangles) - 1.0).abs() < 1e-12);
        // Closed as a chain: every edge's uses cancel.
        for e in edge_uses(&r.triangles).chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
            assert_eq!(e.iter().filter(|u| u.3).count() * 2, e.len());
        }
    }

    #[test]
    fn duplicates_and_degenerates_are_dropped() {
        let (mut p, mut t) = cube();
        t.push(t[3]);
        t.push([t[5][0], t[5][2], t[5][1]]);
        let (a, b) = (t[0][0], t[0][1]);
        p.push((p[a as usize] + p[b as usize]) / 2.0);
        t.push([a, b, p.len() as u32 - 1]);
        t.push([2, 2, 3]);
        let r = repair(&p, &t);
        // One copy of the repeated triangle stays; the reversed pair cancels entirely, and the
        // hole it leaves is capped back.
        assert_eq!(r.repairs.duplicates_dropped, 3);
        assert_eq!(r.repairs.degenerate_dropped, 2);
        assert_eq!(r.repairs.border_edges, 3);
        assert!((signed_volume(&r.points, &r.triangles) - 1.0).abs() < 1e-12);
    }
}
