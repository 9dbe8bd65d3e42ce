//! Where the class changes along a segment of index space: sample the segment every half voxel,
//! jumping across blocks of one class and across the outside of the image, then bisect every
//! change down to a thousandth of a voxel.

use crate::grid::{BLOCK, Class, ClassGrid, MIXED};
use glam::DVec3;

/// Distance between samples in blocks with several classes, in voxels. Finer than a voxel so that
/// a label one voxel thick is seen.
const STEP: f64 = 0.5;
/// Bisection stops when the bracket is this short, in voxels.
const TOLERANCE: f64 = 1e-3;

/// A change of class along a segment: at parameter `t`, from class `from` to class `to`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Change {
    pub t: f64,
    pub from: u32,
    pub to: u32,
}

/// Appends every change of class along `[a, b]` (index space), in increasing `t`.
pub(crate) fn changes<C: Class>(grid: &ClassGrid<C>, a: DVec3, b: DVec3, out: &mut Vec<Change>) {
    let d = b - a;
    let len = d.length();
    if !(len.is_finite() && len > 0.0) {
        return;
    }
    let (lo, hi) = grid.domain_box();
    let Some((enter, leave)) = clip(a, d, lo, hi) else {
        return;
    };
    let at = |t: f64| a + t * d;
    let step = STEP / len;
    // Every iteration advances by a step, to the next block or across the outside, so the walk
    // ends after at most ~2 len + 3 len / BLOCK + a few iterations; the cap only guards against
    // rounding trapping `t` on a block face.
    let max_iterations = (4.0 * len) as usize + 64;
    let mut t = 0.0;
    let mut class = grid.class_at(at(0.0));
    for _ in 0..max_iterations {
        if t >= 1.0 {
            break;
        }
        let q = at(t);
        let next = if t < enter {
            enter
        } else if t > leave {
            1.0
        } else {
            match grid.block_of(q) {
                Some(blk) if grid.block_summary(blk) != MIXED => {
                    block_exit(blk, a, d).max(t + step * 1e-3)
                }
                _ => t + step,
            }
        }
        .min(1.0);
        // In a block of one class the block says it, without reading voxels.
        let next_class = match grid.block_of(at(next)).map(|b| grid.block_summary(b)) {
            Some(s) if s != MIXED => s,
            _ => grid.class_at(at(next)),
        };
        // Several changes between two samples (a third label a fraction of a voxel thick): find
        // them one after the other.
        let (mut from, mut c) = (t, class);
        for _ in 0..8 {
            if c == next_class {
                break;
            }
            let (change, after) = bisect(grid, a, d, (from, c), (next, next_class), len);
            out.push(change);
            (from, c) = (after, change.to);
        }
        t = next;
        class = next_class;
    }
}

/// The parameter where `a + t d` leaves the closed box of block `blk`.
fn block_exit(blk: [usize; 3], a: DVec3, d: DVec3) -> f64 {
    let mut exit = f64::INFINITY;
    for axis in 0..3 {
        let (o, v) = (a[axis], d[axis]);
        if v == 0.0 {
            continue;
        }
        let lo = (blk[axis] * BLOCK) as f64;
        let face = if v > 0.0 { lo + BLOCK as f64 } else { lo };
        exit = exit.min((face - o) / v);
    }
    exit
}

/// Parameters `[enter, leave]` of the part of `a + t d` inside the box, if any.
fn clip(a: DVec3, d: DVec3, lo: DVec3, hi: DVec3) -> Option<(f64, f64)> {
    let (mut enter, mut leave) = (0.0f64, 1.0f64);
    for axis in 0..3 {
        let (o, v) = (a[axis], d[axis]);
        if v == 0.0 {
            if o < lo[axis] || o > hi[axis] {
                return None;
            }
            continue;
        }
        let (t0, t1) = ((lo[axis] - o) / v, (hi[axis] - o) / v);
        enter = enter.max(t0.min(t1));
        leave = leave.min(t0.max(t1));
    }
    (enter <= leave).then_some((enter, leave))
}

/// Narrows `[t0, t1]`, whose ends have different classes, to a change of class; also returns
/// the end of the final bracket, where the class is the change's `to`.
fn bisect<C: Class>(
    grid: &ClassGrid<C>,
    a: DVec3,
    d: DVec3,
    (mut t0, c0): (f64, u32),
    (mut t1, mut c1): (f64, u32),
    len: f64,
) -> (Change, f64) {
    let tolerance = TOLERANCE / len;
    // Halving a bracket of at most one block's diagonal down to the tolerance takes < 20 steps.
    for _ in 0..64 {
        if t1 - t0 <= tolerance {
            break;
        }
        let mid = 0.5 * (t0 + t1);
        let cm = grid.class_at(a + mid * d);
        if cm == c0 {
            t0 = mid;
        } else {
            t1 = mid;
            c1 = cm;
        }
    }
    let change = Change {
        t: 0.5 * (t0 + t1),
        from: c0,
        to: c1,
    };
    (change, t1)
}
