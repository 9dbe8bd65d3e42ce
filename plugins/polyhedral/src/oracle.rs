//! `PolyhedralOracle`: the `Oracle` of a closed triangle surface.

mod arrangement;

use crate::occupancy::Occupancy;
use crate::predicates::{Crossing, orient, segment_crossing};
use crate::repair::{Repairs, repair};
use crate::tree::{TriangleTree, closest_point_on_triangle};
use crate::validate::{SurfaceDefects, crossed_triangles, surface_defects_in};
pub use arrangement::{ArrangementError, WindingBoundary};
use delamesh_core::mesh::{component_euler_characteristics, first_out_of_range};
use delamesh_core::oracle::{
    Aabb, OUTSIDE, Oracle, PatchId, SubdomainId, SurfaceHit, SurfacePoint,
};
use delamesh_core::union_find::UnionFind;
use glam::DVec3;
use std::sync::OnceLock;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum PolyhedralError {
    #[error("the surface has no triangles")]
    Empty,
    #[error("triangle {triangle} refers to vertex {index}, but there are only {count} vertices")]
    IndexOutOfRange {
        triangle: usize,
        index: u32,
        count: usize,
    },
    #[error("vertex {0} has a non-finite coordinate")]
    NonFinite(usize),
    #[error("{0} triangles have a repeated vertex")]
    DegenerateTriangles(usize),
    #[error("the surface is not closed: {0} edges belong to a single triangle")]
    NotClosed(usize),
    #[error("the surface is not a manifold: {0} edges belong to more than two triangles")]
    NonManifold(usize),
    #[error(
        "the surface is not consistently oriented: {0} edges are traversed twice in the same direction"
    )]
    Inconsistent(usize),
    #[error("the surface intersects itself (triangles {0} and {1} cross)")]
    SelfIntersecting(usize, usize),
    #[error("{0} patch labels given for {1} triangles")]
    PatchCount(usize, usize),
    #[error("connected component {0} encloses no volume")]
    FlatComponent(usize),
    #[error("the surface encloses no volume (no point has a positive winding number)")]
    NoVolume,
}

/// Indices in range, finite coordinates, one patch per triangle.
fn check_input(
    points: &[DVec3],
    triangles: &[[u32; 3]],
    patches: Option<&[PatchId]>,
) -> Result<(), PolyhedralError> {
    if triangles.is_empty() {
        return Err(PolyhedralError::Empty);
    }
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(PolyhedralError::NonFinite(i));
    }
    if let Some((triangle, index)) = first_out_of_range(triangles, points.len()) {
        return Err(PolyhedralError::IndexOutOfRange {
            triangle,
            index,
            count: points.len(),
        });
    }
    if let Some(p) = patches
        && p.len() != triangles.len()
    {
        return Err(PolyhedralError::PatchCount(p.len(), triangles.len()));
    }
    Ok(())
}

/// The refusal of `--strict`: the first defect that keeps the surface from bounding a volume.
pub fn refuse_defects(defects: &SurfaceDefects) -> Result<(), PolyhedralError> {
    if defects.degenerate_triangles > 0 {
        return Err(PolyhedralError::DegenerateTriangles(
            defects.degenerate_triangles,
        ));
    }
    if defects.border_edges > 0 {
        return Err(PolyhedralError::NotClosed(defects.border_edges));
    }
    if defects.non_manifold_edges > 0 {
        return Err(PolyhedralError::NonManifold(defects.non_manifold_edges));
    }
    if defects.inconsistent_edges > 0 {
        return Err(PolyhedralError::Inconsistent(defects.inconsistent_edges));
    }
    if let Some((a, b)) = defects.first_intersection {
        return Err(PolyhedralError::SelfIntersecting(a, b));
    }
    Ok(())
}

/// What [`PolyhedralOracle::new`] repairs or reinterprets in this surface (for `info`). Indices
/// must be in range. The oracle is built, so that the counts are the ones `mesh` reports; a
/// surface it refuses (no volume) gets the counts of the repairs made before the refusal.
pub fn diagnose(points: &[DVec3], triangles: &[[u32; 3]]) -> Repairs {
    if let Ok(oracle) = PolyhedralOracle::new(points, triangles, None) {
        return oracle.repairs;
    }
    let repaired = repair(points, triangles);
    let geometry = geometry_of(&repaired.points, &repaired.triangles);
    let tree = TriangleTree::new(&geometry);
    let mut repairs = repaired.repairs;
    repairs.crossing_triangles = crossed_triangles(&repaired.triangles, &geometry, &tree)
        .iter()
        .filter(|&&c| c)
        .count();
    repairs
}

fn geometry_of(points: &[DVec3], triangles: &[[u32; 3]]) -> Vec<[DVec3; 3]> {
    triangles
        .iter()
        .map(|t| t.map(|v| points[v as usize]))
        .collect()
}

/// A domain bounded by a closed, consistently oriented, non-self-intersecting triangle surface.
pub struct PolyhedralOracle {
    triangles: Vec<[DVec3; 3]>,
    /// The plane of each triangle, for a floating-point test that settles most segment tests.
    planes: Vec<Plane>,
    patch: Vec<PatchId>,
    /// Connected component of each triangle.
    component: Vec<u32>,
    tree: TriangleTree,
    /// Settles the short segment queries far from the surface without walking the tree.
    occupancy: Occupancy,
    bbox: Aabb,
    /// Number of other components around each component.
    depth: Vec<u32>,
    /// Subdomain of the region just inside each component ([`OUTSIDE`] for a hollow).
    inner_label: Vec<SubdomainId>,
    initial: Vec<SurfacePoint>,
    domain_volume: f64,
    repairs: Repairs,
    /// Set when the domain is where the winding number is at least one (see [`Repairs`]).
    winding: Option<WindingDomain>,
}

/// How [`PolyhedralOracle::with_options`] treats a surface that does not bound a volume as given.
#[derive(Clone, Debug, Default)]
pub struct PolyhedralOptions {
    /// Refuse it (with the first defect found) instead of repairing it.
    pub strict: bool,
}

/// Which triangles bound the winding-number domain `{w ≥ 1}`: those with winding number one
/// just behind them (and so zero just in front).
struct WindingDomain {
    /// Triangles crossed by another, on which the winding number behind changes from place to
    /// place: decided at each hit.
    crossed: Vec<bool>,
    /// For the other triangles, decided once.
    on_boundary: Vec<OnceLock<bool>>,
    /// Euler characteristic of each component of the domain's boundary, when it is the capped
    /// surface itself (no triangles cross, no edge is non-manifold).
    euler: Option<Vec<i64>>,
    /// Triangles from the input (the caps follow them).
    input_triangles: usize,
}

/// Directions tried in turn by the inside test until a ray misses every edge and vertex.
fn ray_direction(attempt: usize) -> DVec3 {
    // Points on a Fibonacci spiral: well spread, deterministic, and never axis-aligned.
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let k = attempt as f64 + 0.5;
    let z = 1.0 - 2.0 * (k / 97.0).fract();
    let r = (1.0 - z * z).sqrt();
    let phi = golden * k + 0.123;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

impl PolyhedralOracle {
    /// Build the oracle of whatever surface is given (see [`PolyhedralOptions`]); `patches` labels
    /// each triangle (default: one patch per component).
    pub fn new(
        points: &[DVec3],
        triangles: &[[u32; 3]],
        patches: Option<&[PatchId]>,
    ) -> Result<Self, PolyhedralError> {
        Self::with_options(points, triangles, patches, &PolyhedralOptions::default())
    }

    /// [`PolyhedralOracle::new`] with options: `strict` refuses a surface that does not bound a
    /// volume as given, else it is repaired (see [`Repairs`]).
    pub fn with_options(
        points: &[DVec3],
        triangles: &[[u32; 3]],
        patches: Option<&[PatchId]>,
        options: &PolyhedralOptions,
    ) -> Result<Self, PolyhedralError> {
        if options.strict {
            return Self::with_defects(points, triangles, patches, options)
                .map(|(oracle, _)| oracle);
        }
        check_input(points, triangles, patches)?;
        let repaired = repair(points, triangles);
        if repaired.triangles.is_empty() {
            return Err(PolyhedralError::Empty);
        }
        let mut repairs = repaired.repairs;
        let geometry = geometry_of(&repaired.points, &repaired.triangles);
        let tree = TriangleTree::new(&geometry);
        let crossed = crossed_triangles(&repaired.triangles, &geometry, &tree);
        repairs.crossing_triangles = crossed.iter().filter(|&&c| c).count();
        // Caps get a patch of their own, after the input's.
        let patches: Option<Vec<PatchId>> = patches.map(|p| {
            let cap = PatchId(p.iter().max().map_or(1, |&m| m.0 + 1));
            let of = |s: &Option<usize>| s.map_or(cap, |i| p[i]);
            repaired.source.iter().map(of).collect()
        });
        let winding = repairs.needs_winding_domain().then(|| WindingDomain {
            on_boundary: (0..crossed.len()).map(|_| OnceLock::new()).collect(),
            crossed,
            euler: (repairs.crossing_triangles == 0 && repairs.non_manifold_edges == 0)
                .then(|| component_euler_characteristics(&repaired.triangles).1),
            input_triangles: repaired.source.iter().filter(|s| s.is_some()).count(),
        });
        Self::build(
            &repaired.points,
            &repaired.triangles,
            patches.as_deref(),
            geometry,
            tree,
            repairs,
            winding,
        )
    }

    /// The oracle of the surface as given when it bounds a volume, else as
    /// [`PolyhedralOracle::with_options`] makes it (repaired, or refused with `strict`); with
    /// the defects the surface had as given. One search for self-intersections serves the
    /// check and the oracle (`--preserve-surface` keeps a clean surface's triangles as they are).
    pub fn with_defects(
        points: &[DVec3],
        triangles: &[[u32; 3]],
        patches: Option<&[PatchId]>,
        options: &PolyhedralOptions,
    ) -> Result<(Self, SurfaceDefects), PolyhedralError> {
        check_input(points, triangles, patches)?;
        let geometry = geometry_of(points, triangles);
        let tree = TriangleTree::new(&geometry);
        let defects = surface_defects_in(triangles, &geometry, &tree);
        if !defects.is_empty() {
            if options.strict {
                refuse_defects(&defects)?;
            }
            let oracle = Self::with_options(points, triangles, patches, options)?;
            return Ok((oracle, defects));
        }
        let oracle = Self::build(
            points,
            triangles,
            patches,
            geometry,
            tree,
            Repairs::default(),
            None,
        )?;
        Ok((oracle, defects))
    }

    fn build(
        points: &[DVec3],
        triangles: &[[u32; 3]],
        patches: Option<&[PatchId]>,
        geometry: Vec<[DVec3; 3]>,
        tree: TriangleTree,
        repairs: Repairs,
        winding: Option<WindingDomain>,
    ) -> Result<Self, PolyhedralError> {
        let component = components(points.len(), triangles);
        let num_components = component.iter().max().map_or(0, |&c| c as usize + 1);
        let patch = match patches {
            Some(p) => p.to_vec(),
            None => component.iter().map(|&c| PatchId(c + 1)).collect(),
        };
        let bbox = Aabb::of(&geometry.iter().flatten().copied().collect::<Vec<_>>())
            .ok_or(PolyhedralError::Empty)?;
        let occupancy = Occupancy::new(bbox.min, bbox.max, &geometry);
        let mut oracle = PolyhedralOracle {
            planes: geometry.iter().map(Plane::of).collect(),
            triangles: geometry,
            patch,
            component,
            tree,
            occupancy,
            bbox,
            depth: vec![0; num_components],
            inner_label: vec![OUTSIDE; num_components],
            initial: Vec::new(),
            domain_volume: 0.0,
            repairs,
            winding,
        };
        if oracle.winding.is_some() {
            oracle.inner_label = vec![SubdomainId(1); num_components];
            // A surface in an axis plane encloses nothing (and every line of the volume
            // integral would lie in its plane).
            if (bbox.max - bbox.min).min_element() <= 0.0 {
                return Err(PolyhedralError::NoVolume);
            }
            oracle.repairs.flipped += oracle.turn_outermost_outwards(num_components);
            oracle.domain_volume = oracle.winding_volume();
            if oracle.domain_volume <= 0.0 {
                return Err(PolyhedralError::NoVolume);
            }
        } else {
            oracle.label_components(num_components)?;
        }
        oracle.initial = oracle.sample_initial_points(num_components);
        Ok(oracle)
    }

    /// Reverses the outermost components of the closed chain that face inwards (negative signed
    /// volume), together with the components inside them, and returns the number of input
    /// triangles reversed. An inward component is a hollow only inside another one; on its own
    /// it is a surface written the other way round (an exporter's convention), whose inside
    /// would have winding number −1 and so lie outside `{w ≥ 1}`. What it encloses was written
    /// the same way, so it is reversed too (a hollow stays a hollow).
    fn turn_outermost_outwards(&mut self, n: usize) -> usize {
        let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (t, &k) in self.component.iter().enumerate() {
            members[k as usize].push(t);
        }
        // The components with a non-zero winding number around each one.
        let around: Vec<Vec<usize>> = (0..n)
            .map(|k| {
                let w = self.windings_around(k as u32, &members[k], n);
                (0..n).filter(|&j| j != k && w[j] != 0).collect()
            })
            .collect();
        let inward_root = |k: usize| {
            let Some(&first) = members[k].first() else {
                return false;
            };
            // Relative to a point of the component: far from the origin, products of absolute
            // coordinates would lose the volume of a small component.
            let o = self.triangles[first][0];
            let volume: f64 = members[k]
                .iter()
                .map(|&t| {
                    let [a, b, c] = self.triangles[t].map(|p| p - o);
                    a.dot(b.cross(c))
                })
                .sum();
            around[k].is_empty() && volume < 0.0
        };
        let reversed: Vec<bool> = (0..n).map(inward_root).collect();
        let input = self.winding.as_ref().map_or(0, |w| w.input_triangles);
        let mut flipped = 0;
        for k in 0..n {
            if reversed[k] || around[k].iter().any(|&j| reversed[j]) {
                for &t in &members[k] {
                    self.triangles[t].swap(1, 2);
                    self.planes[t] = Plane::of(&self.triangles[t]);
                }
                flipped += members[k].iter().filter(|&&t| t < input).count();
            }
        }
        flipped
    }

    /// Nesting depth and subdomain of every component, from the winding numbers of one vertex of
    /// each component with respect to all the others; and the volume of the domain.
    fn label_components(&mut self, n: usize) -> Result<(), PolyhedralError> {
        let mut volume = vec![0.0f64; n];
        let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
        for (t, tri) in self.triangles.iter().enumerate() {
            let k = self.component[t] as usize;
            volume[k] += tri[0].dot(tri[1].cross(tri[2])) / 6.0;
            members[k].push(t);
        }
        if let Some(k) = volume.iter().position(|&v| v == 0.0) {
            return Err(PolyhedralError::FlatComponent(k));
        }
        // around[k]: winding number of every component around component k.
        let around: Vec<Vec<i32>> = (0..n)
            .map(|k| self.windings_around(k as u32, &members[k], n))
            .collect();
        self.depth = around
            .iter()
            .map(|w| w.iter().filter(|&&x| x != 0).count() as u32)
            .collect();
        let mut next_label = 1;
        let mut inside_volume = vec![0.0f64; n];
        for k in 0..n {
            let own = if volume[k] > 0.0 { 1 } else { -1 };
            if own + around[k].iter().sum::<i32>() != 0 {
                self.inner_label[k] = SubdomainId(next_label);
                next_label += 1;
                inside_volume[k] += volume[k].abs();
            }
            // The region inside the parent (the innermost component around k) loses k's volume.
            let parent = (0..n)
                .filter(|&j| around[k][j] != 0)
                .max_by_key(|&j| self.depth[j]);
            if let Some(j) = parent {
                inside_volume[j] -= volume[k].abs();
            }
        }
        // The region between a component and its children is in the domain when labelled.
        self.domain_volume = (0..n)
            .filter(|&k| self.inner_label[k] != OUTSIDE)
            .map(|k| inside_volume[k])
            .sum();
        Ok(())
    }

    /// Winding numbers of the other components around component `k` (triangles `members`), probed
    /// at a point of `k`: its first vertex, or when that lies on another component (components
    /// sharing a face, see [`crate::surface_defects`]) the centroid of the first triangle of `k` that
    /// lies on no other component.
    fn windings_around(&self, k: u32, members: &[usize], n: usize) -> Vec<i32> {
        let first = members
            .first()
            .map_or(DVec3::ZERO, |&t| self.triangles[t][0]);
        let own = |t: u32| self.component[t as usize] == k;
        let (w, resolved) = self.windings(first, own, n);
        if resolved.is_some() {
            return w;
        }
        for &t in members {
            let [a, b, c] = self.triangles[t];
            let (w, resolved) = self.windings((a + b + c) / 3.0, own, n);
            if resolved.is_some() {
                return w;
            }
        }
        w
    }

    /// Winding number of each component around `p` (components numbered `0..n`), ignoring the
    /// triangles `skip` accepts (used for points lying on them), and the end of the ray that
    /// avoided every edge and vertex (`None` if none did). Exact: a ray through an edge or a vertex is replaced by another one.
    fn windings(
        &self,
        p: DVec3,
        skip: impl Fn(u32) -> bool,
        n: usize,
    ) -> (Vec<i32>, Option<DVec3>) {
        let reach = 2.0 * (self.bbox.diagonal() + p.distance(self.bbox.center())) + 1.0;
        let mut w = vec![0i32; n];
        let mut resolved = None;
        for attempt in 0..64 {
            // First towards the nearest side of the box (the shortest walk through the tree),
            // slightly tilted off the axis; then along well-spread directions.
            let q = if attempt == 0 {
                self.exit_point(p)
            } else {
                p + reach * ray_direction(attempt)
            };
            w.iter_mut().for_each(|x| *x = 0);
            let mut degenerate = false;
            self.tree.for_each_near_segment(p, q, |t| {
                let k = self.component[t as usize];
                if degenerate || skip(t) {
                    return;
                }
                match segment_crossing(p, q, &self.triangles[t as usize]) {
                    Crossing::Proper { from_back } => {
                        w[k as usize] += if from_back { 1 } else { -1 }
                    }
                    Crossing::Degenerate | Crossing::Coplanar => degenerate = true,
                    Crossing::None => {}
                }
            });
            if !degenerate {
                resolved = Some(q);
                break;
            }
        }
        (w, resolved)
    }

    /// A point just outside the bounding box, beyond its side nearest to `p`.
    fn exit_point(&self, p: DVec3) -> DVec3 {
        let (lo, hi) = (p - self.bbox.min, self.bbox.max - p);
        let near = lo.min(hi);
        let axis = near.min_position();
        let sign = if lo[axis] < hi[axis] { -1.0 } else { 1.0 };
        let margin = 1e-3 * self.bbox.diagonal() + 1e-300;
        let mut dir = DVec3::new(0.0137, 0.0291, 0.0213);
        dir[axis] = sign;
        p + (near[axis] + margin) * dir
    }

    /// Points on each component: where rays from the component's centre leave it, completed by
    /// some of its vertices when the component is far from star-shaped.
    fn sample_initial_points(&self, n: usize) -> Vec<SurfacePoint> {
        let mut centre = vec![(DVec3::ZERO, 0.0f64); n];
        for (t, tri) in self.triangles.iter().enumerate() {
            let area = 0.5 * (tri[1] - tri[0]).cross(tri[2] - tri[0]).length();
            let c = &mut centre[self.component[t] as usize];
            c.0 += area * (tri[0] + tri[1] + tri[2]) / 3.0;
            c.1 += area;
        }
        let mut out = Vec::new();
        let mut hits = Vec::new();
        for (k, &(sum, area)) in centre.iter().enumerate() {
            let origin = if area > 0.0 { sum / area } else { sum };
            for attempt in 0..24 {
                hits.clear();
                self.ray_hits_filtered(origin, ray_direction(attempt), Some(k as u32), &mut hits);
                out.extend(hits.iter().map(|h| SurfacePoint {
                    point: h.point,
                    patch: h.patch,
                }));
            }
            // Rays from the centre miss parts of non-convex components (and give nearly coplanar
            // points on flat ones): add vertices of the component spread by farthest-point sampling.
            self.spread_vertices(k as u32, 16, &mut out);
        }
        out
    }

    /// Appends `count` corners of the triangles of component `k`, each the farthest from the
    /// ones chosen before (starting from the corner of lowest index).
    fn spread_vertices(&self, k: u32, count: usize, out: &mut Vec<SurfacePoint>) {
        // Corners of triangles known to bound the domain all along (a corner of a buried
        // triangle would be no surface point).
        let whole = |t: usize| match &self.winding {
            Some(w) => !w.crossed[t] && self.bounds_domain(t as u32, self.triangles[t][0]),
            None => true,
        };
        let corners: Vec<(DVec3, PatchId)> = (0..self.triangles.len())
            .filter(|&t| self.component[t] == k && whole(t))
            .flat_map(|t| self.triangles[t].map(|p| (p, self.patch[t])))
            .collect();
        let Some(&(start, _)) = corners.first() else {
            return;
        };
        let mut nearest: Vec<f64> = corners
            .iter()
            .map(|(p, _)| p.distance_squared(start))
            .collect();
        out.push(SurfacePoint {
            point: start,
            patch: corners[0].1,
        });
        for _ in 1..count {
            let Some((i, _)) = nearest
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
            else {
                break;
            };
            let (p, patch) = corners[i];
            if nearest[i] == 0.0 {
                break;
            }
            out.push(SurfacePoint { point: p, patch });
            for (d, (q, _)) in nearest.iter_mut().zip(&corners) {
                *d = d.min(q.distance_squared(p));
            }
        }
    }

    fn ray_hits_filtered(
        &self,
        origin: DVec3,
        dir: DVec3,
        only: Option<u32>,
        out: &mut Vec<SurfaceHit>,
    ) {
        let len = dir.length();
        if len == 0.0 || !len.is_finite() || !origin.is_finite() {
            return;
        }
        let reach =
            (2.0 * (self.bbox.diagonal() + origin.distance(self.bbox.center())) + 1.0) / len;
        let start = out.len();
        self.segment_hits_filtered(origin, origin + reach * dir, only, out);
        for h in &mut out[start..] {
            h.t *= reach;
        }
    }

    fn segment_hits_filtered(
        &self,
        a: DVec3,
        b: DVec3,
        only: Option<u32>,
        out: &mut Vec<SurfaceHit>,
    ) {
        if !a.is_finite() || !b.is_finite() {
            return;
        }
        let start = out.len();
        let visit = |t: u32| {
            if only.is_some_and(|k| k != self.component[t as usize]) {
                return;
            }
            if self.planes[t as usize].strictly_one_side(a, b) {
                return;
            }
            let tri = &self.triangles[t as usize];
            if let Crossing::Proper { .. } | Crossing::Degenerate = segment_crossing(a, b, tri) {
                let (point, s) = crossing_point(a, b, tri);
                if !self.bounds_domain(t, point) {
                    return;
                }
                out.push(SurfaceHit {
                    point,
                    t: s,
                    patch: self.patch[t as usize],
                });
            }
        };
        self.occupancy
            .for_each_near_segment(&self.tree, a, b, visit);
        let hits = &mut out[start..];
        hits.sort_by(|x, y| x.t.total_cmp(&y.t).then(x.patch.cmp(&y.patch)));
        // A segment through an edge or a vertex meets several triangles at one point.
        let mut kept = start;
        for i in start..out.len() {
            if kept == start || (out[i].t - out[kept - 1].t).abs() > 1e-12 {
                out[kept] = out[i];
                kept += 1;
            }
        }
        out.truncate(kept);
    }

    /// Does triangle `t` bound the domain at its point `x`? Always for a surface that bounds a
    /// volume as given; for the winding-number domain, where the winding number is at least one
    /// just behind `t` and at most zero just in front: a triangle buried in the volume, or in an
    /// inverted region, is not part of its boundary, and of two overlapping coplanar triangles
    /// facing the same way (two solids sharing a face, both outward) both are.
    fn bounds_domain(&self, t: u32, x: DVec3) -> bool {
        let Some(w) = &self.winding else {
            return true;
        };
        let bounds = |x: DVec3| {
            self.windings_across(t, x)
                .is_none_or(|(behind, front)| behind >= 1 && front <= 0)
        };
        if w.crossed[t as usize] {
            return bounds(x);
        }
        *w.on_boundary[t as usize].get_or_init(|| {
            let [a, b, c] = self.triangles[t as usize];
            bounds((a + b + c) / 3.0)
        })
    }

    /// The winding numbers just behind and just in front of triangle `t` at its point `x`. Where
    /// no other triangle lies in `t`'s plane at `x`, from one ray from `x` that ignores `t` (the
    /// two differ by one); otherwise, or when every ray from `x` starts on a neighbour (`x` on an
    /// edge or a vertex of `t`), from points a hair behind and in front (`None` if that fails).
    fn windings_across(&self, t: u32, x: DVec3) -> Option<(i32, i32)> {
        let n = self.depth.len();
        let [a, b, c] = self.triangles[t as usize];
        let hair = 1e-9 * self.bbox.diagonal();
        if !self.coplanar_neighbour_at(t, x, hair) {
            let (w, end) = self.windings(x, |s| s == t, n);
            let total: i32 = w.iter().sum();
            // Leaving through the front, the ray counted the winding number in front.
            match end.map(|q| orient(a, b, c, q)) {
                Some(std::cmp::Ordering::Less) => return Some((total + 1, total)),
                Some(std::cmp::Ordering::Greater) => return Some((total, total - 1)),
                _ => {}
            }
        }
        let normal = (b - a).cross(c - a).normalize_or_zero();
        let at = |p: DVec3| {
            let (w, end) = self.windings(p, |_| false, n);
            end.map(|_| w.iter().sum::<i32>())
        };
        Some((at(x - hair * normal)?, at(x + hair * normal)?))
    }

    /// Is there, besides `t`, a triangle in `t`'s plane (exactly) within `tolerance` of `x`?
    fn coplanar_neighbour_at(&self, t: u32, x: DVec3, tolerance: f64) -> bool {
        let tri = self.triangles[t as usize];
        let mut found = false;
        self.tree
            .for_each_near_box(x - tolerance, x + tolerance, |s| {
                let other = &self.triangles[s as usize];
                found = found
                    || (s != t
                        && other.iter().all(|&p| {
                            orient(tri[0], tri[1], tri[2], p) == std::cmp::Ordering::Equal
                        })
                        && closest_point_on_triangle(x, other).distance(x) <= tolerance);
            });
        found
    }

    /// Volume of `{w ≥ 1}`: the exact length inside along each of a grid of lines parallel to
    /// the z axis (from the signed crossings, walked in order), integrated by the midpoint rule.
    fn winding_volume(&self) -> f64 {
        const LINES: usize = 128;
        let size = self.bbox.max - self.bbox.min;
        let (dx, dy) = (size.x / LINES as f64, size.y / LINES as f64);
        let (z0, z1) = (
            self.bbox.min.z - 0.01 * size.z - 1.0,
            self.bbox.max.z + 0.01 * size.z + 1.0,
        );
        let mut crossings: Vec<(f64, i32)> = Vec::new();
        let mut volume = 0.0;
        for i in 0..LINES {
            for j in 0..LINES {
                // A line through an edge or a vertex is moved a little (deterministically).
                for attempt in 0..8 {
                    // Unequal shifts, or a line on a diagonal would stay on it.
                    let x = self.bbox.min.x + (i as f64 + 0.5 + 0.0731 * attempt as f64) * dx;
                    let y = self.bbox.min.y + (j as f64 + 0.5 + 0.0419 * attempt as f64) * dy;
                    let (p, q) = (DVec3::new(x, y, z0), DVec3::new(x, y, z1));
                    crossings.clear();
                    let mut degenerate = false;
                    self.tree.for_each_near_segment(p, q, |t| {
                        let tri = &self.triangles[t as usize];
                        match segment_crossing(p, q, tri) {
                            Crossing::Proper { from_back } => {
                                let z = crossing_point(p, q, tri).0.z;
                                crossings.push((z, if from_back { -1 } else { 1 }));
                            }
                            Crossing::Degenerate | Crossing::Coplanar => degenerate = true,
                            Crossing::None => {}
                        }
                    });
                    if degenerate {
                        continue;
                    }
                    crossings.sort_by(|a, b| a.0.total_cmp(&b.0));
                    let (mut w, mut length, mut entered) = (0, 0.0, 0.0);
                    for &(z, step) in &crossings {
                        let was_inside = w >= 1;
                        w += step;
                        match (was_inside, w >= 1) {
                            (false, true) => entered = z,
                            (true, false) => length += z - entered,
                            _ => {}
                        }
                    }
                    volume += length * dx * dy;
                    break;
                }
            }
        }
        volume
    }

    /// The subdomain of `p` from the winding numbers of the components around it.
    fn subdomain_by_windings(&self, p: DVec3) -> SubdomainId {
        let (w, _) = self.windings(p, |_| false, self.depth.len());
        if self.winding.is_some() {
            return if w.iter().sum::<i32>() >= 1 {
                SubdomainId(1)
            } else {
                OUTSIDE
            };
        }
        w.iter()
            .enumerate()
            .filter(|&(_, &x)| x != 0)
            .max_by_key(|&(k, _)| self.depth[k])
            .map_or(OUTSIDE, |(k, _)| self.inner_label[k])
    }

    /// Distance from `p` to the surface, for approximation measurements.
    pub fn distance_to_surface(&self, p: DVec3) -> f64 {
        self.tree.distance(p, &self.triangles)
    }

    /// Volume of the domain (the union of the subdomains).
    pub fn domain_volume(&self) -> f64 {
        self.domain_volume
    }

    /// The input triangles, as points.
    pub fn triangles(&self) -> &[[DVec3; 3]] {
        &self.triangles
    }

    /// What was repaired or reinterpreted in the input surface.
    pub fn repairs(&self) -> &Repairs {
        &self.repairs
    }

    /// For a domain read by its winding number (see [`Repairs::needs_winding_domain`]), whose
    /// boundary is not the input surface: the Euler characteristic of each component of the
    /// boundary when it is the surface with its holes capped, `None` when triangles cross or an
    /// edge is non-manifold (the boundary's topology is then only known by meshing it). `None`
    /// for a surface that bounds a volume as given, which is its own boundary.
    pub fn winding_boundary_euler_characteristics(&self) -> Option<&[i64]> {
        self.winding.as_ref()?.euler.as_deref()
    }

    /// Number of subdomains (regions with a non-zero winding number; one when the domain is
    /// defined by the total winding number).
    pub fn num_subdomains(&self) -> usize {
        if self.winding.is_some() {
            return 1;
        }
        self.inner_label.iter().filter(|&&l| l != OUTSIDE).count()
    }
}

impl Oracle for PolyhedralOracle {
    fn bounding_box(&self) -> Aabb {
        self.bbox
    }

    fn subdomain(&self, p: DVec3) -> SubdomainId {
        let windings = |x| self.subdomain_by_windings(x);
        self.occupancy.subdomain(p, windings, windings)
    }

    fn segment_hits(&self, a: DVec3, b: DVec3, out: &mut Vec<SurfaceHit>) {
        self.segment_hits_filtered(a, b, None, out);
    }

    fn ray_hits(&self, origin: DVec3, dir: DVec3, out: &mut Vec<SurfaceHit>) {
        self.ray_hits_filtered(origin, dir, None, out);
    }

    fn initial_points(&self) -> Vec<SurfacePoint> {
        self.initial.clone()
    }
}

/// A triangle's plane with an error bound, so that a floating-point side test is trusted only
/// when its sign cannot be an artefact of rounding; the exact predicates decide the rest.
#[derive(Clone, Copy, Debug)]
struct Plane {
    origin: DVec3,
    normal: DVec3,
    /// Bound on the rounding error of `normal · (p − origin)`, per unit of `|p − origin|∞`.
    error: f64,
}

impl Plane {
    fn of(t: &[DVec3; 3]) -> Self {
        let (u, v) = (t[1] - t[0], t[2] - t[0]);
        // The determinant's rounding error is a few ulps of |u|·|v|·|p − origin|; 1e-12 leaves
        // a margin of three orders of magnitude, and √3 covers the max-norm of `p − origin`.
        let error = 1e-12 * 3f64.sqrt() * u.length() * v.length();
        Plane {
            origin: t[0],
            normal: u.cross(v),
            error,
        }
    }

    /// Are `a` and `b` both certainly on the same side of the plane, off it?
    fn strictly_one_side(&self, a: DVec3, b: DVec3) -> bool {
        let side = |p: DVec3| {
            let d = p - self.origin;
            let h = self.normal.dot(d);
            let bound = self.error * d.abs().max_element();
            if h > bound {
                1
            } else if h < -bound {
                -1
            } else {
                0
            }
        };
        let sa = side(a);
        sa != 0 && sa == side(b)
    }
}

/// Where segment `[a, b]`, known to meet triangle `tri`, crosses its plane: the point and its
/// parameter along `a → b`.
///
/// The point is interpolated from the endpoint nearer to the plane: the circumcentre of a nearly
/// flat cell can be 10¹⁵ away, and interpolating from it would lose every significant digit.
fn crossing_point(a: DVec3, b: DVec3, tri: &[DVec3; 3]) -> (DVec3, f64) {
    let normal = (tri[1] - tri[0]).cross(tri[2] - tri[0]);
    let (ha, hb) = (normal.dot(a - tri[0]), normal.dot(b - tri[0]));
    let denom = ha - hb;
    if denom == 0.0 || !denom.is_finite() {
        return if ha.abs() <= hb.abs() {
            (a, 0.0)
        } else {
            (b, 1.0)
        };
    }
    if ha.abs() <= hb.abs() {
        let s = (ha / denom).clamp(0.0, 1.0);
        (a + s * (b - a), s)
    } else {
        let s = (hb / -denom).clamp(0.0, 1.0);
        (b + s * (a - b), 1.0 - s)
    }
}

/// Connected components of triangles sharing an edge, numbered in order of their first triangle.
fn components(num_points: usize, triangles: &[[u32; 3]]) -> Vec<u32> {
    // Union-find over vertices: in a closed edge-manifold surface, triangles sharing a vertex
    // but no edge could join two components only at a pinched vertex, which the checks allow.
    let mut sets = UnionFind::new(num_points);
    for t in triangles {
        for k in 0..3 {
            sets.union(t[k], t[(k + 1) % 3]);
        }
    }
    let mut label = vec![u32::MAX; num_points];
    let mut next = 0;
    triangles
        .iter()
        .map(|t| {
            let root = sets.find(t[0]) as usize;
            if label[root] == u32::MAX {
                label[root] = next;
                next += 1;
            }
            label[root]
        })
        .collect()
}
