//! The voxel classes of an image and the class of any point of index space, with a coarse grid of
//! blocks that records where the class cannot change, so that segment walks skip them.
//!
//! Index space puts voxel `(i, j, k)`'s centre at the integer point `(i, j, k)`. A class is the rank
//! of a label among the image's labels; class 0 is the background (outside).

use glam::DVec3;
use rayon::prelude::*;

/// Voxels per block edge. A block `b` covers the closed index box `[B b, B (b + 1)]` on each axis,
/// so its region is decided by the voxels `B b ..= B (b + 1)` alone, for both interpolations.
pub(crate) const BLOCK: usize = 8;
/// Block summary of a block whose voxels have several classes.
pub(crate) const MIXED: u32 = u32::MAX;

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

/// Voxel classes in x-fastest order, and a summary per block.
pub(crate) struct ClassGrid<C> {
    pub dims: [usize; 3],
    classes: Vec<C>,
    pub interpolation: Interpolation,
    blocks: [usize; 3],
    /// Per block: its only class, or [`MIXED`].
    summary: Vec<u32>,
}

impl<C: Class> ClassGrid<C> {
    pub fn new(dims: [usize; 3], classes: Vec<C>, interpolation: Interpolation) -> Self {
        let blocks = dims.map(|n| (n.saturating_sub(1)).div_ceil(BLOCK).max(1));
        let mut grid = ClassGrid {
            dims,
            classes,
            interpolation,
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
            let lo = a * BLOCK;
            lo..=(lo + BLOCK).min(self.dims[a] - 1)
        };
        let first = self.voxel(b[0] * BLOCK, b[1] * BLOCK, b[2] * BLOCK);
        let [nx, ny, _] = self.dims;
        for k in range(2) {
            for j in range(1) {
                let row = nx * (j + ny * k);
                let xs = range(0);
                let (lo, hi) = (*xs.start() + row, *xs.end() + row);
                if self.classes[lo..=hi].iter().any(|&c| c != first) {
                    return MIXED;
                }
            }
        }
        first.index()
    }

    /// The class of voxel `(i, j, k)`, which must be in the image.
    pub fn voxel(&self, i: usize, j: usize, k: usize) -> C {
        let [nx, ny, _] = self.dims;
        self.classes[i + nx * (j + ny * k)]
    }

    /// The class of voxel `(i, j, k)` as an index, background outside the image.
    pub fn voxel_or_background(&self, i: i64, j: i64, k: i64) -> u32 {
        let inside = |v: i64, n: usize| v >= 0 && (v as usize) < n;
        if inside(i, self.dims[0]) && inside(j, self.dims[1]) && inside(k, self.dims[2]) {
            self.voxel(i as usize, j as usize, k as usize).index()
        } else {
            0
        }
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
                self.voxel(i(r.x, self.dims[0]), i(r.y, self.dims[1]), i(r.z, self.dims[2]))
                    .index()
            }
            Interpolation::Trilinear => self.trilinear(q),
        }
    }

    /// CGAL's labellized trilinear interpolation: the class with the largest interpolated
    /// indicator among the eight voxels around `q` (ties to the smaller class).
    fn trilinear(&self, q: DVec3) -> u32 {
        let corner = |v: f64, n: usize| -> (usize, usize, f64) {
            if n == 1 {
                return (0, 0, 0.0);
            }
            let i = (v.floor().max(0.0) as usize).min(n - 2);
            (i, i + 1, v - i as f64)
        };
        let (x0, x1, fx) = corner(q.x, self.dims[0]);
        let (y0, y1, fy) = corner(q.y, self.dims[1]);
        let (z0, z1, fz) = corner(q.z, self.dims[2]);
        let c = [
            self.voxel(x0, y0, z0),
            self.voxel(x1, y0, z0),
            self.voxel(x0, y1, z0),
            self.voxel(x1, y1, z0),
            self.voxel(x0, y0, z1),
            self.voxel(x1, y0, z1),
            self.voxel(x0, y1, z1),
            self.voxel(x1, y1, z1),
        ];
        if c.iter().all(|&v| v == c[0]) {
            return c[0].index();
        }
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
            let total: f64 = (n..8).filter(|&m| c[m] == cn).map(|m| w[m]).sum();
            let label = cn.index();
            if total > best.0 || (total == best.0 && label < best.1) {
                best = (total, label);
            }
        }
        best.1
    }

    /// Blocks along each axis.
    pub fn blocks(&self) -> [usize; 3] {
        self.blocks
    }

    /// The summary of block `b` (its class or [`MIXED`]).
    pub fn block_summary(&self, b: [usize; 3]) -> u32 {
        let [bx, by, _] = self.blocks;
        self.summary[b[0] + bx * (b[1] + by * b[2])]
    }

    /// The block whose closed index box contains `q` (clamped to the grid), and whether `q` lies
    /// inside the region blocks describe (between the outer voxel centres).
    pub fn block_of(&self, q: DVec3) -> Option<[usize; 3]> {
        let hi = DVec3::new(
            self.dims[0] as f64 - 1.0,
            self.dims[1] as f64 - 1.0,
            self.dims[2] as f64 - 1.0,
        );
        if !(q.cmpge(DVec3::ZERO).all() && q.cmple(hi).all()) {
            return None;
        }
        let b = |v: f64, a: usize| ((v / BLOCK as f64) as usize).min(self.blocks[a] - 1);
        Some([b(q.x, 0), b(q.y, 1), b(q.z, 2)])
    }
}
