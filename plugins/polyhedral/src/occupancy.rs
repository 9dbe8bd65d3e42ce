//! A coarse grid over the surface's bounding box marking the cells that may hold surface: a short
//! segment whose box covers only unmarked cells meets no triangle, which settles most dual-edge
//! queries (edges deep inside or outside the domain) with a few bit tests instead of a tree walk.
//!
//! Conservative by construction: a triangle marks every cell its bounding box overlaps, and the
//! same monotone map from coordinates to cell indices serves triangles and segments. If a segment
//! meets a triangle, their boxes overlap; the low corner of the overlap lies in both boxes, so its
//! cell lies in both index ranges and is marked.

use glam::DVec3;

/// Cells along the longest side of the bounding box.
const RESOLUTION: f64 = 64.0;
/// A segment whose box covers more cells than this is left to the tree.
const MAX_CELLS: usize = 64;

#[derive(Clone, Debug)]
pub(crate) struct Occupancy {
    origin: DVec3,
    inv_cell: f64,
    dims: [usize; 3],
    bits: Vec<u64>,
}

impl Occupancy {
    /// The grid over the box `[min, max]` with the cells overlapped by each triangle marked.
    pub(crate) fn new(min: DVec3, max: DVec3, triangles: &[[DVec3; 3]]) -> Self {
        let extent = (max - min).max_element();
        let inv_cell = if extent > 0.0 && extent.is_finite() {
            RESOLUTION / extent
        } else {
            1.0
        };
        let cells = |len: f64| ((len * inv_cell) as usize).saturating_add(1);
        let size = max - min;
        let dims = [cells(size.x), cells(size.y), cells(size.z)].map(|d| d.clamp(1, 1 << 10));
        let mut grid = Occupancy {
            origin: min,
            inv_cell,
            dims,
            bits: vec![0; (dims[0] * dims[1] * dims[2]).div_ceil(64)],
        };
        for t in triangles {
            let lo = t[0].min(t[1]).min(t[2]);
            let hi = t[0].max(t[1]).max(t[2]);
            let (a, b) = (grid.index(lo), grid.index(hi));
            for z in a[2]..=b[2] {
                for y in a[1]..=b[1] {
                    for x in a[0]..=b[0] {
                        let k = grid.linear([x, y, z]);
                        grid.bits[k / 64] |= 1u64 << (k % 64);
                    }
                }
            }
        }
        grid
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

    fn linear(&self, [x, y, z]: [usize; 3]) -> usize {
        (z * self.dims[1] + y) * self.dims[0] + x
    }

    /// Whether the segment `[a, b]` certainly meets no triangle (`false` when unsure).
    pub(crate) fn segment_is_clear(&self, a: DVec3, b: DVec3) -> bool {
        let (lo, hi) = (self.index(a.min(b)), self.index(a.max(b)));
        let count = (hi[0] - lo[0] + 1) * (hi[1] - lo[1] + 1) * (hi[2] - lo[2] + 1);
        if count > MAX_CELLS {
            return false;
        }
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let k = self.linear([x, y, z]);
                    if self.bits[k / 64] & (1u64 << (k % 64)) != 0 {
                        return false;
                    }
                }
            }
        }
        true
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

    #[test]
    fn a_clear_segment_meets_no_triangle_and_most_far_segments_are_clear() {
        let mut rng = StdRng::seed_from_u64(7);
        let mut point = |r: f64| {
            DVec3::new(
                rng.random_range(-r..r),
                rng.random_range(-r..r),
                rng.random_range(-r..r),
            )
        };
        let triangles: Vec<[DVec3; 3]> = (0..200)
            .map(|_| {
                let c = point(1.0);
                [c, c + point(0.05), c + point(0.05)]
            })
            .collect();
        let grid = Occupancy::new(DVec3::splat(-1.1), DVec3::splat(1.1), &triangles);
        let mut rng = StdRng::seed_from_u64(8);
        let mut clear = 0;
        for _ in 0..20_000 {
            let a = DVec3::new(
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
                rng.random_range(-1.5..1.5),
            );
            let b = a + DVec3::new(
                rng.random_range(-0.05..0.05),
                rng.random_range(-0.05..0.05),
                rng.random_range(-0.05..0.05),
            );
            if grid.segment_is_clear(a, b) {
                clear += 1;
                assert!(!triangles.iter().any(|t| meets(a, b, t)), "{a} {b}");
            }
        }
        assert!(clear > 10_000, "only {clear} clear");
        // A segment through a triangle's centre is never clear.
        for t in &triangles {
            let c = (t[0] + t[1] + t[2]) / 3.0;
            let n = (t[1] - t[0]).cross(t[2] - t[0]).normalize() * 1e-3;
            assert!(!grid.segment_is_clear(c - n, c + n));
        }
    }
}
