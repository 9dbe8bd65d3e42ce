//! A coarse grid over the surface's bounding box listing, for each cell, the triangles whose
//! bounding box overlaps it. A short segment then needs no tree walk: when its box covers only
//! empty cells it meets no triangle (most dual-edge queries, deep inside or outside the domain),
//! and otherwise the triangles listed in the cells it covers are the candidates.
//!
//! The grid also knows the subdomain of every empty cell: face-adjacent empty cells lie in one
//! subdomain (the segment between their centres meets no triangle), so each connected region of
//! empty cells is asked once, at a fixed cell (so the answer does not depend on which query came
//! first), and then read. Most points a mesher asks about are far from the surface; near it, a
//! short segment to an empty cell replaces a ray.
//!
//! Conservative by construction: the same monotone map from coordinates to cell indices serves
//! triangles and segments. If a segment meets a triangle, their boxes overlap; the low corner of
//! the overlap lies in both boxes, so its cell lies in both index ranges and lists the triangle.

use crate::TriangleTree;
use delamesh_core::oracle::{OUTSIDE, SubdomainId};
use glam::DVec3;
use std::sync::OnceLock;

/// Cells along the longest side of the bounding box: about two per triangle (the mean longest
/// side of their boxes), within these bounds. Finer cells list big triangles many times over;
/// coarser ones give small triangles many neighbours in a cell.
const RESOLUTION: (f64, f64) = (16.0, 128.0);
/// A segment whose box covers more cells than this is left to the tree.
const MAX_CELLS: usize = 64;
/// Most candidates gathered for one segment before leaving it to the tree.
const MAX_CANDIDATES: usize = 64;
/// Triangle lists are kept while they hold at most this many entries per triangle on average, or
/// [`ENTRIES_ALWAYS_KEPT`] (a few huge triangles could fill the grid); beyond, cells are only
/// marked.
const MAX_ENTRIES_PER_TRIANGLE: usize = 32;
const ENTRIES_ALWAYS_KEPT: usize = 1 << 20;
/// The region of a cell that is not empty.
const NOT_EMPTY: u32 = u32::MAX;

/// The grid: cells of one size over a box, with the triangles (or boxes, given as degenerate
/// triangles) overlapping each.
#[derive(Clone, Debug)]
pub struct Occupancy {
    origin: DVec3,
    /// The far corner of the box the grid was made for (its cells may reach past it).
    max: DVec3,
    inv_cell: f64,
    dims: [usize; 3],
    /// Cell `k` lists `items[start[k]..start[k + 1]]`; a cell is empty when the range is.
    start: Vec<u32>,
    /// The listed triangles, or nothing when the lists were too long to keep.
    items: Vec<u32>,
    /// The region of each empty cell (`NOT_EMPTY` for the others): connected sets of empty cells.
    region: Vec<u32>,
    /// The first cell of each region, where its subdomain is asked, and that subdomain once asked.
    regions: Vec<(usize, OnceLock<SubdomainId>)>,
}

/// What the grid knows of a segment.
enum Near<'a> {
    /// It meets no triangle.
    Clear,
    /// It can only meet these triangles (sorted, without repeats).
    Candidates(&'a [u32]),
    /// Too long, or too many candidates: ask the tree.
    Unknown,
}

impl Occupancy {
    /// The grid over the box `[min, max]` with the cells overlapped by each triangle marked.
    pub fn new(min: DVec3, max: DVec3, triangles: &[[DVec3; 3]]) -> Self {
        let extent = (max - min).max_element();
        let mean_side = triangles
            .iter()
            .map(|t| (t[0].max(t[1]).max(t[2]) - t[0].min(t[1]).min(t[2])).max_element())
            .sum::<f64>()
            / triangles.len().max(1) as f64;
        let resolution = (2.0 * extent / mean_side).clamp(RESOLUTION.0, RESOLUTION.1);
        // A subnormal extent makes `resolution / extent` infinite, which would ask for 1024³
        // cells: such a box gets a single cell (still conservative).
        let inv_cell = Some(resolution / extent)
            .filter(|v| extent > 0.0 && v.is_finite())
            .unwrap_or(1.0);
        let cells = |len: f64| ((len * inv_cell) as usize).saturating_add(1);
        let size = max - min;
        let dims = [cells(size.x), cells(size.y), cells(size.z)].map(|d| d.clamp(1, 1 << 10));
        let mut grid = Occupancy {
            origin: min,
            max,
            inv_cell,
            dims,
            start: Vec::new(),
            items: Vec::new(),
            region: Vec::new(),
            regions: Vec::new(),
        };
        let ranges: Vec<([usize; 3], [usize; 3])> = triangles
            .iter()
            .map(|t| {
                let lo = t[0].min(t[1]).min(t[2]);
                let hi = t[0].max(t[1]).max(t[2]);
                (grid.index(lo), grid.index(hi))
            })
            .collect();
        let mut count = vec![0u32; dims[0] * dims[1] * dims[2] + 1];
        for &(a, b) in &ranges {
            grid.for_cells(a, b, |k| count[k] += 1);
        }
        let mut total = 0u32;
        for c in count.iter_mut() {
            let n = *c;
            *c = total;
            total = total.saturating_add(n);
        }
        grid.start = count;
        let keep = (total as usize)
            <= (MAX_ENTRIES_PER_TRIANGLE * triangles.len()).max(ENTRIES_ALWAYS_KEPT);
        if keep {
            let mut fill = grid.start.clone();
            grid.items = vec![0; total as usize];
            for (t, &(a, b)) in ranges.iter().enumerate() {
                let (items, fill) = (&mut grid.items, &mut fill);
                let dims = grid.dims;
                for_cells_in(dims, a, b, |k| {
                    items[fill[k] as usize] = t as u32;
                    fill[k] += 1;
                });
            }
        } else {
            // Only the marks are kept: `start[k]` < `start[k + 1]` for a cell with triangles.
            grid.items.clear();
        }
        grid.find_regions();
        grid
    }

    /// Labels the connected regions of empty cells (through their faces), in cell order.
    fn find_regions(&mut self) {
        let [nx, ny, nz] = self.dims;
        let mut region = vec![NOT_EMPTY; self.num_cells()];
        let mut stack = Vec::new();
        for first in 0..region.len() {
            if region[first] != NOT_EMPTY || !self.is_empty(first) {
                continue;
            }
            let id = self.regions.len() as u32;
            self.regions.push((first, OnceLock::new()));
            region[first] = id;
            stack.push(first);
            while let Some(k) = stack.pop() {
                let (x, y, z) = (k % nx, (k / nx) % ny, k / (nx * ny));
                let neighbours = [
                    (x > 0).then(|| k - 1),
                    (x + 1 < nx).then(|| k + 1),
                    (y > 0).then(|| k - nx),
                    (y + 1 < ny).then(|| k + nx),
                    (z > 0).then(|| k - nx * ny),
                    (z + 1 < nz).then(|| k + nx * ny),
                ];
                for n in neighbours.into_iter().flatten() {
                    if region[n] == NOT_EMPTY && self.is_empty(n) {
                        region[n] = id;
                        stack.push(n);
                    }
                }
            }
        }
        self.region = region;
    }

    fn is_empty(&self, k: usize) -> bool {
        self.start[k] == self.start[k + 1]
    }

    /// Calls `f` with the linear index of every cell in the index box `[a, b]`.
    fn for_cells(&self, a: [usize; 3], b: [usize; 3], f: impl FnMut(usize)) {
        for_cells_in(self.dims, a, b, f)
    }

    /// The cell of `p`, clamped to the grid (monotone in each coordinate).
    fn index(&self, p: DVec3) -> [usize; 3] {
        let q = (p - self.origin) * self.inv_cell;
        // Truncation is the floor of a non-negative value (and `as` saturates NaN to 0).
        let axis = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
        [
            axis(q.x, self.dims[0]),
            axis(q.y, self.dims[1]),
            axis(q.z, self.dims[2]),
        ]
    }

    /// The cell of `p` when no triangle comes near it: all points of such a cell lie in one
    /// subdomain, since the segment between two of them meets no triangle.
    fn empty_cell(&self, p: DVec3) -> Option<usize> {
        let k = self.linear(self.index(p));
        self.is_empty(k).then_some(k)
    }

    /// The subdomain of empty cell `k`: `find` answers at the centre of its region's first cell
    /// the first time.
    fn subdomain_of(&self, k: usize, find: impl FnOnce(DVec3) -> SubdomainId) -> SubdomainId {
        let (first, known) = &self.regions[self.region[k] as usize];
        *known.get_or_init(|| find(self.center(*first)))
    }

    /// The subdomain of `p` for a domain inside the grid's box: none outside the box (or for
    /// no point), its region's in an empty cell (see [`Self::subdomain_of`]), else what `near`
    /// answers.
    pub fn subdomain(
        &self,
        p: DVec3,
        find: impl FnOnce(DVec3) -> SubdomainId,
        near: impl FnOnce(DVec3) -> SubdomainId,
    ) -> SubdomainId {
        if !(p.is_finite() && p.cmpge(self.origin).all() && p.cmple(self.max).all()) {
            return OUTSIDE;
        }
        self.empty_cell_subdomain(p, find)
            .unwrap_or_else(|| near(p))
    }

    /// The subdomain of `p` when its cell is empty (see [`Self::subdomain_of`]).
    pub fn empty_cell_subdomain(
        &self,
        p: DVec3,
        find: impl FnOnce(DVec3) -> SubdomainId,
    ) -> Option<SubdomainId> {
        self.empty_cell(p).map(|k| self.subdomain_of(k, find))
    }

    /// The centre and subdomain of the first empty cell met from `p` along `dir` (in steps of
    /// half a cell, so a cell barely grazed may be passed over), or `None` when the walk leaves
    /// the grid first. The segment from `p` to that centre is short where `p` is near the
    /// surface: its crossings and the cell's subdomain give `p`'s side.
    pub fn first_empty_along(
        &self,
        p: DVec3,
        dir: DVec3,
        find: impl FnOnce(DVec3) -> SubdomainId,
    ) -> Option<(DVec3, SubdomainId)> {
        let step = dir.normalize_or_zero() * (0.5 / self.inv_cell);
        let end = self.origin
            + DVec3::new(
                self.dims[0] as f64,
                self.dims[1] as f64,
                self.dims[2] as f64,
            ) / self.inv_cell;
        // Half-cell steps cross the grid's diagonal within twice the sum of its dimensions.
        let steps = 2 * self.dims.iter().sum::<usize>();
        let k = (1..=steps)
            .map(|i| p + step * i as f64)
            .take_while(|q| q.cmpge(self.origin).all() && q.cmple(end).all())
            .find_map(|q| self.empty_cell(q))?;
        Some((self.center(k), self.subdomain_of(k, find)))
    }

    /// The centre of cell `k`.
    fn center(&self, k: usize) -> DVec3 {
        let [nx, ny, _] = self.dims;
        let at = [k % nx, (k / nx) % ny, k / (nx * ny)].map(|i| i as f64 + 0.5);
        self.origin + DVec3::new(at[0], at[1], at[2]) / self.inv_cell
    }

    /// The number of cells.
    fn num_cells(&self) -> usize {
        self.start.len() - 1
    }

    fn linear(&self, [x, y, z]: [usize; 3]) -> usize {
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    /// Calls `visit` with every triangle (or box) of `tree`, the tree over the grid's items,
    /// that may meet the segment `[a, b]`: none when the segment's cells are empty, the cells'
    /// lists when they are short, else what the tree finds.
    pub fn for_each_near_segment(
        &self,
        tree: &TriangleTree,
        a: DVec3,
        b: DVec3,
        mut visit: impl FnMut(u32),
    ) {
        let mut buffer = [0; MAX_CANDIDATES];
        match self.near_segment(a, b, &mut buffer) {
            Near::Clear => {}
            Near::Candidates(items) => items.iter().for_each(|&t| visit(t)),
            Near::Unknown => tree.for_each_near_segment(a, b, visit),
        }
    }

    /// What the grid knows of the segment `[a, b]`; `buffer` holds the candidates.
    fn near_segment<'b>(
        &self,
        a: DVec3,
        b: DVec3,
        buffer: &'b mut [u32; MAX_CANDIDATES],
    ) -> Near<'b> {
        let (lo, hi) = (self.index(a.min(b)), self.index(a.max(b)));
        let count = (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1);
        if count > MAX_CELLS {
            return Near::Unknown;
        }
        let lists = !self.items.is_empty();
        let mut len = 0;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let k = self.linear([x, y, z]);
                    let (s, e) = (self.start[k] as usize, self.start[k + 1] as usize);
                    if s == e {
                        continue;
                    }
                    if !lists || len + (e - s) > MAX_CANDIDATES {
                        return Near::Unknown;
                    }
                    buffer[len..len + (e - s)].copy_from_slice(&self.items[s..e]);
                    len += e - s;
                }
            }
        }
        if len == 0 {
            return Near::Clear;
        }
        let found = &mut buffer[..len];
        found.sort_unstable();
        let mut kept = 1;
        for i in 1..len {
            if found[i] != found[kept - 1] {
                found[kept] = found[i];
                kept += 1;
            }
        }
        Near::Candidates(&buffer[..kept])
    }
}

/// Calls `f` with the linear index of every cell in the index box `[a, b]` of a grid `dims`.
fn for_cells_in(dims: [usize; 3], a: [usize; 3], b: [usize; 3], mut f: impl FnMut(usize)) {
    for z in a[2]..=b[2] {
        for y in a[1]..=b[1] {
            for x in a[0]..=b[0] {
                f((z * dims[1] + y) * dims[0] + x);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng, rngs::StdRng};

    /// Whether segment `[a, b]` meets triangle `t` (floating point, with a margin that only
    /// makes it answer "meets" more often, which is the safe side for this test).
    fn meets(a: DVec3, b: DVec3, t: &[DVec3; 3]) -> bool {
        let n = (t[1] - t[0]).cross(t[2] - t[0]);
        let (da, db) = (n.dot(a - t[0]), n.dot(b - t[0]));
        if da * db > 0.0 {
            return false;
        }
        let s = da / (da - db);
        let p = a + (b - a) * s;
        (0..3).all(|k| {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            n.dot((v - u).cross(p - u)) >= -1e-12 * n.length_squared()
        })
    }

    /// A point of `[-r, r]³`.
    fn random_point(rng: &mut StdRng, r: f64) -> DVec3 {
        DVec3::new(
            rng.random_range(-r..r),
            rng.random_range(-r..r),
            rng.random_range(-r..r),
        )
    }

    #[test]
    fn a_subnormal_box_gets_one_cell() {
        let s = 1e-310;
        let t = [[DVec3::ZERO, DVec3::new(s, 0.0, 0.0), DVec3::new(0.0, s, s)]];
        let grid = Occupancy::new(DVec3::ZERO, DVec3::splat(s), &t);
        assert_eq!(grid.dims, [1, 1, 1]);
    }

    #[test]
    fn every_triangle_a_segment_meets_is_a_candidate() {
        let mut rng = StdRng::seed_from_u64(7);
        let mut point = |r: f64| random_point(&mut rng, r);
        let triangles: Vec<[DVec3; 3]> = (0..200)
            .map(|_| {
                let c = point(1.0);
                [c, c + point(0.05), c + point(0.05)]
            })
            .collect();
        let grid = Occupancy::new(DVec3::splat(-1.1), DVec3::splat(1.1), &triangles);
        let mut rng = StdRng::seed_from_u64(8);
        let mut buffer = [0; MAX_CANDIDATES];
        let (mut clear, mut listed) = (0, 0);
        for _ in 0..20_000 {
            let a = random_point(&mut rng, 1.5);
            let b = a + random_point(&mut rng, 0.05);
            let meeting = |t: &usize| meets(a, b, &triangles[*t]);
            match grid.near_segment(a, b, &mut buffer) {
                Near::Clear => {
                    clear += 1;
                    assert!(!(0..triangles.len()).any(|t| meeting(&t)), "{a} {b}");
                }
                Near::Candidates(c) => {
                    listed += 1;
                    assert!(c.windows(2).all(|w| w[0] < w[1]), "sorted, no repeats");
                    for t in (0..triangles.len()).filter(meeting) {
                        assert!(c.contains(&(t as u32)), "{t} missed for {a} {b}");
                    }
                }
                Near::Unknown => {}
            }
        }
        assert!(
            clear > 10_000 && listed > 100,
            "{clear} clear, {listed} listed"
        );
        // A segment through a triangle's centre lists it.
        for (t, tri) in triangles.iter().enumerate() {
            let c = (tri[0] + tri[1] + tri[2]) / 3.0;
            let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).normalize() * 1e-3;
            match grid.near_segment(c - n, c + n, &mut buffer) {
                Near::Candidates(found) => assert!(found.contains(&(t as u32))),
                Near::Clear => panic!("triangle {t} missed"),
                Near::Unknown => {}
            }
        }
    }

    /// A convex polyhedron close to the unit sphere (latitude and longitude bands) and its
    /// exact inside test by its faces' planes.
    fn convex_sphere() -> (Vec<[DVec3; 3]>, impl Fn(DVec3) -> bool) {
        let (bands, sectors) = (12, 24);
        let at = |i: usize, j: usize| {
            let (theta, phi) = (
                std::f64::consts::PI * i as f64 / bands as f64,
                std::f64::consts::TAU * j as f64 / sectors as f64,
            );
            DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            )
        };
        let mut triangles = Vec::new();
        for i in 0..bands {
            for j in 0..sectors {
                let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j), at(i + 1, j + 1));
                if i > 0 {
                    triangles.push([a, c, b]);
                }
                if i + 1 < bands {
                    triangles.push([b, c, d]);
                }
            }
        }
        let planes: Vec<(DVec3, f64)> = triangles
            .iter()
            .map(|t| {
                let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                (n, n.dot(t[0]))
            })
            .collect();
        (triangles, move |p: DVec3| {
            planes.iter().all(|&(n, d)| n.dot(p) < d)
        })
    }

    /// Every empty cell gets its region's subdomain, which is asked once per region, and the
    /// walk from a point near the surface ends at an empty cell with its subdomain.
    #[test]
    fn empty_regions_are_asked_once_and_answer_for_all_their_cells() {
        let (triangles, inside) = convex_sphere();
        let grid = Occupancy::new(DVec3::splat(-1.5), DVec3::splat(1.5), &triangles);
        let asked = std::cell::Cell::new(0);
        let find = |c: DVec3| {
            asked.set(asked.get() + 1);
            SubdomainId(inside(c) as u32)
        };
        let mut rng = StdRng::seed_from_u64(9);
        let (mut empty, mut walked) = (0, 0);
        for _ in 0..20_000 {
            let p = random_point(&mut rng, 1.5);
            let expected = SubdomainId(inside(p) as u32);
            match grid.empty_cell_subdomain(p, find) {
                Some(s) => {
                    empty += 1;
                    assert_eq!(s, expected, "{p}");
                }
                None => {
                    if let Some((c, s)) = grid.first_empty_along(p, DVec3::new(0.3, 0.5, 0.8), find)
                    {
                        walked += 1;
                        assert_eq!(grid.empty_cell_subdomain(c, find), Some(s));
                        assert_eq!(s, SubdomainId(inside(c) as u32), "{c}");
                    }
                }
            }
        }
        assert!(
            empty > 10_000 && walked > 100,
            "{empty} empty, {walked} walked"
        );
        // One region inside the surface, one around it.
        assert_eq!(grid.regions.len(), 2);
        assert_eq!(asked.get(), 2);
    }
}
