//! Sliver removal on the tetrahedra of a finished mesh, worst cell first: edge removal (which
//! includes the 3-2 and 4-4 flips), 2-3 flips, moves of interior vertices and, for the slivers
//! none of those mends, a new vertex on an interior edge; each change kept only when it raises
//! the smallest dihedral sine of the cells it replaces.
//!
//! No vertex move or weight removes a flat cell whose four vertices lie on the boundary, such as
//! one spanning two nearly coplanar boundary facets: its circumball is the diametral ball of
//! those facets, so no point can be inserted into it without encroaching on them, and its
//! vertices are the input's. Replacing the cells around one of its interior edges, or across
//! one of its interior faces, does remove it. The result is no longer a regular triangulation,
//! so this runs last, on the complex itself. Boundary facets (and every edge on one) are never
//! touched, so the surface and the subdomains stay exactly as they are.
//!
//! Each change is validated with exact orientation tests: the new cells fill the region of the
//! old ones with positive volume.

use super::state::size_excess;
use crate::complex::{MeshComplex, VertexDimension};
use crate::kernel::{Point3, Sign, orient3d};
use crate::oracle::SubdomainId;
use crate::quality::tet_volume;
use crate::refine::Deadline;
use crate::refine::criteria::Sizing;
use rustc_hash::FxHashSet;

/// The largest ring of cells around an edge that edge removal re-triangulates: the search over
/// the ring's triangulations grows as its cube, and larger rings seldom give a better one.
const MAX_RING: usize = 7;

/// The largest ring of cells around an edge that a split may replace.
const MAX_SPLIT_RING: usize = 16;

/// Only cells with a smallest dihedral angle below this (degrees) get a new vertex: the slivers
/// proper (see [`super::SLIVER_DEG`]); above it a split costs a vertex for a small gain.
const SPLIT_BELOW: f64 = super::SLIVER_DEG;

/// Vertices a run may insert: this many, plus one per hundred mesh vertices.
const MAX_INSERTIONS_BASE: usize = 64;

/// Vertices with more cells than this are not moved: a search over their star costs more than
/// the few slivers it may mend.
const MAX_MOVED_STAR: usize = 96;

/// Steps of the pattern search that places a moved or inserted vertex.
const MAX_SEARCH_STEPS: usize = 24;

/// Passes over the cells below the bound at most (a pass stops early once nothing improves).
const MAX_PASSES: usize = 8;

/// A change is kept when it raises the smallest [`quality`] of the cells it replaces by more
/// than this: quality is computed in floating point, and a change that gains less than
/// rounding could undo another in the next pass.
const MIN_GAIN: f64 = 1e-8;

/// No change creates a cell below this quality (the sine of 0.001°, the angle below which the
/// optimisers call a cell flat): replacing a flat cell by several nearly flat ones raises the
/// smallest quality but leaves more cells a mesh user cannot use.
const FLAT: f64 = 1.75e-5;

/// A cell below this fraction of the largest cell's volume is flat for [`Cells::measure`]: a
/// hundred times the fraction (1e-14) below which mesh checkers call a cell flat.
const TINY: f64 = 1e-12;

/// Whether created cells of smallest quality `new` may replace cells of smallest quality `old`.
fn gains(new: f64, old: f64) -> bool {
    new > old + MIN_GAIN && new > FLAT
}

/// Orientation of the output's positive cells (the opposite of Shewchuk's sign; see
/// [`crate::complex::signed_volume`]).
const POSITIVE: Sign = Sign::Negative;

/// The quality a change must raise: the smallest sine of the six dihedral angles; 0 when the
/// cell (of signed volume `volume`, which the caller has) is flat or inverted. It is the sine
/// of the smallest dihedral angle unless an obtuse one is closer to 180°, and unlike an angle
/// computed from face normals it stays small for a cell whose vertices are coplanar to within
/// rounding, whose orientation may still be exactly positive (the sine is three times the
/// volume times the edge length over twice the product of the two face areas).
fn quality(p: &[Point3; 4], volume: f64) -> f64 {
    if volume.is_nan() || volume <= 0.0 {
        return 0.0;
    }
    // Squared, so that one square root serves the six sines: twice each face's area, squared,
    // and the edges opposite as pairs (i, j) with their two faces (k, l).
    const OTHERS: [[usize; 3]; 4] = [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]];
    const EDGES: [[usize; 4]; 6] = [
        [0, 1, 2, 3],
        [0, 2, 1, 3],
        [0, 3, 1, 2],
        [1, 2, 0, 3],
        [1, 3, 0, 2],
        [2, 3, 0, 1],
    ];
    let area2 = OTHERS.map(|[a, b, c]| (p[b] - p[a]).cross(p[c] - p[a]).length_squared());
    // sine = 1.5 V |e| / (A_k A_l) = 6 V |e| / (2A_k 2A_l).
    let six_v2 = 36.0 * volume * volume;
    let mut sine2 = 1.0f64;
    for [i, j, k, l] in EDGES {
        sine2 = sine2.min(six_v2 * p[i].distance_squared(p[j]) / (area2[k] * area2[l]));
    }
    sine2.max(0.0).sqrt()
}

/// A change found for a cell: the cells it removes, the cells it creates (positively
/// oriented) and the smallest [`quality`] among them.
struct Plan {
    removed: Vec<u32>,
    created: Vec<[u32; 4]>,
    quality: f64,
    vertex: Vertex,
}

/// What a change does to the vertices.
enum Vertex {
    /// Nothing: a flip.
    Keep,
    /// Moves one to a new position.
    Move(u32, Point3),
    /// Inserts one at this position; the created cells name it [`NEW`].
    Insert(Point3),
}

/// The vertex a split inserts, in the cells it plans.
const NEW: u32 = u32::MAX;

/// The cells of a complex under change: dead slots are kept (by `alive`) so indices stay
/// valid during a pass, and are dropped at the end.
struct Cells {
    points: Vec<Point3>,
    /// Whether each vertex may move (an interior vertex; those on the boundary are the
    /// surface's).
    movable: Vec<bool>,
    /// Vertices that may still be inserted (splits are bounded, though each raises the
    /// smallest angle of the cells it replaces).
    insertions_left: usize,
    tets: Vec<[u32; 4]>,
    subdomain: Vec<SubdomainId>,
    /// [`quality`] of each cell slot.
    quality: Vec<f64>,
    alive: Vec<bool>,
    /// The live cells around each vertex.
    around: Vec<Vec<u32>>,
    /// Changes around each vertex so far, and for each cell the sum of its vertices' counts
    /// when no change was found for it: a cell is tried again only once something around it
    /// changed.
    version: Vec<u64>,
    stuck_at: Vec<Option<u64>>,
    /// For each vertex, its count when a search for a better position last failed.
    unmovable_at: Vec<Option<u64>>,
    /// Cells of this volume or less count as [`FLAT`] whatever their angles: checkers call a
    /// cell flat below a fraction of the largest cell's volume (the mesh's scale), and a
    /// change must not make one.
    tiny: f64,
    /// Boundary facets (sorted vertices) and their edges: never removed.
    fixed_faces: FxHashSet<[u32; 3]>,
    fixed_edges: FxHashSet<[u32; 2]>,
    /// The cell-size criterion, which no change may break further (see [`Cells::sizes_kept`]).
    cell_size: Sizing,
}

fn sorted3(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

fn sorted2(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

impl Cells {
    fn new(complex: &MeshComplex, cell_size: &Sizing) -> Self {
        let mut cells = Cells {
            points: complex.points.clone(),
            movable: complex
                .vertex_dimension
                .iter()
                .map(|&d| d == VertexDimension::Volume)
                .collect(),
            insertions_left: MAX_INSERTIONS_BASE + complex.points.len() / 100,
            tets: Vec::with_capacity(complex.tets.len()),
            subdomain: Vec::with_capacity(complex.tets.len()),
            quality: Vec::with_capacity(complex.tets.len()),
            alive: Vec::with_capacity(complex.tets.len()),
            around: vec![Vec::new(); complex.points.len()],
            version: vec![0; complex.points.len()],
            unmovable_at: vec![None; complex.points.len()],
            stuck_at: Vec::with_capacity(complex.tets.len()),
            tiny: TINY
                * (0..complex.tets.len())
                    .map(|t| tet_volume(&complex.tet_points(t)))
                    .fold(0.0, f64::max),
            fixed_faces: complex.facets.iter().map(|&f| sorted3(f)).collect(),
            fixed_edges: complex
                .facets
                .iter()
                .flat_map(|f| {
                    [
                        sorted2(f[0], f[1]),
                        sorted2(f[1], f[2]),
                        sorted2(f[2], f[0]),
                    ]
                })
                .collect(),
            cell_size: cell_size.clone(),
        };
        for (&t, &sub) in complex.tets.iter().zip(&complex.tet_subdomain) {
            cells.add(t, sub);
        }
        cells
    }

    /// Whether no cell `plan` creates is larger, for the cell-size criterion, than that allows
    /// or than the largest cell it removes (the rule of the workspace's moves): a flip can
    /// join small cells into one whose circumball is far larger.
    fn sizes_kept(&self, plan: &Plan) -> bool {
        let sub = self.subdomain[plan.removed[0] as usize];
        let bound = plan
            .removed
            .iter()
            .map(|&c| size_excess(&self.cell_size, &self.pts(self.tets[c as usize]), sub))
            .fold(1.0, f64::max);
        plan.created.iter().all(|&c| {
            let p = match plan.vertex {
                Vertex::Keep => self.pts(c),
                Vertex::Move(v, at) => self.pts_with(c, v, at),
                Vertex::Insert(at) => self.pts_with(c, NEW, at),
            };
            size_excess(&self.cell_size, &p, sub) <= bound
        })
    }

    /// [`quality`], and 0 for a cell of [`Cells::tiny`] volume.
    fn measure(&self, p: &[Point3; 4]) -> f64 {
        let volume = tet_volume(p);
        if volume <= self.tiny {
            0.0
        } else {
            quality(p, volume)
        }
    }

    fn pts(&self, t: [u32; 4]) -> [Point3; 4] {
        t.map(|v| self.points[v as usize])
    }

    /// The points of `t` with vertex `v` (possibly [`NEW`]) at `at`.
    fn pts_with(&self, t: [u32; 4], v: u32, at: Point3) -> [Point3; 4] {
        t.map(|u| if u == v { at } else { self.points[u as usize] })
    }

    /// The smallest quality of the cells of `star` with `v` at `at`, if it is above `floor`
    /// and every cell is positive (exactly). Stops at the first cell at or below the floor,
    /// which is most of the tries of a search, and moves that cell to the front of `star`,
    /// where the next try meets it first.
    fn star_quality(&self, star: &mut [[u32; 4]], v: u32, at: Point3, floor: f64) -> Option<f64> {
        let mut worst = f64::INFINITY;
        for i in 0..star.len() {
            let q = self.measure(&self.pts_with(star[i], v, at));
            if q <= floor {
                star.swap(0, i);
                return None;
            }
            worst = worst.min(q);
        }
        star.iter()
            .all(|&t| {
                let p = self.pts_with(t, v, at);
                orient3d(p[0], p[1], p[2], p[3]) == POSITIVE
            })
            .then_some(worst)
    }

    /// A position of `v` near `start` that raises the smallest quality of `star`, by pattern
    /// search: steps along the axes and towards the centroid of the star's other vertices,
    /// halving the step when none helps.
    fn best_position(&self, star: &mut [[u32; 4]], v: u32, start: Point3) -> (Point3, f64) {
        let others: Vec<Point3> = star
            .iter()
            .flat_map(|t| t.iter().copied().filter(|&u| u != v))
            .map(|u| self.points[u as usize])
            .collect();
        let centroid = others.iter().fold(Point3::ZERO, |a, &b| a + b) / others.len().max(1) as f64;
        let shortest = others
            .iter()
            .map(|q| q.distance(start))
            .fold(f64::INFINITY, f64::min);
        let (mut at, mut q) = (start, self.star_quality(star, v, start, 0.0).unwrap_or(0.0));
        let mut step = 0.25 * shortest;
        let finest = step * 1e-2;
        for _ in 0..MAX_SEARCH_STEPS {
            if step.is_nan() || step <= finest {
                break;
            }
            let inward = (centroid - at).normalize_or_zero();
            let moved = [
                inward,
                Point3::X,
                -Point3::X,
                Point3::Y,
                -Point3::Y,
                Point3::Z,
                -Point3::Z,
            ]
            .into_iter()
            .map(|d| at + d * step)
            .find_map(|c| Some((c, self.star_quality(star, v, c, q + MIN_GAIN)?)));
            match moved {
                Some((c, qc)) => (at, q) = (c, qc),
                None => step *= 0.5,
            }
        }
        (at, q)
    }

    /// Moves interior vertex `v` to raise the smallest quality of its cells.
    fn relocate(&self, v: u32) -> Option<Plan> {
        if !self.movable[v as usize] {
            return None;
        }
        if self.around[v as usize].len() > MAX_MOVED_STAR {
            return None;
        }
        let ids = self.around[v as usize].clone();
        let mut star: Vec<[u32; 4]> = ids.iter().map(|&c| self.tets[c as usize]).collect();
        let old = ids
            .iter()
            .map(|&c| self.quality[c as usize])
            .fold(f64::INFINITY, f64::min);
        let (at, q) = self.best_position(&mut star, v, self.points[v as usize]);
        gains(q, old).then_some(Plan {
            removed: ids,
            created: star,
            quality: q,
            vertex: Vertex::Move(v, at),
        })
    }

    /// Splits interior edge `(a, b)` by a new vertex, placed where it best serves the cells
    /// around the edge, each of which it splits in two.
    fn split_edge(&self, a: u32, b: u32) -> Option<Plan> {
        if self.insertions_left == 0 || self.fixed_edges.contains(&sorted2(a, b)) {
            return None;
        }
        let (ids, ring) = self.ring(a, b, MAX_SPLIT_RING)?;
        let mut star: Vec<[u32; 4]> = ids
            .iter()
            .flat_map(|&c| {
                let t = self.tets[c as usize];
                [a, b].map(|end| t.map(|u| if u == end { NEW } else { u }))
            })
            .collect();
        let (pa, pb) = (self.points[a as usize], self.points[b as usize]);
        let around = ring
            .iter()
            .fold(pa + pb, |s, &u| s + self.points[u as usize]);
        let starts = [around / (ring.len() + 2) as f64, (pa + pb) / 2.0];
        let start = starts
            .into_iter()
            .filter_map(|p| Some((p, self.star_quality(&mut star, NEW, p, 0.0)?)))
            .max_by(|x, y| x.1.total_cmp(&y.1))?
            .0;
        let old = ids
            .iter()
            .map(|&c| self.quality[c as usize])
            .fold(f64::INFINITY, f64::min);
        let (at, q) = self.best_position(&mut star, NEW, start);
        gains(q, old).then_some(Plan {
            removed: ids,
            created: star,
            quality: q,
            vertex: Vertex::Insert(at),
        })
    }

    /// The cells around interior edge `(a, b)` and the other vertices of the edge's ring in
    /// order around it, when the ring is closed, simple and of at most `max` cells.
    fn ring(&self, a: u32, b: u32, max: usize) -> Option<(Vec<u32>, Vec<u32>)> {
        // The cells around the end with fewer (a vertex may have thousands).
        let fewer = if self.around[a as usize].len() <= self.around[b as usize].len() {
            (a, b)
        } else {
            (b, a)
        };
        let ring_cells: Vec<u32> = self.around[fewer.0 as usize]
            .iter()
            .copied()
            .filter(|&c| self.tets[c as usize].contains(&fewer.1))
            .collect();
        let n = ring_cells.len();
        if !(3..=max).contains(&n) {
            return None;
        }
        // Each cell gives a ring edge (its two other vertices); chain them into the polygon.
        let edges: Vec<[u32; 2]> = ring_cells
            .iter()
            .map(|&c| {
                let mut o = self.tets[c as usize]
                    .iter()
                    .copied()
                    .filter(|&v| v != a && v != b);
                [o.next().unwrap_or(a), o.next().unwrap_or(a)]
            })
            .collect();
        let mut ring = vec![edges[0][0], edges[0][1]];
        let mut used = vec![false; n];
        used[0] = true;
        while ring.len() < n {
            let last = ring[ring.len() - 1];
            let next = (0..n).find(|&i| !used[i] && edges[i].contains(&last))?;
            used[next] = true;
            let e = edges[next];
            ring.push(if e[0] == last { e[1] } else { e[0] });
        }
        let mut distinct = ring.clone();
        distinct.sort_unstable();
        distinct.dedup();
        if distinct.len() != n {
            return None;
        }
        // The polygon must close with the one edge left.
        let last = (0..n).find(|&i| !used[i])?;
        if sorted2(edges[last][0], edges[last][1]) != sorted2(ring[0], ring[n - 1]) {
            return None;
        }
        Some((ring_cells, ring))
    }

    fn add(&mut self, t: [u32; 4], sub: SubdomainId) {
        let id = self.tets.len() as u32;
        self.quality.push(self.measure(&self.pts(t)));
        self.tets.push(t);
        self.subdomain.push(sub);
        self.alive.push(true);
        self.stuck_at.push(None);
        for v in t {
            self.around[v as usize].push(id);
            self.version[v as usize] += 1;
        }
    }

    fn kill(&mut self, id: u32) {
        self.alive[id as usize] = false;
        for v in self.tets[id as usize] {
            self.around[v as usize].retain(|&c| c != id);
            self.version[v as usize] += 1;
        }
    }

    /// The cell `created` oriented positively, if its vertices are not coplanar (exactly).
    fn oriented(&self, mut t: [u32; 4]) -> Option<[u32; 4]> {
        let p = self.pts(t);
        match orient3d(p[0], p[1], p[2], p[3]) {
            Sign::Zero => None,
            s if s == POSITIVE => Some(t),
            _ => {
                t.swap(0, 1);
                Some(t)
            }
        }
    }

    fn orient(&self, a: u32, b: u32, c: u32, d: u32) -> Sign {
        let p = |v: u32| self.points[v as usize];
        orient3d(p(a), p(b), p(c), p(d))
    }

    /// Removes interior edge `(a, b)`: its ring of cells is replaced by the best triangulation
    /// of the ring polygon, each triangle joined to `a` and to `b`.
    fn remove_edge(&self, a: u32, b: u32) -> Option<Plan> {
        if self.fixed_edges.contains(&sorted2(a, b)) {
            return None;
        }
        let (ring_cells, ring) = self.ring(a, b, MAX_RING)?;
        let n = ring.len();
        // Every cell of the ring turns the same way around the edge.
        let s = self.orient(a, b, ring[0], ring[1]);
        if s == Sign::Zero || (1..n).any(|i| self.orient(a, b, ring[i], ring[(i + 1) % n]) != s) {
            return None;
        }
        let old = ring_cells
            .iter()
            .map(|&c| self.quality[c as usize])
            .fold(f64::INFINITY, f64::min);
        // Triangle (i, j, k) of the polygon, i < j < k, gives the cells (a, i, j, k) and
        // (b, i, j, k), which must turn like the ring's for a and the other way for b.
        let pair = |i: usize, j: usize, k: usize| -> f64 {
            let (ri, rj, rk) = (ring[i], ring[j], ring[k]);
            if self.orient(a, ri, rj, rk) != s || self.orient(b, ri, rj, rk) != s.flip() {
                return -1.0;
            }
            let qa = self.measure(&self.pts(self.oriented([a, ri, rj, rk]).unwrap_or([a; 4])));
            let qb = self.measure(&self.pts(self.oriented([b, ri, rj, rk]).unwrap_or([b; 4])));
            qa.min(qb)
        };
        // best[i][j]: the best smallest quality over triangulations of the sub-polygon i..=j.
        let mut best = [[f64::INFINITY; MAX_RING]; MAX_RING];
        let mut split = [[0usize; MAX_RING]; MAX_RING];
        for len in 2..n {
            for i in 0..n - len {
                let j = i + len;
                best[i][j] = -1.0;
                for k in i + 1..j {
                    let q = pair(i, k, j).min(best[i][k]).min(best[k][j]);
                    if q > best[i][j] {
                        best[i][j] = q;
                        split[i][j] = k;
                    }
                }
            }
        }
        if !gains(best[0][n - 1], old) {
            return None;
        }
        let mut created = Vec::with_capacity(2 * (n - 2));
        let mut stack = vec![(0, n - 1)];
        while let Some((i, j)) = stack.pop() {
            if j < i + 2 {
                continue;
            }
            let k = split[i][j];
            for apex in [a, b] {
                created.push(self.oriented([apex, ring[i], ring[k], ring[j]])?);
            }
            stack.push((i, k));
            stack.push((k, j));
        }
        Some(Plan {
            removed: ring_cells,
            created,
            quality: best[0][n - 1],
            vertex: Vertex::Keep,
        })
    }

    /// The 2-3 flip across the face of cell `t` opposite its vertex `k`: the two cells
    /// sharing the face become three around the segment joining their apices.
    fn flip23(&self, t: u32, k: usize) -> Option<Plan> {
        let cell = self.tets[t as usize];
        let p = cell[k];
        let face: Vec<u32> = (0..4).filter(|&i| i != k).map(|i| cell[i]).collect();
        let [x, y, z] = [face[0], face[1], face[2]];
        if self.fixed_faces.contains(&sorted3([x, y, z])) {
            return None;
        }
        let fewest = [x, y, z]
            .into_iter()
            .min_by_key(|&v| self.around[v as usize].len())
            .unwrap_or(x);
        let u = self.around[fewest as usize].iter().copied().find(|&c| {
            c != t && {
                let o = self.tets[c as usize];
                o.contains(&x) && o.contains(&y) && o.contains(&z)
            }
        })?;
        let q = self.tets[u as usize]
            .into_iter()
            .find(|v| ![x, y, z].contains(v))?;
        // Segment pq crosses the face's interior exactly when the three new cells turn alike.
        let s = self.orient(p, q, x, y);
        if s == Sign::Zero || self.orient(p, q, y, z) != s || self.orient(p, q, z, x) != s {
            return None;
        }
        let old = self.quality[t as usize].min(self.quality[u as usize]);
        let created =
            [[p, q, x, y], [p, q, y, z], [p, q, z, x]].map(|c| self.oriented(c).unwrap_or(c));
        let q = created
            .iter()
            .map(|&c| self.measure(&self.pts(c)))
            .fold(f64::INFINITY, f64::min);
        gains(q, old).then(|| Plan {
            removed: vec![t, u],
            created: created.to_vec(),
            quality: q,
            vertex: Vertex::Keep,
        })
    }

    /// The best change that removes cell `t`, if one raises the smallest quality; a flip
    /// that lifts every cell it makes to `bound` (a sine) is taken without moving vertices.
    fn plan_for(&mut self, t: u32, bound: f64) -> Option<Plan> {
        let c = self.tets[t as usize];
        let edges = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
        let mut plans: Vec<Plan> = edges
            .iter()
            .filter_map(|&(i, j)| self.remove_edge(c[i], c[j]))
            .chain((0..4).filter_map(|k| self.flip23(t, k)))
            .filter(|p| self.sizes_kept(p))
            .collect();
        // A flip that leaves no cell below the bound ends the search: the vertex searches,
        // most of the step's time, are for the cells no flip mends.
        let mended = plans.iter().any(|p| p.quality >= bound);
        for v in c.into_iter().filter(|_| !mended) {
            // A vertex whose search failed is searched again only once its star changed.
            let at = self.version[v as usize];
            if self.unmovable_at[v as usize] == Some(at) {
                continue;
            }
            match self.relocate(v) {
                Some(plan) if self.sizes_kept(&plan) => plans.push(plan),
                Some(_) => {}
                None => self.unmovable_at[v as usize] = Some(at),
            }
        }
        // A new vertex only for a sliver proper that no flip or move helps.
        if plans.is_empty() && self.quality[t as usize] < SPLIT_BELOW.to_radians().sin() {
            plans.extend(
                edges
                    .iter()
                    .filter_map(|&(i, j)| self.split_edge(c[i], c[j]))
                    .filter(|p| self.sizes_kept(p)),
            );
        }
        // The first of the best, in the order above.
        plans
            .into_iter()
            .rev()
            .max_by(|x, y| x.quality.total_cmp(&y.quality))
    }

    fn apply(&mut self, plan: Plan) {
        let sub = self.subdomain[plan.removed[0] as usize];
        for &c in &plan.removed {
            self.kill(c);
        }
        let new = self.points.len() as u32;
        match plan.vertex {
            Vertex::Keep => {}
            Vertex::Move(v, at) => self.points[v as usize] = at,
            Vertex::Insert(at) => {
                self.points.push(at);
                self.movable.push(true);
                self.around.push(Vec::new());
                self.version.push(0);
                self.unmovable_at.push(None);
                self.insertions_left -= 1;
            }
        }
        for c in plan.created {
            self.add(c.map(|u| if u == NEW { new } else { u }), sub);
        }
    }

    /// The live cells and their subdomains, in slot order.
    fn into_live(self) -> (Vec<[u32; 4]>, Vec<SubdomainId>) {
        (0..self.tets.len())
            .filter(|&i| self.alive[i])
            .map(|i| (self.tets[i], self.subdomain[i]))
            .unzip()
    }
}

/// Removes the cells of `complex` whose [`quality`] is below the sine of `bound` (degrees),
/// worst first, by the change that raises the smallest quality of the cells it replaces the
/// most: an edge removal, a 2-3 flip or an interior vertex move, or else a split of an interior
/// edge. Stops when a pass changes nothing, after [`MAX_PASSES`] passes or at the deadline.
/// Boundary facets and the edges on them are kept, and no cell grows past `cell_size` (see
/// [`Cells::sizes_kept`]). Returns the number of changes.
pub(super) fn flip(
    complex: &mut MeshComplex,
    bound: f64,
    cell_size: &Sizing,
    deadline: &Deadline,
) -> usize {
    let bound = bound.to_radians().sin();
    let mut cells = Cells::new(complex, cell_size);
    let mut changes = 0;
    for _ in 0..MAX_PASSES {
        let mut bad: Vec<(f64, u32)> = (0..cells.tets.len())
            .filter(|&i| cells.alive[i] && cells.quality[i] < bound)
            .map(|i| (cells.quality[i], i as u32))
            .collect();
        bad.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
        let mut changed = 0;
        for (_, t) in bad {
            if deadline.passed() {
                break;
            }
            let at = cells.tets[t as usize]
                .iter()
                .map(|&v| cells.version[v as usize])
                .sum();
            if !cells.alive[t as usize] || cells.stuck_at[t as usize] == Some(at) {
                continue;
            }
            match cells.plan_for(t, bound) {
                Some(plan) => {
                    cells.apply(plan);
                    changed += 1;
                }
                None => cells.stuck_at[t as usize] = Some(at),
            }
        }
        changes += changed;
        if changed == 0 || deadline.passed() {
            break;
        }
    }
    let added = cells.points.len() - complex.points.len();
    complex
        .vertex_dimension
        .extend(std::iter::repeat_n(VertexDimension::Volume, added));
    complex.points = std::mem::take(&mut cells.points);
    (complex.tets, complex.tet_subdomain) = cells.into_live();
    changes
}
