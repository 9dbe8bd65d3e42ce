//! A background tetrahedral mesh with a size at every node.

use super::{SizingError, SizingField, check_count, check_value, show};
use crate::kernel::Point3;
use rstar::RTree;
use rstar::primitives::GeomWithData;
use std::sync::atomic::{AtomicU32, Ordering};

type Node = GeomWithData<[f64; 3], u32>;

/// Barycentric coordinates may be this much below zero (relative) and still count as inside:
/// points on a shared face belong to both tets, whichever is found first.
const INSIDE_TOLERANCE: f64 = 1e-9;

/// Barycentric coordinates above this are inside the last tet found and no other (unless a
/// neighbour is a thousand times larger): there the cached tet answers.
const STRICTLY_INSIDE: f64 = 1e-6;

/// Six times the signed volume of a tet.
fn volume([a, b, c, d]: &[Point3; 4]) -> f64 {
    (b - a).dot((c - a).cross(d - a))
}

/// Sizes at the nodes of a tetrahedral mesh: linear interpolation in the tet containing the
/// point (the first, by index, of the tets listed in the point's bucket of a uniform grid), the
/// nearest node's value outside every tet (through an R*-tree of the nodes). Flat tets are never
/// "containing": their neighbours or the nearest node answer. A bucket grid rather than a tree
/// of tet boxes: refinement asks millions of times, and a bucket costs one division per axis.
pub struct BackgroundMesh {
    positions: Vec<Point3>,
    tets: Vec<[u32; 4]>,
    values: Vec<f64>,
    buckets: Buckets,
    /// Six times each tet's signed volume.
    volumes: Vec<f64>,
    nodes: RTree<Node>,
    smallest: f64,
    /// The tet the last located point was in: refinement asks about points near each other
    /// one after another, and most fall in the same tet.
    last: AtomicU32,
}

impl BackgroundMesh {
    /// A background mesh; refuses a value count other than the node count, a value that is not
    /// finite and positive (naming its node), a tet naming a missing node, and a mesh without
    /// tets.
    pub fn new(
        positions: Vec<Point3>,
        tets: Vec<[u32; 4]>,
        values: Vec<f64>,
    ) -> Result<BackgroundMesh, SizingError> {
        check_count(values.len(), positions.len(), "nodes")?;
        if tets.is_empty() {
            return Err(SizingError("no tetrahedra".into()));
        }
        for (n, &v) in values.iter().enumerate() {
            check_value(v, || format!("node {n} {}", show(positions[n])))?;
        }
        let mut boxes: Vec<(Point3, Point3)> = Vec::with_capacity(tets.len());
        for (t, tet) in tets.iter().enumerate() {
            let mut corners = [Point3::ZERO; 4];
            for (c, &v) in corners.iter_mut().zip(tet) {
                *c = *positions.get(v as usize).ok_or_else(|| {
                    SizingError(format!(
                        "tetrahedron {t} names node {v}, there are {}",
                        positions.len()
                    ))
                })?;
            }
            let lo = corners.iter().fold(corners[0], |a, &b| a.min(b));
            let hi = corners.iter().fold(corners[0], |a, &b| a.max(b));
            boxes.push((lo, hi));
        }
        let nodes = positions
            .iter()
            .enumerate()
            .map(|(n, p)| GeomWithData::new(p.to_array(), n as u32))
            .collect();
        let smallest = values.iter().copied().fold(f64::INFINITY, f64::min);
        Ok(BackgroundMesh {
            buckets: Buckets::new(&boxes),
            volumes: tets
                .iter()
                .map(|t| volume(&t.map(|v| positions[v as usize])))
                .collect(),
            nodes: RTree::bulk_load(nodes),
            positions,
            tets,
            values,
            smallest,
            last: AtomicU32::new(0),
        })
    }

    /// The barycentric coordinates of `p` in tet `t`, if it contains `p`.
    fn barycentric(&self, t: u32, p: Point3) -> Option<[f64; 4]> {
        let total = self.volumes[t as usize];
        if total == 0.0 || !total.is_finite() {
            return None;
        }
        let [a, b, c, d] = self.tets[t as usize].map(|v| self.positions[v as usize]);
        // One coordinate at a time: most candidates fail on the first or second.
        let mut l = [0.0; 4];
        for (k, corners) in [[p, b, c, d], [a, p, c, d], [a, b, p, d]]
            .iter()
            .enumerate()
        {
            l[k] = volume(corners) / total;
            if l[k] < -INSIDE_TOLERANCE {
                return None;
            }
        }
        l[3] = 1.0 - l[0] - l[1] - l[2];
        (l[3] >= -INSIDE_TOLERANCE).then_some(l)
    }

    /// The containing tet and the coordinates of `p` in it. The last tet found answers first
    /// when `p` lies strictly inside it ([`STRICTLY_INSIDE`]: no other tet of a valid mesh
    /// contains `p`, so the answer does not depend on the order of the queries, from several
    /// threads or not);
    /// otherwise the first containing tet by index.
    fn locate(&self, p: Point3) -> Option<(u32, [f64; 4])> {
        let last = self.last.load(Ordering::Relaxed);
        if let Some(l) = self.barycentric(last, p)
            && l.iter().all(|&c| c > STRICTLY_INSIDE)
        {
            return Some((last, l));
        }
        let found = self
            .buckets
            .tets_near(p)
            .iter()
            .find_map(|&t| self.barycentric(t, p).map(|l| (t, l)));
        if let Some((t, _)) = found {
            self.last.store(t, Ordering::Relaxed);
        }
        found
    }

    /// Whether some tet contains `p`.
    pub fn covers(&self, p: Point3) -> bool {
        self.locate(p).is_some()
    }

    /// Whether some tet's bounding box lies within `tolerance` of `p`: the check that the mesh
    /// covers a domain up to the gap between a curved surface and its chords.
    pub fn near(&self, p: Point3, tolerance: f64) -> bool {
        self.buckets
            .tets_around(p, tolerance)
            .any(|t| self.box_distance(t, p) <= tolerance)
    }

    fn box_distance(&self, t: u32, p: Point3) -> f64 {
        let corners = self.tets[t as usize].map(|v| self.positions[v as usize]);
        let lo = corners.iter().fold(corners[0], |a, &b| a.min(b));
        let hi = corners.iter().fold(corners[0], |a, &b| a.max(b));
        (lo - p).max(p - hi).max(Point3::ZERO).length()
    }

    /// The value at `p` (see the type's documentation).
    pub fn at(&self, p: Point3) -> f64 {
        if let Some((t, l)) = self.locate(p) {
            let tet = self.tets[t as usize];
            return (0..4).map(|k| l[k] * self.values[tet[k] as usize]).sum();
        }
        match self.nodes.nearest_neighbor(p.to_array()) {
            Some(n) => self.values[n.data as usize],
            None => self.smallest,
        }
    }
}

/// At most this many buckets (4 M): 16 MB of list starts.
const MAX_BUCKETS: u64 = 1 << 22;

/// Tets listed by the cells of a uniform grid their bounding boxes overlap.
struct Buckets {
    origin: Point3,
    /// 1 / the cells' side.
    scale: f64,
    dims: [usize; 3],
    /// Bucket `b` lists `items[start[b]..start[b + 1]]`, in increasing tet order.
    start: Vec<u32>,
    items: Vec<u32>,
}

impl Buckets {
    /// About one bucket per tet; coarser when big tets would be listed in too many buckets, so
    /// the lists stay within a few entries per tet.
    fn new(boxes: &[(Point3, Point3)]) -> Buckets {
        let lo = boxes
            .iter()
            .fold(Point3::splat(f64::INFINITY), |a, b| a.min(b.0));
        let hi = boxes
            .iter()
            .fold(Point3::splat(f64::NEG_INFINITY), |a, b| a.max(b.1));
        let extent = (hi - lo).max(Point3::splat(f64::MIN_POSITIVE));
        let target = (boxes.len() as f64).clamp(1.0, MAX_BUCKETS as f64);
        let base = (extent.x * extent.y * extent.z / target).cbrt();
        // The side among a few around one bucket per tet with the shortest lists on average
        // (what a query scans), within a memory bound: counting costs one pass per side.
        let mut best = (f64::INFINITY, extent.max_element());
        for k in -4..=4 {
            let side = (base * 2f64.powf(f64::from(k) / 2.0)).max(extent.max_element() / 4096.0);
            let dims = Buckets::dims_for(extent, side);
            let buckets = dims.iter().map(|&d| d as u64).product::<u64>();
            if buckets > MAX_BUCKETS {
                continue;
            }
            let items: u64 = boxes
                .iter()
                .map(|b| {
                    Buckets::range(b, lo, 1.0 / side, dims)
                        .iter()
                        .map(|(a, z)| (z - a + 1) as u64)
                        .product::<u64>()
                })
                .sum();
            let mean = items as f64 / buckets as f64;
            if items <= 32 * boxes.len() as u64 + buckets && mean < best.0 {
                best = (mean, side);
            }
        }
        Buckets::with_side(boxes, lo, extent, best.1)
    }

    fn dims_for(extent: Point3, side: f64) -> [usize; 3] {
        extent
            .to_array()
            .map(|e| ((e / side).floor() as usize + 1).max(1))
    }

    /// The buckets a box overlaps, per axis (first, last).
    fn range(
        b: &(Point3, Point3),
        origin: Point3,
        scale: f64,
        dims: [usize; 3],
    ) -> [(usize, usize); 3] {
        let a = ((b.0 - origin) * scale).to_array();
        let z = ((b.1 - origin) * scale).to_array();
        [0, 1, 2].map(|k| {
            let clamp = |x: f64| (x.max(0.0) as usize).min(dims[k] - 1);
            (clamp(a[k]), clamp(z[k]))
        })
    }

    fn with_side(boxes: &[(Point3, Point3)], origin: Point3, extent: Point3, side: f64) -> Buckets {
        let dims = Buckets::dims_for(extent, side);
        let scale = 1.0 / side;
        let n = dims[0] * dims[1] * dims[2];
        let range = |b: &(Point3, Point3)| Buckets::range(b, origin, scale, dims);
        let mut count = vec![0u32; n + 1];
        let visit = |t: usize, f: &mut dyn FnMut(usize, u32)| {
            let [(i0, i1), (j0, j1), (k0, k1)] = range(&boxes[t]);
            for k in k0..=k1 {
                for j in j0..=j1 {
                    for i in i0..=i1 {
                        f(i + dims[0] * (j + dims[1] * k), t as u32);
                    }
                }
            }
        };
        for t in 0..boxes.len() {
            visit(t, &mut |b, _| count[b + 1] += 1);
        }
        for b in 0..n {
            count[b + 1] += count[b];
        }
        let mut items = vec![0u32; count[n] as usize];
        let mut fill = count.clone();
        for t in 0..boxes.len() {
            visit(t, &mut |b, t| {
                items[fill[b] as usize] = t;
                fill[b] += 1;
            });
        }
        Buckets {
            origin,
            scale,
            dims,
            start: count,
            items,
        }
    }

    /// The tets listed in the buckets within `r` of `p` (with repeats).
    fn tets_around(&self, p: Point3, r: f64) -> impl Iterator<Item = u32> + '_ {
        let lo = ((p - Point3::splat(r) - self.origin) * self.scale).to_array();
        let hi = ((p + Point3::splat(r) - self.origin) * self.scale).to_array();
        let span = [0, 1, 2].map(|k| {
            let clamp = |x: f64| (x.max(0.0) as usize).min(self.dims[k] - 1);
            let outside = hi[k] < 0.0 || lo[k] > self.dims[k] as f64;
            (
                clamp(lo[k]),
                if outside { 0 } else { clamp(hi[k]) + 1 },
                outside,
            )
        });
        let empty = span.iter().any(|s| s.2);
        let [(i0, i1, _), (j0, j1, _), (k0, k1, _)] = span;
        let (ni, nj) = (self.dims[0], self.dims[1]);
        (k0..if empty { k0 } else { k1 })
            .flat_map(move |k| {
                (j0..j1).flat_map(move |j| (i0..i1).map(move |i| i + ni * (j + nj * k)))
            })
            .flat_map(move |b| {
                self.items[self.start[b] as usize..self.start[b + 1] as usize]
                    .iter()
                    .copied()
            })
    }

    /// The tets whose boxes may contain `p` (none outside the grid).
    fn tets_near(&self, p: Point3) -> &[u32] {
        let q = ((p - self.origin) * self.scale).to_array();
        let mut b = 0;
        for k in (0..3).rev() {
            if !(q[k] >= 0.0 && q[k] < self.dims[k] as f64 + 1e-9) {
                return &[];
            }
            b = b * self.dims[k] + (q[k] as usize).min(self.dims[k] - 1);
        }
        &self.items[self.start[b] as usize..self.start[b + 1] as usize]
    }
}

impl SizingField for BackgroundMesh {
    fn size_at(&self, p: Point3, _label: u32) -> f64 {
        self.at(p)
    }
    fn smallest(&self) -> Option<f64> {
        Some(self.smallest)
    }
}
