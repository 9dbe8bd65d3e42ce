//! The voxel classes of an image and the class of any point of index space, with a coarse grid of
//! blocks that records where the class cannot change, so that segment walks skip them.
//!
//! Index space puts voxel `(i, j, k)`'s centre at the integer point `(i, j, k)`. A class is the rank
//! of a label among the image's labels; class 0 is the background (outside).

use glam::DVec3;
use rayon::prelude::*;

/// Voxels per block edge. A block `b` covers the closed index box `[B b, B (b + 1)]` on each axis,
/// so its region is decided by the voxels `B b ..= B (b + 1)` alone, for both interpolations.
pub(crate) const BLOCK: usize = 4;
/// Block summary of a block whose voxels have several classes.
pub(crate) const MIXED: u32 = u32::MAX;

/// Largest bias added to an interpolated indicator (see [`ClassGrid::class_at`]): class `c` of
/// `n` gets `TIE_BIAS · c / n`, so that however many classes, a voxel's own class wins at its
/// centre and interfaces move by a few hundredths of a voxel at most.
const TIE_BIAS: f64 = 4e-2;

/// How the class of a point between voxel centres is chosen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Interpolation {
    /// The class of the nearest voxel: staircase surfaces, exactly the voxels' boundaries.
    Nearest,
    /// The class whose indicator function, interpolated trilinearly between the eight nearest
    /// voxel centres, is largest (CGAL's labellized trilinear interpolation): smoother surfaces.
    #[default]
    Trilinear,
}

/// A voxel class stored compactly: one byte for up to 256 labels, two beyond.
pub(crate) trait Class: Copy + Eq + Send + Sync + 'static {
    fn index(self) -> u32;
}

impl Class for u8 {
    fn index(self) -> u32 {
        u32::from(self)
    }
}

impl Class for u16 {
    fn index(self) -> u32 {
        u32::from(self)
    }
}

/// Voxels per brick edge: classes are stored brick by brick (64 voxels, one cache line of bytes),
/// so that the eight voxels around a point, and the next samples of a walk, share cache lines.
const BRICK: usize = 4;

/// Voxel classes in bricks, and a summary per block.
pub(crate) struct ClassGrid<C> {
    pub dims: [usize; 3],
    /// Bricks along x and y.
    bricks: [usize; 2],
    classes: Vec<C>,
    pub interpolation: Interpolation,
    /// The bias per class rank (see [`TIE_BIAS`]).
    bias: f64,
    blocks: [usize; 3],
    /// Per block: its only class, or [`MIXED`].
    summary: Vec<u32>,
}

impl<C: Class> ClassGrid<C> {
    /// The grid of `classes` (each below `count`), given x fastest, then y, then z.
    pub fn new(
        dims: [usize; 3],
        classes: Vec<C>,
        count: usize,
        interpolation: Interpolation,
    ) -> Self {
        let blocks = dims.map(|n| (n.saturating_sub(1)).div_ceil(BLOCK).max(1));
        let [bx, by, bz] = dims.map(|n| n.div_ceil(BRICK));
        let [nx, ny, _] = dims;
        // Padding voxels (past the image in the last bricks) are never read.
        let slab = bx * by * BRICK.pow(3);
        let mut bricked = vec![classes[0]; slab * bz];
        // Each slab of bricks along z is filled on its own (in parallel), row by row.
        bricked
            .par_chunks_mut(slab)
            .enumerate()
            .for_each(|(kb, out)| {
                for k in kb * BRICK..((kb + 1) * BRICK).min(dims[2]) {
                    for j in 0..ny {
                        let row = &classes[nx * (j + ny * k)..][..nx];
                        for (i, &c) in row.iter().enumerate() {
                            out[brick_index([bx, by], i, j, k % BRICK)] = c;
                        }
                    }
                }
            });
        drop(classes);
        let mut grid = ClassGrid {
            dims,
            bricks: [bx, by],
            classes: bricked,
            interpolation,
            bias: TIE_BIAS / count.max(1) as f64,
            blocks,
            summary: Vec::new(),
        };
        grid.summary = grid.summarise();
        grid
    }

    fn summarise(&self) -> Vec<u32> {
        let [bx, by, bz] = self.blocks;
        (0..bx * by * bz)
            .into_par_iter()
            .with_min_len(64)
            .map(|b| {
                let (i, j, k) = (b % bx, (b / bx) % by, b / (bx * by));
                self.block_class([i, j, k])
            })
            .collect()
    }

    /// The one class of the voxels `B b ..= B (b + 1)` of block `b`, or [`MIXED`].
    fn block_class(&self, b: [usize; 3]) -> u32 {
        let range = |a: usize| {
            let lo = b[a] * BLOCK;
            lo..=(lo + BLOCK).min(self.dims[a] - 1)
        };
        let first = self.voxel(b[0] * BLOCK, b[1] * BLOCK, b[2] * BLOCK);
        // Blocks and bricks share their lower corner: a brick of several classes (most blocks
        // near the interfaces) is told by one compare of its 64 stored voxels.
        const { assert!(BLOCK == BRICK) };
        // Padding past the image is not the image's, so only a full brick decides alone.
        let full = (0..3).all(|a| (b[a] + 1) * BLOCK <= self.dims[a]);
        let lower = brick_index(self.bricks, b[0] * BLOCK, b[1] * BLOCK, b[2] * BLOCK);
        let brick = &self.classes[lower..lower + BRICK.pow(3)];
        if full && brick.iter().any(|&c| c != first) {
            return MIXED;
        }
        // Past a uniform full brick, only the block's upper faces are left to read.
        let upper = b.map(|v| v * BLOCK + BLOCK);
        for k in range(2) {
            for j in range(1) {
                let inside = full && j < upper[1] && k < upper[2];
                let mut row = range(0);
                if inside {
                    row = upper[0]..=upper[0];
                    if upper[0] >= self.dims[0] {
                        continue;
                    }
                }
                if row.any(|i| self.voxel(i, j, k) != first) {
                    return MIXED;
                }
            }
        }
        first.index()
    }

    /// The class of voxel `(i, j, k)`, which must be in the image.
    pub fn voxel(&self, i: usize, j: usize, k: usize) -> C {
        self.classes[brick_index(self.bricks, i, j, k)]
    }

    /// The index-space box where classes may be non-background: between the outer voxel centres
    /// (trilinear) or the outer voxel faces (nearest).
    pub fn domain_box(&self) -> (DVec3, DVec3) {
        let hi = DVec3::new(
            self.dims[0] as f64 - 1.0,
            self.dims[1] as f64 - 1.0,
            self.dims[2] as f64 - 1.0,
        );
        match self.interpolation {
            Interpolation::Trilinear => (DVec3::ZERO, hi),
            Interpolation::Nearest => (DVec3::splat(-0.5), hi + 0.5),
        }
    }

    /// The class at index-space point `q`; background outside [`Self::domain_box`].
    pub fn class_at(&self, q: DVec3) -> u32 {
        let (lo, hi) = self.domain_box();
        if !(q.cmpge(lo).all() && q.cmple(hi).all()) {
            return 0;
        }
        match self.interpolation {
            Interpolation::Nearest => {
                let r = (q + 0.5).floor();
                let i = |v: f64, n: usize| (v.max(0.0) as usize).min(n - 1);
                self.voxel(
                    i(r.x, self.dims[0]),
                    i(r.y, self.dims[1]),
                    i(r.z, self.dims[2]),
                )
                .index()
            }
            Interpolation::Trilinear => self.trilinear(q),
        }
    }

    /// CGAL's labellized trilinear interpolation at `q` (in the domain box).
    fn trilinear(&self, q: DVec3) -> u32 {
        let cell = self.cell_of(q);
        let f = q - DVec3::from_array(cell.map(|v| v as f64));
        self.pick(&self.cell_corners(cell), f)
    }

    /// The lower corner of the unit cell between voxel centres that holds `q`, clamped to the
    /// image (a point on the upper faces belongs to the last cell).
    pub fn cell_of(&self, q: DVec3) -> [usize; 3] {
        let c = |v: f64, n: usize| (v.floor().max(0.0) as usize).min(n.saturating_sub(2));
        [
            c(q.x, self.dims[0]),
            c(q.y, self.dims[1]),
            c(q.z, self.dims[2]),
        ]
    }

    /// The classes of the eight voxels around the unit cell with lower corner `cell`, x fastest
    /// (on an axis of one voxel, both ends are that voxel).
    pub fn cell_corners(&self, cell: [usize; 3]) -> [C; 8] {
        let up = |a: usize| (cell[a] + 1).min(self.dims[a] - 1);
        let (x, y, z) = ([cell[0], up(0)], [cell[1], up(1)], [cell[2], up(2)]);
        std::array::from_fn(|n| self.voxel(x[n & 1], y[(n >> 1) & 1], z[n >> 2]))
    }

    /// The class with the largest interpolated indicator at the fractional position `f` (each
    /// coordinate in [0, 1]) of a cell whose corners are `c`, slightly biased to higher classes so
    /// that interfaces avoid the exact ties of symmetric voxel patterns.
    pub fn pick(&self, c: &[C; 8], f: DVec3) -> u32 {
        if c.iter().all(|&v| v == c[0]) {
            return c[0].index();
        }
        let (fx, fy, fz) = (f.x, f.y, f.z);
        let w = [
            (1.0 - fx) * (1.0 - fy) * (1.0 - fz),
            fx * (1.0 - fy) * (1.0 - fz),
            (1.0 - fx) * fy * (1.0 - fz),
            fx * fy * (1.0 - fz),
            (1.0 - fx) * (1.0 - fy) * fz,
            fx * (1.0 - fy) * fz,
            (1.0 - fx) * fy * fz,
            fx * fy * fz,
        ];
        let mut best = (f64::NEG_INFINITY, u32::MAX);
        for (n, &cn) in c.iter().enumerate() {
            if c[..n].contains(&cn) {
                continue;
            }
            let class = cn.index();
            // The bias moves the interfaces off the level 1/2, where the saddles of binary
            // corner patterns lie: there two sheets of one label would touch at a point (a
            // pinch no mesh can follow).
            let total: f64 = (n..8).filter(|&m| c[m] == cn).map(|m| w[m]).sum::<f64>()
                + self.bias * f64::from(class);
            if total > best.0 || (total == best.0 && class < best.1) {
                best = (total, class);
            }
        }
        best.1
    }

    /// Blocks along each axis.
    pub fn blocks(&self) -> [usize; 3] {
        self.blocks
    }

    /// The block holding the unit cell with lower corner `cell`.
    pub fn cell_block(&self, cell: [usize; 3]) -> [usize; 3] {
        std::array::from_fn(|a| (cell[a] / BLOCK).min(self.blocks[a] - 1))
    }

    /// The summary of block `b` (its class or [`MIXED`]).
    pub fn block_summary(&self, b: [usize; 3]) -> u32 {
        let [bx, by, _] = self.blocks;
        self.summary[b[0] + bx * (b[1] + by * b[2])]
    }
}

/// Where voxel `(i, j, k)` is stored, given the bricks along x and y.
#[inline]
fn brick_index([bx, by]: [usize; 2], i: usize, j: usize, k: usize) -> usize {
    let brick = i / BRICK + bx * (j / BRICK + by * (k / BRICK));
    brick * BRICK.pow(3) + i % BRICK + BRICK * (j % BRICK + BRICK * (k % BRICK))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_block_of_one_class_has_that_class_everywhere() {
        let dims = [21, 18, 13];
        let c = DVec3::new(9.3, 8.1, 6.2);
        let classes: Vec<u8> = (0..dims[0] * dims[1] * dims[2])
            .map(|n| {
                let p = DVec3::new(
                    (n % dims[0]) as f64,
                    ((n / dims[0]) % dims[1]) as f64,
                    (n / (dims[0] * dims[1])) as f64,
                );
                u8::from((p - c).length() < 5.5) + u8::from(p.x > 15.0)
            })
            .collect();
        for interpolation in [Interpolation::Nearest, Interpolation::Trilinear] {
            let g = ClassGrid::new(dims, classes.clone(), 3, interpolation);
            let mut uniform = 0;
            for n in 0..20_000u32 {
                // A deterministic scatter over the image, faces included.
                let f = |k: u32, m: usize| ((n * k) % 997) as f64 / 996.0 * (m - 1) as f64;
                let q = DVec3::new(f(7, dims[0]), f(13, dims[1]), f(29, dims[2]));
                let b = g.cell_block(g.cell_of(q));
                let s = g.block_summary(b);
                if s != MIXED {
                    uniform += 1;
                    assert_eq!(s, g.class_at(q), "{q} in block {b:?}");
                }
            }
            assert!(uniform > 100);
        }
    }
}
