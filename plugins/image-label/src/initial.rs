//! The extent of the labels and the initial surface points: a few crossings on every connected
//! group of blocks the interfaces pass through, so that every interface component starts with
//! restricted facets (P0 of the thesis) whatever its size.

use crate::grid::{BLOCK, Class, ClassGrid, Interpolation, MIXED};
use crate::walk::changes;
use glam::DVec3;
use std::collections::VecDeque;

/// Blocks sampled per connected group of boundary blocks, spread along the group.
const BLOCKS_PER_GROUP: usize = 16;

/// The index-space box of the blocks holding a non-background voxel, with a voxel of margin so
/// that the boundary lies strictly inside; `None` for an image of background only.
pub(crate) fn occupied_box<C: Class>(g: &ClassGrid<C>) -> Option<(DVec3, DVec3)> {
    let [bx, by, bz] = g.blocks();
    let (mut lo, mut hi) = ([usize::MAX; 3], [0usize; 3]);
    for k in 0..bz {
        for j in 0..by {
            for i in 0..bx {
                if g.block_summary([i, j, k]) != 0 {
                    for (a, b) in [i, j, k].into_iter().enumerate() {
                        lo[a] = lo[a].min(b);
                        hi[a] = hi[a].max(b);
                    }
                }
            }
        }
    }
    if lo[0] == usize::MAX {
        return None;
    }
    let margin = match g.interpolation {
        Interpolation::Trilinear => 1.0,
        Interpolation::Nearest => 1.5,
    };
    let lo = DVec3::from_array(lo.map(|b| (b * BLOCK) as f64)) - margin;
    let top = |a: usize| (((hi[a] + 1) * BLOCK).min(g.dims[a] - 1)) as f64 + margin;
    Some((lo, DVec3::new(top(0), top(1), top(2))))
}

/// Initial surface points as `(index-space point, class on one side, class on the other)`.
pub(crate) fn initial_points<C: Class>(g: &ClassGrid<C>) -> Vec<(DVec3, u32, u32)> {
    let [bx, by, bz] = g.blocks();
    let index = |b: [usize; 3]| b[0] + bx * (b[1] + by * b[2]);
    // Boundary blocks: several classes, or a label touching the image border.
    let is_boundary = |b: [usize; 3]| {
        let s = g.block_summary(b);
        let on_border = (0..3).any(|a| b[a] == 0 || b[a] + 1 == g.blocks()[a]);
        s == MIXED || (s != 0 && on_border)
    };
    let mut seen = vec![false; bx * by * bz];
    let mut points = Vec::new();
    for k in 0..bz {
        for j in 0..by {
            for i in 0..bx {
                let start = [i, j, k];
                if seen[index(start)] || !is_boundary(start) {
                    continue;
                }
                // Breadth-first over face neighbours: the group, in a deterministic order.
                let mut group = Vec::new();
                let mut queue = VecDeque::from([start]);
                seen[index(start)] = true;
                while let Some(b) = queue.pop_front() {
                    group.push(b);
                    for a in 0..3 {
                        for up in [false, true] {
                            let mut n = b;
                            if up {
                                if b[a] + 1 >= g.blocks()[a] {
                                    continue;
                                }
                                n[a] += 1;
                            } else {
                                if b[a] == 0 {
                                    continue;
                                }
                                n[a] -= 1;
                            }
                            if !seen[index(n)] && is_boundary(n) {
                                seen[index(n)] = true;
                                queue.push_back(n);
                            }
                        }
                    }
                }
                let stride = group.len().div_ceil(BLOCKS_PER_GROUP);
                for b in group.iter().step_by(stride) {
                    // The block's index box, clipped to the image (the last blocks may be
                    // shorter, a small image smaller than one block).
                    let lo = DVec3::from_array(b.map(|v| (v * BLOCK) as f64));
                    let hi = DVec3::from_array(
                        [0, 1, 2].map(|a| ((b[a] + 1) * BLOCK).min(g.dims[a] - 1) as f64),
                    );
                    let centre = 0.5 * (lo + hi);
                    let before = points.len();
                    for (a, axis) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
                        let reach = 0.5 * (hi[a] - lo[a]) + 1.5;
                        crossings(g, centre - reach * axis, centre + reach * axis, &mut points);
                    }
                    // Lines through the centre can miss every interface of the block (specks
                    // of a voxel): then the segment between two neighbouring voxels of
                    // different classes crosses one.
                    if points.len() == before
                        && let Some((p, q)) = differing_neighbours(g, *b)
                    {
                        crossings(g, p, q, &mut points);
                    }
                }
            }
        }
    }
    points
}

/// Appends the class changes along `[from, to]` as initial points.
fn crossings<C: Class>(g: &ClassGrid<C>, from: DVec3, to: DVec3, out: &mut Vec<(DVec3, u32, u32)>) {
    let mut found = Vec::new();
    changes(g, from, to, &mut found);
    out.extend(
        found
            .iter()
            .map(|c| (from + c.t * (to - from), c.from, c.to)),
    );
}

/// The centres of the first two face-neighbouring voxels of block `b` (its cells' corners) with
/// different classes: a voxel centre has its voxel's class under either interpolation.
fn differing_neighbours<C: Class>(g: &ClassGrid<C>, b: [usize; 3]) -> Option<(DVec3, DVec3)> {
    let top = [0, 1, 2].map(|a| ((b[a] + 1) * BLOCK).min(g.dims[a] - 1));
    let range = |a: usize| b[a] * BLOCK..=top[a];
    for k in range(2) {
        for j in range(1) {
            for i in range(0) {
                let here = g.voxel(i, j, k).index();
                for (a, n) in [[i + 1, j, k], [i, j + 1, k], [i, j, k + 1]]
                    .into_iter()
                    .enumerate()
                {
                    if n[a] <= top[a] && g.voxel(n[0], n[1], n[2]).index() != here {
                        let centre = |v: [usize; 3]| DVec3::from_array(v.map(|x| x as f64));
                        return Some((centre([i, j, k]), centre(n)));
                    }
                }
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Specks of one voxel in every other block, off the lines through the block centres: each
    /// sampled block still gives points, on the interface of a speck it holds.
    #[test]
    fn blocks_of_specks_off_the_centre_lines_give_initial_points() {
        let dims = [20, 20, 20];
        let classes: Vec<u8> = (0..8000)
            .map(|v: usize| {
                let speck = [v % 20, v / 20 % 20, v / 400].iter().all(|&i| i % 6 == 1);
                u8::from(speck)
            })
            .collect();
        for interpolation in [Interpolation::Trilinear, Interpolation::Nearest] {
            let g = ClassGrid::new(dims, classes.clone(), 2, interpolation);
            let points = initial_points(&g);
            assert!(!points.is_empty());
            for (p, c0, c1) in points {
                assert_eq!([c0.min(c1), c0.max(c1)], [0, 1]);
                // On a speck's interface: within a voxel of a speck's centre.
                let speck = p.to_array().map(|x| 6.0 * ((x - 1.0) / 6.0).round() + 1.0);
                assert!(p.distance(DVec3::from_array(speck)) <= 1.0, "{p}");
            }
        }
    }
}
