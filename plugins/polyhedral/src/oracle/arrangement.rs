//! The boundary of the winding-number domain as a triangle surface, for meshes that keep the
//! surface (`--preserve-surface`) of an input that does not bound a volume as given.
//!
//! Each pair of crossing triangles meets along a segment; where three triangles cross, their
//! three segments meet at one point. Every crossed triangle is cut along its segments (a 2D
//! constrained Delaunay triangulation in its plane), so that the pieces of all the triangles meet
//! only along shared edges. The pieces then fall into sheets joined across ordinary edges, on
//! which the winding number just behind and just in front does not change: a sheet is kept where
//! it separates `w ≥ 1` from `w ≤ 0` (turned to face `w ≤ 0`), and dropped where it is buried
//! inside the volume or lies outside it.
//!
//! Every point is named by what makes it (an input corner, an input edge through a triangle,
//! three triangles), so the pieces of neighbouring triangles share their points exactly; the
//! coordinates of a new point are computed once from its name. Degenerate contacts (a corner on
//! another triangle, two edges through each other) are refused rather than guessed.

use super::PolyhedralOracle;
use crate::predicates::{Crossing, segment_crossing};
use crate::repair::edge_uses;
use crate::validate::{crossing_pairs, surface_defects};
use delamesh_core::mesh::weld_exact;
use delamesh_core::oracle::PatchId;
use delamesh_core::union_find::UnionFind;
use glam::{DVec2, DVec3};
use spade::{ConstrainedDelaunayTriangulation, Point2, Triangulation};
use std::collections::{BTreeMap, HashMap};

/// The boundary of the winding-number domain, as triangles whose interiors do not meet.
#[derive(Clone, Debug, Default)]
pub struct WindingBoundary {
    /// The input's corners that the boundary uses, followed by the points where triangles cross.
    pub points: Vec<DVec3>,
    /// Oriented outwards (the domain behind them).
    pub triangles: Vec<[u32; 3]>,
    /// The patch of the input triangle each triangle lies in.
    pub patches: Vec<PatchId>,
    /// Triangles of the (repaired) input that were cut along their crossings.
    pub cut: usize,
    /// Triangles and pieces left out: buried inside the volume, or outside it.
    pub dropped: usize,
    /// Points where kept sheets touched (a pinched vertex or an edge of four triangles), given
    /// one copy per sheet, the copies moved apart.
    pub separated: usize,
}

/// How far, relative to the diagonal of the bounding box, the copies of a point where sheets
/// touch are moved into their own sheet: far below the distances a mesh is measured to (a
/// tenth of fTetWild's default envelope), far above rounding.
const SEPARATION: f64 = 1e-4;

/// Why the boundary could not be built as a surface.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ArrangementError {
    /// A contact that is not a proper crossing: a corner on another triangle, two edges through
    /// each other, or a crossing segment through an edge of a third triangle.
    #[error("triangles touch without crossing cleanly near ({0:.6e}, {1:.6e}, {2:.6e})")]
    Degenerate(f64, f64, f64),
    /// The winding number beside a sheet could not be found by any ray.
    #[error("the winding number beside a piece near ({0:.6e}, {1:.6e}, {2:.6e}) is undecided")]
    Undecided(f64, f64, f64),
    /// The kept sheets do not form a closed 2-manifold without crossings (sheets touching along
    /// an edge or at a point, or crossings cut too fine for floating point).
    #[error("the boundary of the winding-number domain is not a closed 2-manifold ({0})")]
    NotManifold(String),
}

/// What a point of the cut surface is, so that every triangle that has it has the same point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
enum Name {
    /// An input corner (corners are welded by coordinates).
    Corner(u32),
    /// Where the input edge between two corners (sorted) crosses a triangle.
    EdgeThrough(u32, u32, u32),
    /// Where three triangles (sorted) cross.
    Triple(u32, u32, u32),
}

impl Name {
    /// Does the point lie on the input edge between corners `a` and `b`?
    fn on_edge(self, a: u32, b: u32) -> bool {
        match self {
            Name::Corner(c) => c == a || c == b,
            Name::EdgeThrough(p, q, _) => (p, q) == (a.min(b), a.max(b)),
            Name::Triple(..) => false,
        }
    }
}

/// The points made so far and their coordinates.
#[derive(Default)]
struct Points {
    at: HashMap<Name, DVec3>,
}

impl PolyhedralOracle {
    /// The boundary of the domain `{w ≥ 1}` as a closed surface of triangles that do not cross:
    /// the surface the oracle answers for, cut where it crosses itself, less its buried and
    /// outer sheets. For a surface that bounds a volume as given, that surface itself.
    pub fn winding_boundary(&self) -> Result<WindingBoundary, ArrangementError> {
        let geometry = &self.triangles;
        let mut corners: Vec<DVec3> = geometry.iter().flatten().copied().collect();
        let mut ids: Vec<[u32; 3]> = (0..geometry.len() as u32)
            .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
            .collect();
        weld_exact(&mut corners, &mut ids);
        let pairs = crossing_pairs(&ids, geometry, &self.tree).pairs;
        let mut points = Points::default();
        let segments = segments(geometry, &ids, &corners, &pairs, &mut points)?;
        let mut pieces: Vec<([Name; 3], u32)> = Vec::new();
        let mut cut = 0;
        for (t, tri) in ids.iter().enumerate() {
            let names = tri.map(Name::Corner);
            match segments.get(&(t as u32)) {
                None => pieces.push((names, t as u32)),
                Some(list) => {
                    cut += 1;
                    for piece in cut_triangle(&geometry[t], tri, list, &points, &corners)? {
                        pieces.push((piece, t as u32));
                    }
                }
            }
        }
        self.keep_boundary_sheets(&corners, &points, pieces, cut)
    }

    /// Numbers the pieces' points, joins the pieces into sheets and keeps the sheets between
    /// `w ≥ 1` and `w ≤ 0`.
    fn keep_boundary_sheets(
        &self,
        corners: &[DVec3],
        points: &Points,
        pieces: Vec<([Name; 3], u32)>,
        cut: usize,
    ) -> Result<WindingBoundary, ArrangementError> {
        let mut index: BTreeMap<Name, u32> = BTreeMap::new();
        for (names, _) in &pieces {
            for &n in names {
                index.insert(n, 0);
            }
        }
        let mut coords = Vec::with_capacity(index.len());
        for (name, i) in index.iter_mut() {
            *i = coords.len() as u32;
            coords.push(points.get(*name, corners));
        }
        let triangles: Vec<[u32; 3]> = pieces
            .iter()
            .map(|(names, _)| names.map(|n| index[&n]))
            .collect();
        let sheet = sheets(&triangles);
        // Each sheet is decided at the centroid of its largest piece: far from the sheet's
        // rim, where rounding could put the centroid of a sliver on the wrong side of another.
        let area = |t: &[u32; 3]| {
            let [a, b, c] = t.map(|v| coords[v as usize]);
            (b - a).cross(c - a).length()
        };
        let mut largest: BTreeMap<u32, (f64, usize)> = BTreeMap::new();
        for (k, t) in triangles.iter().enumerate() {
            let entry = largest.entry(sheet[k]).or_insert((-1.0, k));
            if area(t) > entry.0 {
                *entry = (area(t), k);
            }
        }
        let mut side: HashMap<u32, Option<bool>> = HashMap::new();
        for (&s, &(_, k)) in &largest {
            let [a, b, c] = triangles[k].map(|v| coords[v as usize]);
            let x = (a + b + c) / 3.0;
            let (behind, front) = self
                .windings_across(pieces[k].1, x)
                .ok_or(ArrangementError::Undecided(x.x, x.y, x.z))?;
            let keep = match (behind >= 1, front >= 1) {
                (true, false) => Some(false),
                (false, true) => Some(true),
                _ => None,
            };
            side.insert(s, keep);
        }
        let mut out = WindingBoundary {
            cut,
            ..WindingBoundary::default()
        };
        for (k, tri) in triangles.iter().enumerate() {
            let source = pieces[k].1;
            match side[&sheet[k]] {
                Some(flip) => {
                    out.triangles
                        .push(if flip { [tri[0], tri[2], tri[1]] } else { *tri });
                    out.patches.push(self.patch[source as usize]);
                }
                None => out.dropped += 1,
            }
        }
        out.points = coords;
        // Only the points the kept triangles use, in their order.
        drop_unused_points(&mut out.points, &mut out.triangles);
        out.separated = separate_fans(
            &mut out.points,
            &mut out.triangles,
            SEPARATION * self.bbox.diagonal(),
        );
        let defects = surface_defects(&out.points, &out.triangles);
        if !defects.is_empty() || out.triangles.is_empty() {
            return Err(ArrangementError::NotManifold(describe(&defects)));
        }
        Ok(out)
    }
}

/// The segments along which each triangle is crossed, as point names in order along the
/// segment (its two ends and the triple points between them), keyed by triangle.
fn segments(
    geometry: &[[DVec3; 3]],
    ids: &[[u32; 3]],
    corners: &[DVec3],
    pairs: &[(usize, usize)],
    points: &mut Points,
) -> Result<HashMap<u32, Vec<Vec<Name>>>, ArrangementError> {
    let degenerate = |p: DVec3| ArrangementError::Degenerate(p.x, p.y, p.z);
    // The two ends of each pair's segment.
    let mut ends: BTreeMap<(u32, u32), [Name; 2]> = BTreeMap::new();
    for &(i, j) in pairs {
        let mut found = Vec::with_capacity(2);
        for (s, o) in [(i, j), (j, i)] {
            for k in 0..3 {
                let (a, b) = (ids[s][k], ids[s][(k + 1) % 3]);
                if ids[o].contains(&a) {
                    found.push(Name::Corner(a));
                }
                if ids[o].contains(&a) || ids[o].contains(&b) {
                    continue;
                }
                let (p, q) = (corners[a.min(b) as usize], corners[a.max(b) as usize]);
                match segment_crossing(p, q, &geometry[o]) {
                    Crossing::Proper { .. } => {
                        let name = Name::EdgeThrough(a.min(b), a.max(b), o as u32);
                        points
                            .at
                            .insert(name, super::crossing_point(p, q, &geometry[o]).0);
                        found.push(name);
                    }
                    Crossing::Degenerate => return Err(degenerate(p)),
                    Crossing::None | Crossing::Coplanar => {}
                }
            }
        }
        found.sort_unstable();
        found.dedup();
        match found[..] {
            [p, q] => ends.insert((i as u32, j as u32), [p, q]),
            _ => return Err(degenerate(geometry[i][0])),
        };
    }
    let mut partners: HashMap<u32, Vec<u32>> = HashMap::new();
    for &(i, j) in ends.keys() {
        partners.entry(i).or_default().push(j);
        partners.entry(j).or_default().push(i);
    }
    // Triple points: where the segment of (i, j) crosses a third triangle k crossed by both.
    let mut inner: BTreeMap<(u32, u32), Vec<Name>> = BTreeMap::new();
    for (&(i, j), &[p, q]) in &ends {
        for &k in &partners[&i] {
            if k <= j || !ends.contains_key(&(j, k)) {
                continue;
            }
            let (a, b) = (points.get(p, corners), points.get(q, corners));
            match segment_crossing(a, b, &geometry[k as usize]) {
                Crossing::Proper { .. } => {
                    let name = Name::Triple(i, j, k);
                    points
                        .at
                        .insert(name, super::crossing_point(a, b, &geometry[k as usize]).0);
                    for pair in [(i, j), (i, k), (j, k)] {
                        inner.entry(pair).or_default().push(name);
                    }
                }
                Crossing::Degenerate => return Err(degenerate(a)),
                Crossing::None | Crossing::Coplanar => {}
            }
        }
    }
    let mut by_triangle: HashMap<u32, Vec<Vec<Name>>> = HashMap::new();
    for (&(i, j), &[p, q]) in &ends {
        let (a, b) = (points.get(p, corners), points.get(q, corners));
        let mut chain = inner.remove(&(i, j)).unwrap_or_default();
        // In order along the segment.
        chain.sort_by(|x, y| {
            let along = |n: &Name| (points.get(*n, corners) - a).dot(b - a);
            along(x).total_cmp(&along(y)).then(x.cmp(y))
        });
        chain.insert(0, p);
        chain.push(q);
        for t in [i, j] {
            by_triangle.entry(t).or_default().push(chain.clone());
        }
    }
    Ok(by_triangle)
}

impl Points {
    fn get(&self, name: Name, corners: &[DVec3]) -> DVec3 {
        match name {
            Name::Corner(c) => corners[c as usize],
            other => self.at[&other],
        }
    }
}

/// The pieces of triangle `g` (corners `ids`) cut along `chains`, oriented as `g`: a constrained
/// Delaunay triangulation in the plane the triangle shows most of.
fn cut_triangle(
    g: &[DVec3; 3],
    ids: &[u32; 3],
    chains: &[Vec<Name>],
    points: &Points,
    corners: &[DVec3],
) -> Result<Vec<[Name; 3]>, ArrangementError> {
    let normal = (g[1] - g[0]).cross(g[2] - g[0]);
    let axis = normal.abs().max_position();
    let (mut u, mut v) = ((axis + 1) % 3, (axis + 2) % 3);
    if normal[axis] < 0.0 {
        std::mem::swap(&mut u, &mut v);
    }
    let at = |name: Name| points.get(name, corners);
    let flat = |p: DVec3| {
        let d = p - g[0];
        DVec2::new(d[u], d[v])
    };
    let degenerate = |p: DVec3| ArrangementError::Degenerate(p.x, p.y, p.z);
    let mut names: Vec<Name> = ids.map(Name::Corner).to_vec();
    names.extend(chains.iter().flatten().copied());
    names.sort_unstable();
    names.dedup();
    let mut cdt: ConstrainedDelaunayTriangulation<Point2<f64>> =
        ConstrainedDelaunayTriangulation::new();
    let mut handle = HashMap::new();
    let mut name_of = HashMap::new();
    for &n in &names {
        let p = at(n);
        let f = flat(p);
        let h = cdt
            .insert(Point2::new(f.x, f.y))
            .map_err(|_| degenerate(p))?;
        // Two points that fall on one place in the plane.
        if name_of.insert(h, n).is_some() {
            return Err(degenerate(p));
        }
        handle.insert(n, h);
    }
    for chain in chains {
        for w in chain.windows(2) {
            let (a, b) = (handle[&w[0]], handle[&w[1]]);
            if cdt.try_add_constraint(a, b).is_empty() && !cdt.exists_constraint(a, b) {
                return Err(degenerate(at(w[0])));
            }
        }
    }
    let edges = [(ids[0], ids[1]), (ids[1], ids[2]), (ids[2], ids[0])];
    let mut pieces = Vec::new();
    for face in cdt.inner_faces() {
        let piece = face.vertices().map(|h| name_of[&h.fix()]);
        // Rounding can leave points of one input edge off its line: the slivers between them
        // lie along the edge, outside the triangle or on its rim.
        if edges
            .iter()
            .any(|&(a, b)| piece.iter().all(|n| n.on_edge(a, b)))
        {
            continue;
        }
        pieces.push(piece);
    }
    Ok(pieces)
}

/// Sheet of each triangle: triangles joined across edges used by exactly two triangles in
/// opposite directions (an edge where sheets cross has four uses).
fn sheets(triangles: &[[u32; 3]]) -> Vec<u32> {
    let mut sets = UnionFind::new(triangles.len());
    for edge in edge_uses(triangles).chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if let [x, y] = edge
            && x.3 != y.3
        {
            sets.union(x.2, y.2);
        }
    }
    (0..triangles.len() as u32).map(|k| sets.find(k)).collect()
}

/// Gives each fan of triangles around a point its own copy of the point, where the kept sheets
/// touch (the boundary of the winding-number domain pinched at a vertex, or four triangles on one
/// edge): a fan is the triangles around the point joined through edges of two triangles used in
/// opposite directions. Every copy but the largest fan's moves towards its fan's centroid by
/// `reach` at most (a tenth of the way at most), which parts the sheets without crossing: each
/// copy moves into its own side. Returns how many points were split.
fn separate_fans(points: &mut Vec<DVec3>, triangles: &mut [[u32; 3]], reach: f64) -> usize {
    let slot = |k: u32, v: u32| {
        3 * k
            + triangles[k as usize]
                .iter()
                .position(|&x| x == v)
                .unwrap_or(0) as u32
    };
    let mut fans = UnionFind::new(3 * triangles.len());
    for edge in edge_uses(triangles).chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if let [x, y] = edge
            && x.3 != y.3
        {
            for v in [x.0, x.1] {
                fans.union(slot(x.2, v), slot(y.2, v));
            }
        }
    }
    // Per point, its fans (root slot) with their triangles, in slot order.
    let mut by_point: BTreeMap<u32, BTreeMap<u32, Vec<usize>>> = BTreeMap::new();
    for (k, t) in triangles.iter().enumerate() {
        for (i, &v) in t.iter().enumerate() {
            let root = fans.find((3 * k + i) as u32);
            by_point
                .entry(v)
                .or_default()
                .entry(root)
                .or_default()
                .push(k);
        }
    }
    let mut split = 0;
    for (v, point_fans) in by_point {
        if point_fans.len() < 2 {
            continue;
        }
        split += 1;
        let largest = point_fans
            .iter()
            .max_by_key(|(root, tris)| (tris.len(), std::cmp::Reverse(**root)))
            .map(|(root, _)| *root);
        let p = points[v as usize];
        for (root, tris) in &point_fans {
            if Some(*root) == largest {
                continue;
            }
            let centroid = tris
                .iter()
                .map(|&k| {
                    triangles[k]
                        .iter()
                        .map(|&x| points[x as usize])
                        .sum::<DVec3>()
                        / 3.0
                })
                .sum::<DVec3>()
                / tris.len() as f64;
            let step = (0.1 * p.distance(centroid)).min(reach);
            let copy = points.len() as u32;
            points.push(p + step * (centroid - p).normalize_or_zero());
            for &k in tris {
                for x in triangles[k].iter_mut() {
                    if *x == v {
                        *x = copy;
                    }
                }
            }
        }
    }
    split
}

/// Drops the points no triangle uses, keeping the others in order.
fn drop_unused_points(points: &mut Vec<DVec3>, triangles: &mut [[u32; 3]]) {
    let mut new = vec![u32::MAX; points.len()];
    let mut kept = Vec::new();
    for v in triangles.as_flattened() {
        let v = *v as usize;
        if new[v] == u32::MAX {
            new[v] = 0;
        }
    }
    for (i, p) in points.iter().enumerate() {
        if new[i] != u32::MAX {
            new[i] = kept.len() as u32;
            kept.push(*p);
        }
    }
    for v in triangles.as_flattened_mut() {
        *v = new[*v as usize];
    }
    *points = kept;
}

fn describe(d: &crate::SurfaceDefects) -> String {
    let mut parts = Vec::new();
    if d.border_edges > 0 {
        parts.push(format!("{} border edges", d.border_edges));
    }
    if d.non_manifold_edges > 0 {
        parts.push(format!(
            "{} edges in more than two triangles",
            d.non_manifold_edges
        ));
    }
    if d.inconsistent_edges > 0 {
        parts.push(format!("{} inconsistent edges", d.inconsistent_edges));
    }
    if d.first_intersection.is_some() {
        parts.push("pieces still cross".to_string());
    }
    if parts.is_empty() {
        parts.push("no triangle left".to_string());
    }
    parts.join(", ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A tetrahedron with apex `apex` over the triangle `base` (outward when `base` is clockwise
    /// seen from the apex).
    fn tetrahedron(points: &mut Vec<DVec3>, triangles: &mut Vec<[u32; 3]>, corners: [DVec3; 4]) {
        let o = points.len() as u32;
        points.extend(corners);
        triangles.extend([[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]].map(|t| t.map(|v| v + o)));
    }

    #[test]
    fn sheets_touching_at_a_point_or_an_edge_are_parted() {
        let p = DVec3::new;
        // Two tetrahedra sharing their apex (a pinch), then two sharing an edge.
        for shared in [1, 2] {
            let mut points = Vec::new();
            let mut triangles = Vec::new();
            let down = [p(0., 0., 0.), p(1., 0., 0.), p(0., 1., 0.), p(0.2, 0.2, 1.)];
            tetrahedron(&mut points, &mut triangles, down);
            let mut up = [
                p(0.2, 0.2, 1.),
                p(1.2, 0.2, 2.),
                p(0.2, 1.2, 2.),
                p(0.5, 0.5, 2.5),
            ];
            if shared == 2 {
                up = [
                    p(0.2, 0.2, 1.),
                    p(1., 0., 0.),
                    p(1.5, 1.5, 1.),
                    p(1.6, 0.2, 0.8),
                ];
            }
            tetrahedron(&mut points, &mut triangles, up);
            weld_exact(&mut points, &mut triangles);
            let before = points.len();
            let reach = 1e-3;
            let split = separate_fans(&mut points, &mut triangles, reach);
            assert_eq!(split, shared, "shared {shared}");
            assert_eq!(points.len(), before + shared);
            // Each copy stays within `reach` of the point it copies.
            for copy in &points[before..] {
                assert!(
                    points[..before]
                        .iter()
                        .any(|q| q.distance(*copy) <= reach * 1.000001)
                );
                assert!(points[..before].iter().all(|q| q != copy));
            }
            let (lower, upper) = triangles.split_at(4);
            let used = |ts: &[[u32; 3]]| ts.iter().flatten().copied().collect::<Vec<u32>>();
            assert!(used(lower).iter().all(|v| !used(upper).contains(v)));
            assert!(surface_defects(&points, &triangles).is_empty());
        }
    }
}
