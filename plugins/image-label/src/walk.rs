//! Where the class changes along a segment of index space: a walk through the cells the segment
//! crosses (Amanatides and Woo's traversal), which reads a cell's class from its block or its
//! corner voxels where those agree, and samples and bisects only the cells with several classes.
//!
//! With trilinear interpolation a cell is the unit cube between eight voxel centres, and its
//! class anywhere depends on those eight voxels alone: a cell whose corners agree has their class
//! throughout, exactly. With nearest-voxel classes a cell is a voxel, and changes lie on its
//! faces.

use crate::grid::{BLOCK, Class, ClassGrid, Interpolation, MIXED};
use glam::DVec3;

/// Distance between samples in cells with several classes, in voxels. Finer than a voxel so that
/// a label a fraction of a voxel thick inside one cell is seen.
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
    let walk = Walk { grid, a, d, len };
    // Outside the box the class is the background.
    let mut class = if enter > 0.0 { 0 } else { grid.class_at(a) };
    let nearest = grid.interpolation == Interpolation::Nearest;
    // A nearest-voxel cell is the voxel around its centre: cells start half a voxel lower.
    let offset = if nearest { -0.5 } else { 0.0 };
    let last = grid
        .dims
        .map(|n| if nearest { n - 1 } else { n.saturating_sub(2) });
    let mut cells = Cells::new(a, d, enter, offset);
    // Each iteration crosses a cell face (of at most ~ len + 1 along each axis) or jumps past
    // at least one cell; the cap only guards against rounding.
    let max_iterations = 6 * (len as usize) + 32;
    let mut t = enter;
    // The last jump's end: jumps only go forward, so the walk always progresses.
    let mut jumped = enter;
    for _ in 0..max_iterations {
        if t >= leave {
            break;
        }
        let (cell, exit) = cells.next();
        let exit = exit.clamp(t, leave);
        let cell: [usize; 3] = std::array::from_fn(|k| cell[k].clamp(0, last[k] as i64) as usize);
        let block = grid.cell_block(cell);
        let (summary, reach) = grid.block(block);
        match summary {
            MIXED if nearest => {
                let to = grid.voxel(cell[0], cell[1], cell[2]).index();
                push(out, t, &mut class, to);
            }
            MIXED => walk.through_cell(cell, (t, exit), &mut class, out),
            s => {
                push(out, t, &mut class, s);
                let far = walk.leave_cube(block, reach, offset);
                if far > exit && far > jumped {
                    if far >= leave {
                        break;
                    }
                    t = far;
                    jumped = t;
                    cells = Cells::new(a, d, t, offset);
                    continue;
                }
            }
        }
        t = exit;
    }
    if leave < 1.0 {
        push(out, leave, &mut class, 0);
    }
}

/// Records a change at `t` if the class `to` differs from the running `class`.
fn push(out: &mut Vec<Change>, t: f64, class: &mut u32, to: u32) {
    if to != *class {
        out.push(Change {
            t,
            from: *class,
            to,
        });
        *class = to;
    }
}

/// A segment `a + t d` of length `len` across a grid, for the cells with several classes.
struct Walk<'g, C> {
    grid: &'g ClassGrid<C>,
    a: DVec3,
    d: DVec3,
    len: f64,
}

impl<C: Class> Walk<'_, C> {
    /// Where the segment leaves the cube of blocks within `reach - 1` of `block` (whose cells'
    /// lower corners are at `offset` + integers), which has one class throughout.
    fn leave_cube(&self, block: [usize; 3], reach: usize, offset: f64) -> f64 {
        let r = reach.saturating_sub(1);
        let mut far = f64::INFINITY;
        for (k, b) in block.into_iter().enumerate() {
            let (a, d) = (self.a[k], self.d[k]);
            if d > 0.0 {
                let upper = (BLOCK * (b + r + 1)) as f64 - offset;
                far = far.min((upper - a) / d);
            } else if d < 0.0 {
                let lower = (BLOCK * b.saturating_sub(r)) as f64 + offset;
                far = far.min((lower - a) / d);
            }
        }
        far
    }

    /// The changes of class inside the trilinear cell `cell` between parameters `t0` and `t1`,
    /// starting from `class`: samples every [`STEP`] and bisection between samples that differ.
    fn through_cell(
        &self,
        cell: [usize; 3],
        (t0, t1): (f64, f64),
        class: &mut u32,
        out: &mut Vec<Change>,
    ) {
        let corners = self.grid.cell_corners(cell);
        let lower = DVec3::from_array(cell.map(|v| v as f64));
        let class_at = |t: f64| {
            let f = (self.a + t * self.d - lower).clamp(DVec3::ZERO, DVec3::ONE);
            self.grid.pick(&corners, f)
        };
        // A change at the cell's entry happens only on the domain box's faces (or by rounding
        // on a cell face).
        if corners.iter().all(|&c| c == corners[0]) {
            push(out, t0, class, corners[0].index());
            return;
        }
        push(out, t0, class, class_at(t0));
        let samples = (((t1 - t0) * self.len / STEP).ceil() as usize).clamp(1, 8);
        let mut from = t0;
        for k in 1..=samples {
            let t = if k == samples {
                t1
            } else {
                t0 + (t1 - t0) * k as f64 / samples as f64
            };
            let next = class_at(t);
            // Several changes between two samples (a third label a fraction of a voxel thick):
            // find them one after the other.
            let (mut start, mut c) = (from, *class);
            for _ in 0..8 {
                if c == next {
                    break;
                }
                let (change, after) = bisect(&class_at, (start, c), (t, next), self.len);
                out.push(change);
                (start, c) = (after, change.to);
            }
            *class = next;
            from = t;
        }
    }
}

/// Amanatides and Woo's traversal of the unit cells (lower corners at `offset` + integers) that
/// `a + t d` crosses, from parameter `t`.
struct Cells {
    cell: [i64; 3],
    step: [i64; 3],
    /// The parameter where the segment leaves the current cell across each axis.
    t_max: [f64; 3],
    t_delta: [f64; 3],
}

impl Cells {
    fn new(a: DVec3, d: DVec3, t: f64, offset: f64) -> Self {
        let q = a + t * d;
        let mut cells = Cells {
            cell: [0; 3],
            step: [0; 3],
            t_max: [f64::INFINITY; 3],
            t_delta: [f64::INFINITY; 3],
        };
        for k in 0..3 {
            let x = q[k] - offset;
            let mut c = x.floor();
            // On a face, moving down: the cell below.
            if d[k] < 0.0 && c == x {
                c -= 1.0;
            }
            cells.cell[k] = c as i64;
            if d[k] != 0.0 {
                let face = offset + c + if d[k] > 0.0 { 1.0 } else { 0.0 };
                cells.step[k] = if d[k] > 0.0 { 1 } else { -1 };
                cells.t_max[k] = (face - a[k]) / d[k];
                cells.t_delta[k] = 1.0 / d[k].abs();
            }
        }
        cells
    }

    /// The current cell and the parameter where the segment leaves it; moves to the next cell.
    fn next(&mut self) -> ([i64; 3], f64) {
        let cell = self.cell;
        let m = self.t_max;
        let k = if m[0] <= m[1] && m[0] <= m[2] {
            0
        } else if m[1] <= m[2] {
            1
        } else {
            2
        };
        let exit = self.t_max[k];
        self.cell[k] += self.step[k];
        self.t_max[k] += self.t_delta[k];
        (cell, exit)
    }
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

/// Narrows `[t0, t1]`, whose ends have different classes by `class_at`, to a change of class;
/// also returns the end of the final bracket, where the class is the change's `to`.
fn bisect(
    class_at: &impl Fn(f64) -> u32,
    (mut t0, c0): (f64, u32),
    (mut t1, mut c1): (f64, u32),
    len: f64,
) -> (Change, f64) {
    let tolerance = TOLERANCE / len;
    // Halving a bracket of at most one cell's diagonal down to the tolerance takes < 12 steps.
    for _ in 0..64 {
        if t1 - t0 <= tolerance {
            break;
        }
        let mid = 0.5 * (t0 + t1);
        let cm = class_at(mid);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::grid::tests::random_balls;
    use delamesh_core::random::XorShift;

    /// Random segments across random images of blobs (some a voxel thin): every change leaves
    /// the class the walk was in for another one, and between two consecutive changes (and after
    /// the last) `class_at` gives that class wherever it is sampled, an eighth of a voxel apart.
    /// The larger image has long stretches of one class, which the walk crosses in jumps.
    #[test]
    fn changes_match_the_class_along_random_segments() {
        let mut rng = XorShift::new(17);
        for (dims, blobs, largest) in [([23, 19, 14], 12, 4.0), ([70, 58, 44], 9, 12.0)] {
            let size = DVec3::from_array(dims.map(|n| n as f64));
            let classes = random_balls(dims, blobs, (0.6, largest), 3, &mut rng);
            for interpolation in [Interpolation::Trilinear, Interpolation::Nearest] {
                let g = ClassGrid::new(dims, classes.clone(), 4, interpolation);
                check_random_segments(&g, size, &mut rng);
            }
        }
    }

    /// 400 random segments across `g` (of `size` voxels), checked as
    /// [`changes_match_the_class_along_random_segments`] says.
    fn check_random_segments(g: &ClassGrid<u8>, size: DVec3, rng: &mut XorShift) {
        let mut found = Vec::new();
        let (mut walks, mut seen) = (0, 0);
        for _ in 0..400 {
            // Ends inside and outside the image, some segments along grid lines.
            let mut end =
                || DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * (size + 4.0) - 2.0;
            let (mut a, mut b) = (end(), end());
            if rng.below(4) == 0 {
                // In a plane of voxel centres.
                a.y = a.y.round();
                b.y = a.y;
            }
            if rng.below(4) == 0 {
                a = a.round();
            }
            found.clear();
            changes(g, a, b, &mut found);
            walks += 1;
            seen += found.len();
            let len = (b - a).length();
            let at = |t: f64| g.class_at(a + t * (b - a));
            let mut class = at(0.0);
            let mut last = 0.0;
            let margin = 4.0 * TOLERANCE / len;
            for change in &found {
                assert_eq!(change.from, class, "{a} {b} {found:?}");
                assert!(change.t >= last && change.t <= 1.0);
                assert_ne!(change.from, change.to);
                // Dense samples away from the changes have the running class.
                let steps = ((change.t - last) * len * 8.0) as usize;
                for k in 1..steps {
                    let t = last + (change.t - last) * k as f64 / steps as f64;
                    if t - last > margin && change.t - t > margin {
                        assert_eq!(at(t), class, "{a} {b} at {t}: {found:?}");
                    }
                }
                class = change.to;
                last = change.t;
            }
            let steps = ((1.0 - last) * len * 8.0) as usize;
            for k in 1..=steps {
                let t = last + (1.0 - last) * k as f64 / steps as f64;
                if t - last > margin {
                    assert_eq!(at(t), class, "{a} {b} at {t}: {found:?}");
                }
            }
        }
        assert!(walks == 400 && seen > 200, "{seen} changes");
    }
}
