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

/// Largest reach recorded for a block (see [`ClassGrid::block`]), in blocks: 15 blocks
/// is 60 voxels, longer than most segments a refinement asks about.
const MAX_REACH: u8 = 16;

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
pub(crate) trait Class: Copy + Default + Eq + Send + Sync + 'static {
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
    /// Per block: [`MIXED`], or its only class (below 2¹⁶) with its reach (see
    /// [`ClassGrid::block`]) in the bits above: one load, one cache miss, gives both.
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
        let summary = grid.summarise();
        let reach = reaches(blocks, &summary);
        grid.summary = summary
            .iter()
            .zip(reach)
            .map(|(&s, r)| {
                if s == MIXED {
                    MIXED
                } else {
                    s | u32::from(r) << 16
                }
            })
            .collect();
        grid
    }

    fn summarise(&self) -> Vec<u32> {
        let [bx, by, bz] = self.blocks;
        let bricks = self.brick_classes();
        (0..bx * by * bz)
            .into_par_iter()
            .with_min_len(64)
            .map(|b| {
                let (i, j, k) = (b % bx, (b / bx) % by, b / (bx * by));
                self.block_class([i, j, k], &bricks)
            })
            .collect()
    }

    /// Per brick: the one class of its stored voxels (padding included), or [`MIXED`]. One
    /// class there is one class on the brick's image voxels.
    fn brick_classes(&self) -> Vec<u32> {
        self.classes
            .par_chunks(BRICK.pow(3))
            .with_min_len(64)
            .map(|brick| {
                let first = brick[0];
                if brick.iter().all(|&c| c == first) {
                    first.index()
                } else {
                    MIXED
                }
            })
            .collect()
    }

    /// The one class of the voxels `B b ..= B (b + 1)` of block `b`, or [`MIXED`]; `bricks` are
    /// the [`Self::brick_classes`]: when the (at most eight) bricks holding those voxels have one
    /// class, so does the block.
    fn block_class(&self, b: [usize; 3], bricks: &[u32]) -> u32 {
        let [nx, ny] = self.bricks;
        let nz = bricks.len() / (nx * ny);
        let (x, y, z) = (
            [b[0], (b[0] + 1).min(nx - 1)],
            [b[1], (b[1] + 1).min(ny - 1)],
            [b[2], (b[2] + 1).min(nz - 1)],
        );
        let own = bricks[x[0] + nx * (y[0] + ny * z[0])];
        if own != MIXED
            && (0..8).all(|n| bricks[x[n & 1] + nx * (y[(n >> 1) & 1] + ny * z[n >> 2])] == own)
        {
            return own;
        }
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

    /// CGAL's labellized trilinear interpolation at `q` (in the domain box). A cell's eight
    /// corners lie in its block's voxels, so a block of one class answers alone.
    fn trilinear(&self, q: DVec3) -> u32 {
        let cell = self.cell_of(q);
        if let (class, 1..) = self.block(self.cell_block(cell)) {
            return class;
        }
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
        // Inside one brick the corners are at fixed offsets from the lower one.
        if (0..3).all(|a| cell[a] % BRICK < BRICK - 1 && cell[a] + 1 < self.dims[a]) {
            let lower = brick_index(self.bricks, cell[0], cell[1], cell[2]);
            return std::array::from_fn(|n| {
                self.classes[lower + (n & 1) + BRICK * ((n >> 1) & 1) + BRICK * BRICK * (n >> 2)]
            });
        }
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
        self.block(b).0
    }

    /// The summary of block `b` and its reach: every block within Chebyshev distance
    /// `reach - 1` of `b` (in the grid) has `b`'s summary; 0 for a block of several classes.
    /// Segment walks cross such a cube of blocks in one step.
    pub fn block(&self, b: [usize; 3]) -> (u32, usize) {
        let [bx, by, _] = self.blocks;
        match self.summary[b[0] + bx * (b[1] + by * b[2])] {
            MIXED => (MIXED, 0),
            s => (s & 0xffff, (s >> 16) as usize),
        }
    }
}

/// The reach of every block (see [`ClassGrid::block`]), capped at [`MAX_REACH`].
///
/// A block whose 26 neighbours all share its class is *inner*; the others are *boundary*
/// blocks. An inner block at Chebyshev distance `D` from the nearest boundary block has its class
/// on every block within `D` (they are inner or neighbours of inner blocks, all chained to it),
/// so its reach is `D + 1`; a boundary block's class is sure only on itself (reach 1, or 0 when
/// mixed). The distance is the chessboard distance transform, one axis after the other:
/// `d(x) = min over y of max(|y - x|)` splits into nested minima of `max(|offset|, ·)`.
fn reaches(blocks: [usize; 3], summary: &[u32]) -> Vec<u8> {
    let [bx, by, bz] = blocks;
    let at = |i: usize, j: usize, k: usize| i + bx * (j + by * k);
    let cap = MAX_REACH - 1;
    // Distance 0 on boundary blocks, `cap` elsewhere.
    let mut dist: Vec<u8> = (0..bx * by * bz)
        .into_par_iter()
        .with_min_len(1024)
        .map(|n| {
            let (i, j, k) = (n % bx, (n / bx) % by, n / (bx * by));
            let s = summary[n];
            let around = |v: usize, m: usize| v.saturating_sub(1)..=(v + 1).min(m - 1);
            let inner = s != MIXED
                && around(k, bz).all(|k2| {
                    around(j, by).all(|j2| around(i, bx).all(|i2| summary[at(i2, j2, k2)] == s))
                });
            if inner { cap } else { 0 }
        })
        .collect();
    // Along x: two sweeps per row give the exact distance to the nearest boundary block.
    dist.par_chunks_mut(bx).for_each(|row| {
        for i in 1..bx {
            row[i] = row[i].min(row[i - 1].saturating_add(1));
        }
        for i in (0..bx.saturating_sub(1)).rev() {
            row[i] = row[i].min(row[i + 1].saturating_add(1));
        }
    });
    // Along y, then z: whole rows at a time, `min(max(|offset|, row at offset))`.
    let spread = |dist: &[u8], stride: usize, count: usize| -> Vec<u8> {
        let mut spread = dist.to_vec();
        spread.par_chunks_mut(bx).enumerate().for_each(|(r, out)| {
            let pos = (r * bx / stride) % count;
            for offset in 1..=usize::from(cap).min(count) {
                let o = offset as u8;
                let others = [pos.checked_sub(offset), Some(pos + offset)];
                for other in others.into_iter().flatten().filter(|&p| p < count) {
                    let row = &dist[r * bx + other * stride - pos * stride..][..bx];
                    for (d, &e) in out.iter_mut().zip(row) {
                        *d = (*d).min(e.max(o));
                    }
                }
            }
        });
        spread
    };
    let dist = spread(&dist, bx, by);
    let dist = spread(&dist, bx * by, bz);
    dist.iter()
        .zip(summary)
        .map(|(&d, &s)| if s == MIXED { 0 } else { d + 1 })
        .collect()
}

/// Where voxel `(i, j, k)` is stored, given the bricks along x and y.
#[inline]
fn brick_index([bx, by]: [usize; 2], i: usize, j: usize, k: usize) -> usize {
    let brick = i / BRICK + bx * (j / BRICK + by * (k / BRICK));
    brick * BRICK.pow(3) + i % BRICK + BRICK * (j % BRICK + BRICK * (k % BRICK))
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// An image of `dims` voxels, class 0 but for `count` balls at random, each of class 1 to
    /// `classes` and of radius `radius.0 + radius.1 * t` (t uniform in [0, 1)), later ones over
    /// earlier ones.
    pub(crate) fn random_balls(
        dims: [usize; 3],
        count: usize,
        radius: (f64, f64),
        classes: u8,
        rng: &mut delamesh_core::random::XorShift,
    ) -> Vec<u8> {
        let size = DVec3::from_array(dims.map(|n| n as f64));
        let mut out = vec![0u8; dims[0] * dims[1] * dims[2]];
        for _ in 0..count {
            let c = DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) * size;
            let r = radius.0 + radius.1 * rng.next_f64();
            let class = 1 + rng.below(usize::from(classes)) as u8;
            for (v, slot) in out.iter_mut().enumerate() {
                let p = DVec3::new(
                    (v % dims[0]) as f64,
                    ((v / dims[0]) % dims[1]) as f64,
                    (v / (dims[0] * dims[1])) as f64,
                );
                if (p - c).length() < r {
                    *slot = class;
                }
            }
        }
        out
    }

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

    /// On random images of blobs, every block's reach is exactly how far its class extends
    /// (capped): the Chebyshev distance to the nearest block of another summary, found by
    /// brute force.
    #[test]
    fn a_block_reach_is_the_distance_to_the_nearest_other_summary() {
        let mut rng = delamesh_core::random::XorShift::new(5);
        let dims = [97, 61, 45];
        let classes = random_balls(dims, 6, (2.0, 14.0), 2, &mut rng);
        let g = ClassGrid::new(dims, classes, 3, Interpolation::Trilinear);
        let [bx, by, bz] = g.blocks();
        let (mut far, mut mixed) = (0, 0);
        for k in 0..bz {
            for j in 0..by {
                for i in 0..bx {
                    let s = g.block_summary([i, j, k]);
                    let reach = g.block([i, j, k]).1;
                    if s == MIXED {
                        assert_eq!(reach, 0);
                        mixed += 1;
                        continue;
                    }
                    let mut nearest = usize::from(MAX_REACH);
                    for k2 in 0..bz {
                        for j2 in 0..by {
                            for i2 in 0..bx {
                                if g.block_summary([i2, j2, k2]) != s {
                                    let d = i.abs_diff(i2).max(j.abs_diff(j2)).max(k.abs_diff(k2));
                                    nearest = nearest.min(d);
                                }
                            }
                        }
                    }
                    assert_eq!(reach, nearest, "block {:?}", [i, j, k]);
                    far += usize::from(reach > 3);
                }
            }
        }
        assert!(far > 100 && mixed > 100, "{far} far, {mixed} mixed");
    }
}
