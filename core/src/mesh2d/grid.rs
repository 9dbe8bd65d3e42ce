//! A uniform bucket grid over points, for the "which points lie in this disk" queries of the
//! constraint algorithms (Pébay's implementation used the same bucket sort).

use glam::DVec2;

#[derive(Debug, Clone)]
pub(crate) struct PointGrid {
    origin: DVec2,
    inv_cell: f64,
    dims: (usize, usize),
    buckets: Vec<Vec<u32>>,
}

impl PointGrid {
    /// A grid over the box `[lo, hi]` sized for about `n` points (points outside are clamped in).
    pub(crate) fn new(lo: DVec2, hi: DVec2, n: usize) -> Self {
        let ext = (hi - lo).max(DVec2::splat(f64::MIN_POSITIVE));
        let cells = (n.max(1) as f64).sqrt().clamp(1.0, 2048.0);
        let side = ext.max_element() / cells;
        let side = if side > 0.0 { side } else { 1.0 };
        let dims = (
            ((ext.x / side).ceil() as usize).clamp(1, 4096),
            ((ext.y / side).ceil() as usize).clamp(1, 4096),
        );
        Self {
            origin: lo,
            inv_cell: 1.0 / side,
            dims,
            buckets: vec![Vec::new(); dims.0 * dims.1],
        }
    }

    fn cell_of(&self, p: DVec2) -> (usize, usize) {
        let g = (p - self.origin) * self.inv_cell;
        let clamp = |v: f64, n: usize| {
            if v.is_nan() {
                0
            } else {
                (v.max(0.0) as usize).min(n - 1)
            }
        };
        (clamp(g.x, self.dims.0), clamp(g.y, self.dims.1))
    }

    pub(crate) fn insert(&mut self, p: DVec2, id: u32) {
        let (i, j) = self.cell_of(p);
        self.buckets[j * self.dims.0 + i].push(id);
    }

    /// Every stored id whose bucket meets the box `[lo, hi]` (a superset of the points inside it),
    /// in increasing order.
    pub(crate) fn candidates(&self, lo: DVec2, hi: DVec2, out: &mut Vec<u32>) {
        self.candidates_unordered(lo, hi, out);
        out.sort_unstable();
    }

    /// [`Self::candidates`] in bucket order, for callers that do not need the sort.
    pub(crate) fn candidates_unordered(&self, lo: DVec2, hi: DVec2, out: &mut Vec<u32>) {
        out.clear();
        let (i0, j0) = self.cell_of(lo);
        let (i1, j1) = self.cell_of(hi);
        for j in j0..=j1 {
            for i in i0..=i1 {
                out.extend_from_slice(&self.buckets[j * self.dims.0 + i]);
            }
        }
    }
}
