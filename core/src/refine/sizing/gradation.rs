//! Gradation: a size that grows by at most `G` per unit length, so transitions stay smooth.
//!
//! The graded size is the classic h(x) = min over samples i of (hᵢ + G·|x − xᵢ|), computed on a
//! regular grid covering the domain: the field is sampled at every node, then a Dijkstra sweep
//! over the 26-neighbour graph lowers each node to min over paths (h_seed + G · path length). Path
//! lengths in that graph exceed the straight distance by at most 8 %, so the sweep gives a value
//! between the exact h and h with distances 8 % longer; neighbouring nodes differ by at most G
//! times their distance, so the trilinear field between them grows by at most G along each axis.
//! The graded field is the minimum of the field and the grid: it never exceeds the field.

use super::{SizeGrid, SizingError, SizingField};
use crate::kernel::Point3;
use crate::oracle::Aabb;
use crate::refine::criteria::Sizing;
use glam::{DAffine3, DMat3};
use rayon::prelude::*;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Default node count of the gradation grid (64³): fine enough for transitions over a few
/// percent of the domain, a fraction of a second to sample and sweep.
pub const DEFAULT_GRADATION_NODES: usize = 1 << 18;

/// A field limited by a graded grid: min(field, grid).
pub struct Graded {
    field: Sizing,
    grid: SizeGrid,
}

impl Graded {
    /// `field` limited by `grid` (from [`graded`]).
    pub fn new(field: Sizing, grid: SizeGrid) -> Self {
        Graded { field, grid }
    }
}

impl SizingField for Graded {
    fn size_at(&self, p: Point3, label: u32) -> f64 {
        self.field.at(p, label).min(self.grid.at(p))
    }
    fn smallest(&self) -> Option<f64> {
        let grid = self.grid.smallest();
        match self.field.smallest() {
            Some(f) => grid.map(|g| g.min(f)),
            None => grid,
        }
    }
}

/// A node of the sweep's queue, smallest value first (ties by index, so the sweep is the same
/// on every run).
#[derive(PartialEq)]
struct Queued(f64, usize);

impl Eq for Queued {}

impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        other.0.total_cmp(&self.0).then(other.1.cmp(&self.1))
    }
}

impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

/// The grid over `bbox` (padded by one spacing on each side) with at most `max_nodes` nodes:
/// its node counts and spacing.
fn layout(bbox: &Aabb, max_nodes: usize) -> ([usize; 3], f64) {
    let extent = (bbox.max - bbox.min).max(Point3::splat(1e-3 * bbox.diagonal()));
    let max_nodes = max_nodes.max(27) as f64;
    let mut spacing = (extent.x * extent.y * extent.z / max_nodes).cbrt();
    let dims_for = |s: f64| extent.to_array().map(|e| (e / s).ceil() as usize + 3);
    // Each round grows the spacing by 5 %: a few rounds reach the count.
    for _ in 0..200 {
        let d = dims_for(spacing);
        if (d[0] * d[1] * d[2]) as f64 <= max_nodes {
            break;
        }
        spacing *= 1.05;
    }
    (dims_for(spacing), spacing)
}

/// The grid of `sample` over `bbox` graded by `gradation` (see the module's documentation).
/// Values of `sample` that are not finite and positive (no bound there, or outside the domain)
/// seed nothing. Each of `seeds` (a point and its size: a protecting ball) lowers the nodes of
/// its grid cell to its size plus `gradation` times their distance, so the sweep grows sizes
/// from it too. `None` when no node has a bound, or when `gradation` is not a positive number.
pub fn graded(
    sample: &(dyn Fn(Point3) -> f64 + Sync),
    seeds: &[(Point3, f64)],
    bbox: &Aabb,
    gradation: f64,
    max_nodes: usize,
) -> Result<Option<SizeGrid>, SizingError> {
    if !(gradation.is_finite() && gradation > 0.0) {
        return Ok(None);
    }
    let (dims, spacing) = layout(bbox, max_nodes);
    let origin = bbox.min - Point3::splat(spacing);
    let [nx, ny, nz] = dims;
    let node = |n: usize| {
        let (i, j, k) = (n % nx, (n / nx) % ny, n / (nx * ny));
        origin + spacing * Point3::new(i as f64, j as f64, k as f64)
    };
    let mut h: Vec<f64> = (0..nx * ny * nz)
        .into_par_iter()
        .map(|n| {
            let v = sample(node(n));
            if v.is_finite() && v > 0.0 {
                v
            } else {
                f64::INFINITY
            }
        })
        .collect();
    for &(p, size) in seeds {
        if !(size.is_finite() && size > 0.0 && p.is_finite()) {
            continue;
        }
        let q = ((p - origin) / spacing).floor();
        for corner in 0..8 {
            let c = [0, 1, 2].map(|axis| q[axis] as i64 + ((corner >> axis) & 1) as i64);
            if (0..3).any(|axis| c[axis] < 0 || c[axis] >= dims[axis] as i64) {
                continue;
            }
            let n = c[0] as usize + nx * (c[1] as usize + ny * c[2] as usize);
            h[n] = h[n].min(size + gradation * node(n).distance(p));
        }
    }
    let mut queue: BinaryHeap<Queued> = h
        .iter()
        .enumerate()
        .filter(|(_, v)| v.is_finite())
        .map(|(n, &v)| Queued(v, n))
        .collect();
    if queue.is_empty() {
        return Ok(None);
    }
    let mut steps = Vec::new();
    for dk in -1i64..=1 {
        for dj in -1i64..=1 {
            for di in -1i64..=1 {
                if (di, dj, dk) != (0, 0, 0) {
                    let length = spacing * ((di * di + dj * dj + dk * dk) as f64).sqrt();
                    steps.push(([di, dj, dk], gradation * length));
                }
            }
        }
    }
    while let Some(Queued(v, n)) = queue.pop() {
        if v > h[n] {
            continue;
        }
        let at = [n % nx, (n / nx) % ny, n / (nx * ny)];
        for &(d, rise) in &steps {
            let mut m = 0;
            let mut inside = true;
            for axis in (0..3).rev() {
                let c = at[axis] as i64 + d[axis];
                if c < 0 || c >= dims[axis] as i64 {
                    inside = false;
                    break;
                }
                m = m * dims[axis] + c as usize;
            }
            if inside && v + rise < h[m] {
                h[m] = v + rise;
                queue.push(Queued(v + rise, m));
            }
        }
    }
    let index_to_world =
        DAffine3::from_mat3_translation(DMat3::from_diagonal(Point3::splat(spacing)), origin);
    SizeGrid::new(dims, index_to_world, h).map(Some)
}
