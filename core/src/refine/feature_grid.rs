//! A uniform grid over the feature curves and corners, for the protection's nearest-feature
//! queries: each ball radius asks how far the other features are, and on a part with a thousand
//! curves scanning all of them for every radius made the protection quadratic.

use crate::kernel::Point3;

/// Most cells along one axis.
const MAX_CELLS_PER_AXIS: usize = 64;
/// A segment whose box covers more cells than this is listed apart, for every query.
const MAX_CELLS_PER_SEGMENT: usize = 512;
/// A query covering more cells than this, or than there are features, gets every feature
/// (visiting the cells would cost more).
const MAX_CELLS_PER_QUERY: usize = 4096;

/// Curves (as polylines, by index) and corners (as points, by index) registered in the cells
/// their segments' boxes overlap.
pub(crate) struct FeatureGrid {
    origin: Point3,
    cell: f64,
    dims: [usize; 3],
    /// Compressed rows: the items of cell `c` are `items[starts[c]..starts[c + 1]]`.
    starts: Vec<u32>,
    items: Vec<Item>,
    /// Curves with a segment too long to register: candidates of every query.
    everywhere: Vec<u32>,
    curves: usize,
    corners: usize,
}

/// What a cell holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(crate) enum Item {
    Corner(u32),
    Curve(u32),
}

impl FeatureGrid {
    /// The grid of `curves` (each the points of a polyline, closed when its flag says so) and
    /// `corners`.
    pub(crate) fn new<'a>(
        curves: impl IntoIterator<Item = (&'a [Point3], bool)> + Clone,
        corners: &[Point3],
    ) -> Self {
        let all = curves
            .clone()
            .into_iter()
            .flat_map(|(points, _)| points.iter())
            .chain(corners);
        let (lo, hi) = all.fold(
            (
                Point3::splat(f64::INFINITY),
                Point3::splat(f64::NEG_INFINITY),
            ),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let extent = (hi - lo).max_element();
        let cell = if extent.is_finite() && extent > 0.0 {
            extent / MAX_CELLS_PER_AXIS as f64
        } else {
            1.0
        };
        let origin = if lo.is_finite() { lo } else { Point3::ZERO };
        let mut grid = FeatureGrid {
            origin,
            cell,
            dims: [1; 3],
            starts: Vec::new(),
            items: Vec::new(),
            everywhere: Vec::new(),
            curves: 0,
            corners: corners.len(),
        };
        grid.dims = [0, 1, 2].map(|a| {
            let n = ((hi[a] - origin[a]) / cell).floor();
            if n.is_finite() && n >= 0.0 {
                (n as usize + 1).min(MAX_CELLS_PER_AXIS)
            } else {
                1
            }
        });
        // (cell, item) pairs, then sorted into rows.
        let mut pairs: Vec<(u32, Item)> = Vec::new();
        for (k, (points, closed)) in curves.into_iter().enumerate() {
            grid.curves = k + 1;
            let n = points.len();
            let segments = if closed { n } else { n.saturating_sub(1) };
            let mut cells = Vec::new();
            let mut long = false;
            for i in 0..segments {
                let (a, b) = (points[i], points[(i + 1) % n]);
                let range = grid.cell_range(a.min(b), a.max(b));
                if range.iter().map(|r| r.1 - r.0 + 1).product::<usize>() > MAX_CELLS_PER_SEGMENT {
                    long = true;
                    break;
                }
                grid.for_cells(range, |c| cells.push(c));
            }
            if long || n == 1 {
                grid.everywhere.push(k as u32);
                continue;
            }
            cells.sort_unstable();
            cells.dedup();
            pairs.extend(cells.into_iter().map(|c| (c, Item::Curve(k as u32))));
        }
        for (k, &p) in corners.iter().enumerate() {
            grid.for_cells(grid.cell_range(p, p), |c| {
                pairs.push((c, Item::Corner(k as u32)))
            });
        }
        pairs.sort_unstable();
        let count = grid.dims.iter().product::<usize>();
        grid.starts = vec![0; count + 1];
        for &(c, _) in &pairs {
            grid.starts[c as usize + 1] += 1;
        }
        for c in 0..count {
            grid.starts[c + 1] += grid.starts[c];
        }
        grid.items = pairs.into_iter().map(|(_, item)| item).collect();
        grid
    }

    /// The cell index range along each axis of the box `[lo, hi]`, clamped to the grid.
    fn cell_range(&self, lo: Point3, hi: Point3) -> [(usize, usize); 3] {
        [0, 1, 2].map(|a| {
            let index = |x: f64| {
                let t = ((x - self.origin[a]) / self.cell).floor();
                if t.is_nan() || t < 0.0 {
                    0
                } else {
                    (t as usize).min(self.dims[a] - 1)
                }
            };
            (index(lo[a]), index(hi[a]))
        })
    }

    fn for_cells(&self, range: [(usize, usize); 3], mut f: impl FnMut(u32)) {
        let [(x0, x1), (y0, y1), (z0, z1)] = range;
        for z in z0..=z1 {
            for y in y0..=y1 {
                for x in x0..=x1 {
                    f(((z * self.dims[1] + y) * self.dims[0] + x) as u32);
                }
            }
        }
    }

    /// The curves and corners that may come within `radius` of `p`, each once, in increasing
    /// order (a superset: every feature nearer than `radius` is among them).
    pub(crate) fn near(&self, p: Point3, radius: f64) -> Vec<Item> {
        let r = Point3::splat(radius);
        let range = self.cell_range(p - r, p + r);
        if !radius.is_finite()
            || range.iter().map(|r| r.1 - r.0 + 1).product::<usize>()
                > MAX_CELLS_PER_QUERY.min(self.corners + self.curves)
        {
            let corners = (0..self.corners as u32).map(Item::Corner);
            return corners
                .chain((0..self.curves as u32).map(Item::Curve))
                .collect();
        }
        let mut out: Vec<Item> = self.everywhere.iter().map(|&k| Item::Curve(k)).collect();
        self.for_cells(range, |c| {
            let (a, b) = (self.starts[c as usize], self.starts[c as usize + 1]);
            out.extend_from_slice(&self.items[a as usize..b as usize]);
        });
        out.sort_unstable();
        out.dedup();
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::XorShift;

    /// Every curve and corner within the radius is a candidate, whatever the query.
    #[test]
    fn near_features_are_never_missed() {
        let mut rng = XorShift::new(0x9e37_79b9_7f4a_7c15);
        let mut unit = move || rng.next_f64();
        let curves: Vec<Vec<Point3>> = (0..40)
            .map(|_| {
                let start = Point3::new(unit(), unit(), unit()) * 10.0;
                let step = Point3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5);
                (0..5).map(|k| start + step * k as f64).collect()
            })
            .chain(std::iter::once(vec![Point3::ZERO, Point3::splat(10.0)]))
            .collect();
        let corners: Vec<Point3> = (0..30)
            .map(|_| Point3::new(unit(), unit(), unit()) * 10.0)
            .collect();
        let grid = FeatureGrid::new(curves.iter().map(|c| (c.as_slice(), false)), &corners);
        for _ in 0..300 {
            let p = Point3::new(unit(), unit(), unit()) * 12.0 - Point3::ONE;
            let radius = unit() * 3.0;
            let near = grid.near(p, radius);
            for (k, c) in curves.iter().enumerate() {
                let d = c
                    .windows(2)
                    .map(|w| crate::refine::curves::point_segment_distance(p, w[0], w[1]))
                    .fold(f64::INFINITY, f64::min);
                if d < radius {
                    assert!(near.contains(&Item::Curve(k as u32)), "curve {k} missed");
                }
            }
            for (k, &c) in corners.iter().enumerate() {
                if c.distance(p) < radius {
                    assert!(near.contains(&Item::Corner(k as u32)), "corner {k} missed");
                }
            }
        }
    }
}
