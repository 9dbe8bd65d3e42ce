//! The planar straight-line graph: points, constraint segments, holes and regional attributes
//! (the content of Triangle's `.poly` files), and its validation (Pébay's Def. 1.5).

use super::grid::PointGrid;
use crate::triangulation::delaunay2::predicates::{lex_cmp, orient2d};
use glam::DVec2;
use std::cmp::Ordering;

/// A region seed: the connected part of the domain containing `point` gets `attribute`, and an
/// optional area bound of its own.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    /// A point inside the region.
    pub point: DVec2,
    /// The attribute its triangles get.
    pub attribute: f64,
    /// An area bound for its triangles, tighter than the global one.
    pub max_area: Option<f64>,
}

/// Points, segments between them (indices into `points`), hole seeds and region seeds.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Pslg {
    /// The vertices.
    pub points: Vec<DVec2>,
    /// Segments the triangulation must keep, as pairs of point indices.
    pub segments: Vec<[u32; 2]>,
    /// Boundary marker of each segment (0 when the input gives none).
    pub segment_markers: Vec<i32>,
    /// Points inside holes: the part of the domain around each is removed.
    pub holes: Vec<DVec2>,
    /// Region seeds.
    pub regions: Vec<Region>,
}

/// Why a PSLG is not a valid constraint field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum PslgError {
    #[error("point {0} has a non-finite coordinate")]
    NonFinite(usize),
    #[error("points {0} and {1} coincide")]
    DuplicatePoint(usize, usize),
    #[error("segment {0} names point {1}, but there are only {2} points")]
    BadIndex(usize, u32, usize),
    #[error("segment {0} has both ends at point {1}")]
    Degenerate(usize, u32),
    #[error("segments {0} and {1} join the same two points")]
    DuplicateSegment(usize, usize),
    #[error("point {1} lies inside segment {0}")]
    PointOnSegment(usize, usize),
    #[error("segments {0} and {1} cross")]
    Crossing(usize, usize),
}

impl Pslg {
    /// Bounding box of the points (`None` when there are none).
    pub fn bounds(&self) -> Option<(DVec2, DVec2)> {
        let first = *self.points.first()?;
        Some(
            self.points
                .iter()
                .fold((first, first), |(lo, hi), &p| (lo.min(p), hi.max(p))),
        )
    }

    /// Checks Def. 1.5: distinct finite points, segments between two distinct existing points, no
    /// point inside a segment, segments meeting only at shared endpoints.
    pub fn validate(&self) -> Result<(), PslgError> {
        let n = self.points.len();
        if let Some(i) = self.points.iter().position(|p| !p.is_finite()) {
            return Err(PslgError::NonFinite(i));
        }
        // The integer image of `f64::total_cmp`, so that the sort compares plain integers.
        let total_key = |x: f64| {
            let bits = x.to_bits() as i64;
            bits ^ (((bits >> 63) as u64) >> 1) as i64
        };
        let mut order: Vec<(i64, i64, usize)> = (self.points.iter().enumerate())
            .map(|(i, p)| (total_key(p.x), total_key(p.y), i))
            .collect();
        order.sort_unstable();
        for w in order.windows(2) {
            let (i, j) = (w[0].2, w[1].2);
            if self.points[i] == self.points[j] {
                return Err(PslgError::DuplicatePoint(i, j));
            }
        }
        let mut keys = Vec::with_capacity(self.segments.len());
        for (s, &[a, b]) in self.segments.iter().enumerate() {
            for v in [a, b] {
                if v as usize >= n {
                    return Err(PslgError::BadIndex(s, v, n));
                }
            }
            if a == b {
                return Err(PslgError::Degenerate(s, a));
            }
            keys.push(((a.min(b), a.max(b)), s));
        }
        keys.sort_unstable();
        for w in keys.windows(2) {
            if w[0].0 == w[1].0 {
                return Err(PslgError::DuplicateSegment(w[0].1, w[1].1));
            }
        }
        let Some((lo, hi)) = self.bounds() else {
            return Ok(());
        };
        self.check_points_off_segments(lo, hi)?;
        self.check_crossings(lo, hi)
    }

    fn segment(&self, s: usize) -> (DVec2, DVec2) {
        let [a, b] = self.segments[s];
        (self.points[a as usize], self.points[b as usize])
    }

    /// Bounding box of segment `s`, as (min corner, max corner).
    fn segment_box(&self, s: usize) -> (DVec2, DVec2) {
        let (a, b) = self.segment(s);
        (a.min(b), a.max(b))
    }

    fn check_points_off_segments(&self, lo: DVec2, hi: DVec2) -> Result<(), PslgError> {
        let mut grid = PointGrid::new(lo, hi, self.points.len());
        for (i, &p) in self.points.iter().enumerate() {
            grid.insert(p, i as u32);
        }
        let mut cand = Vec::new();
        for s in 0..self.segments.len() {
            let (a, b) = self.segment(s);
            let (lo, hi) = (a.min(b), a.max(b));
            grid.candidates_unordered(lo, hi, &mut cand);
            // The smallest index on the segment, as a sorted scan would report first.
            let on_segment = cand
                .iter()
                .copied()
                .filter(|&i| {
                    let p = self.points[i as usize];
                    // Only points inside the segment's box can lie on it: skip the rest cheaply.
                    p.cmpge(lo).all()
                        && p.cmple(hi).all()
                        && orient2d(a, b, p) == Ordering::Equal
                        && lex_cmp(a, p) == lex_cmp(p, b)
                        && lex_cmp(a, p) != Ordering::Equal
                })
                .min();
            if let Some(i) = on_segment {
                return Err(PslgError::PointOnSegment(s, i as usize));
            }
        }
        Ok(())
    }

    /// Proper crossings, found by bucketing segment bounding boxes on a uniform grid.
    fn check_crossings(&self, lo: DVec2, hi: DVec2) -> Result<(), PslgError> {
        let m = self.segments.len();
        let ext = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let k = ((m as f64).sqrt().ceil() as usize).clamp(1, 1024);
        let side = ext / k as f64;
        let cell = |p: DVec2| {
            let g = (p - lo) / side;
            (
                (g.x.max(0.0) as usize).min(k - 1),
                (g.y.max(0.0) as usize).min(k - 1),
            )
        };
        let mut buckets: Vec<Vec<usize>> = vec![Vec::new(); k * k];
        for s in 0..m {
            let (a, b) = self.segment(s);
            let (i0, j0) = cell(a.min(b));
            let (i1, j1) = cell(a.max(b));
            for j in j0..=j1 {
                for i in i0..=i1 {
                    buckets[j * k + i].push(s);
                }
            }
        }
        for (b, bucket) in buckets.iter().enumerate() {
            for (x, &s) in bucket.iter().enumerate() {
                let (ls, hs) = self.segment_box(s);
                for &t in &bucket[x + 1..] {
                    // Test each pair once: in the bucket of the corner of their boxes' overlap.
                    let (lt, ht) = self.segment_box(t);
                    let (lo, hi) = (ls.max(lt), hs.min(ht));
                    if lo.cmpgt(hi).any() {
                        continue;
                    }
                    let (i, j) = cell(lo);
                    if j * k + i != b {
                        continue;
                    }
                    if self.cross(s, t) {
                        return Err(PslgError::Crossing(s.min(t), s.max(t)));
                    }
                }
            }
        }
        Ok(())
    }

    /// Whether segments `s` and `t` cross at a point interior to both (touching at a vertex is
    /// handled by the point-on-segment test).
    fn cross(&self, s: usize, t: usize) -> bool {
        let [a, b] = self.segments[s];
        let [c, d] = self.segments[t];
        if a == c || a == d || b == c || b == d {
            return false;
        }
        let (pa, pb) = self.segment(s);
        let (pc, pd) = self.segment(t);
        let straddles = |a, b, c, d| {
            let o = orient2d(a, b, c);
            o != Ordering::Equal && o == orient2d(a, b, d).reverse()
        };
        straddles(pa, pb, pc, pd) && straddles(pc, pd, pa, pb)
    }
}
