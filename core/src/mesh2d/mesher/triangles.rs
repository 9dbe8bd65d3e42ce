//! Level 1 of the 2D mesher: triangles of the domain whose smallest angle is below the bound or
//! whose area is above the (regional) bound. Their refinement point is Üngör's off-centre (the
//! circumcentre, pulled towards the shortest edge when that still gives an angle at the bound),
//! which is what Triangle uses and needs fewer points than circumcentres.

use super::constraints::{Constraints, Label};
use crate::refine::{Candidate, Check, MesherLevel};
use crate::triangulation::Triangulation;
use crate::triangulation::delaunay2::{CellId, Delaunay2, InsertReport, VertexId};
use glam::DVec2;
use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;

/// Quality bounds of the triangle level.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct TriangleCriteria {
    /// Squared sine of the smallest allowed angle.
    pub sin2_min_angle: f64,
    /// Off-centre distance factor, from the angle bound.
    pub off_constant: f64,
    /// Area bound of each region (`INFINITY` for none).
    pub max_area: Vec<f64>,
}

impl TriangleCriteria {
    pub(crate) fn new(min_angle_deg: f64, max_area: Vec<f64>) -> Self {
        // Triangle's constant: the off-centre sits 0.475 √((1 + cos θ) / (1 − cos θ)) shortest
        // edges away from that edge (0.95 of the distance giving an apex angle of exactly θ).
        let cos = min_angle_deg.to_radians().cos();
        TriangleCriteria {
            sin2_min_angle: min_angle_deg.to_radians().sin().powi(2),
            off_constant: if min_angle_deg > 0.0 {
                0.475 * ((1.0 + cos) / (1.0 - cos)).sqrt()
            } else {
                0.0
            },
            max_area,
        }
    }
}

type Queued = (CellId, [VertexId; 3]);

/// Triangle's queue of bad triangles: buckets by the binary exponent (and first mantissa bit) of
/// the shortest edge, first-in first-out within a bucket, shortest edges first. Splitting the
/// triangles with the shortest edges first gives fewer points than worst-angle-first order, and
/// the buckets make push and pop O(1). Only the span of buckets in use is stored (a mesh uses a
/// few dozen of the 4096 possible keys), so that a small run does not pay for thousands of them.
#[derive(Default)]
struct BucketQueue {
    /// Bucket `base + i` is `buckets[i]`.
    buckets: VecDeque<VecDeque<Queued>>,
    base: usize,
    /// No bucket below `base + first` holds anything.
    first: usize,
    len: usize,
}

impl BucketQueue {
    const BUCKETS: usize = 1 << 12;

    fn bucket(shortest: f64) -> usize {
        // Positive finite doubles order like their bits; keep sign, exponent and one mantissa bit.
        ((shortest.max(0.0).to_bits() >> 51) as usize).min(Self::BUCKETS - 1)
    }

    fn push(&mut self, shortest: f64, e: Queued) {
        let b = Self::bucket(shortest);
        if self.buckets.is_empty() {
            self.base = b;
            self.first = 0;
        }
        while b < self.base {
            self.buckets.push_front(VecDeque::new());
            self.base -= 1;
            self.first += 1;
        }
        let i = b - self.base;
        if i >= self.buckets.len() {
            self.buckets.resize_with(i + 1, VecDeque::new);
        }
        self.buckets[i].push_back(e);
        self.first = self.first.min(i);
        self.len += 1;
    }

    fn peek(&mut self) -> Option<&Queued> {
        while self.first < self.buckets.len() && self.buckets[self.first].is_empty() {
            self.first += 1;
        }
        self.buckets.get(self.first)?.front()
    }

    fn pop(&mut self) {
        if self.peek().is_some() {
            self.buckets[self.first].pop_front();
            self.len -= 1;
        }
    }
}

pub(crate) struct TriangleLevel {
    cons: Rc<RefCell<Constraints>>,
    criteria: TriangleCriteria,
    /// Region label of each cell slot.
    labels: Vec<Label>,
    /// Cells created since the last labelling, to label and assess.
    pending: Vec<CellId>,
    queue: BucketQueue,
    /// Reused buffers of `resolve_labels`.
    work: Vec<CellId>,
    assess: Vec<CellId>,
}

impl TriangleLevel {
    pub(crate) fn new(
        cons: Rc<RefCell<Constraints>>,
        criteria: TriangleCriteria,
        labels: Vec<Label>,
    ) -> Self {
        TriangleLevel {
            cons,
            criteria,
            labels,
            pending: Vec::new(),
            queue: BucketQueue::default(),
            work: Vec::new(),
            assess: Vec::new(),
        }
    }

    pub(crate) fn label(&self, c: CellId) -> Label {
        self.labels
            .get(c.0 as usize)
            .copied()
            .unwrap_or(Label::Unknown)
    }

    /// Labels the pending cells from their neighbours and the sides of sub-segments. Valid when
    /// every sub-segment is an edge of the triangulation (the segment level has nothing queued),
    /// so that no cell straddles a constraint.
    pub(crate) fn resolve_labels(&mut self, tr: &Delaunay2) {
        let cons = self.cons.borrow();
        let mut work = std::mem::take(&mut self.work);
        work.clear();
        work.extend(
            self.pending
                .drain(..)
                .filter(|&c| tr.is_live(c) && self.labels[c.0 as usize] == Label::Unknown),
        );
        let mut assess = std::mem::take(&mut self.assess);
        assess.clear();
        assess.extend_from_slice(&work);
        let labels = &mut self.labels;
        loop {
            let before = work.len();
            work.retain(|&c| {
                let label = if tr.is_infinite_cell(c) {
                    Label::Outside
                } else {
                    let v = tr.cell(c);
                    (0..3)
                        .map(|i| {
                            let (x, y) = (v[(i + 1) % 3], v[(i + 2) % 3]);
                            match cons.get(x, y) {
                                Some(s) if s.a == x => s.left,
                                Some(s) => s.right,
                                None => labels[tr.neighbor(c, i).0 as usize],
                            }
                        })
                        .find(|&l| l != Label::Unknown)
                        .unwrap_or(Label::Unknown)
                };
                labels[c.0 as usize] = label;
                label == Label::Unknown
            });
            if work.is_empty() || work.len() == before {
                break;
            }
        }
        for &c in &work {
            self.labels[c.0 as usize] = Label::Outside;
        }
        drop(cons);
        for &c in &assess {
            self.assess(tr, c);
        }
        self.work = work;
        self.assess = assess;
    }

    /// Queues `c` if it is a bad triangle of the domain.
    fn assess(&mut self, tr: &Delaunay2, c: CellId) {
        let Label::Region(r) = self.label(c) else {
            return;
        };
        let v = tr.cell(c);
        let p = v.map(|x| tr.point(x));
        // Squared lengths only: the smallest angle is opposite the shortest edge and its sine is
        // twice the area over the product of the two other edges (no square root, no circumcentre).
        let l = [0, 1, 2].map(|i| p[i].distance_squared(p[(i + 1) % 3]));
        let i = shortest_of(&l);
        let twice_area = (p[1] - p[0]).perp_dot(p[2] - p[0]);
        let too_big = 0.5 * twice_area > self.criteria.max_area[r as usize];
        let skinny = twice_area * twice_area
            < self.criteria.sin2_min_angle * l[(i + 1) % 3] * l[(i + 2) % 3]
            && !self.spans_small_angle(tr, &v);
        if too_big || skinny {
            self.queue.push(l[i].sqrt(), (c, v));
        }
    }

    /// Triangle's rule against cascades at small input angles: a skinny triangle whose shortest
    /// edge joins two Steiner points on different segments sharing an apex, equally far from it (on the
    /// same concentric shell), cannot be improved by splitting and is left alone.
    fn spans_small_angle(&self, tr: &Delaunay2, v: &[VertexId; 3]) -> bool {
        let p = v.map(|x| tr.point(x));
        let i = shortest_edge(&p);
        let (x, y) = (v[i], v[(i + 1) % 3]);
        let cons = self.cons.borrow();
        let steiner = |v: VertexId| !cons.is_input.get(v.0 as usize).copied().unwrap_or(true);
        if !steiner(x) || !steiner(y) {
            return false;
        }
        let (Some(sx), Some(sy)) = (
            cons.on_segments.get(x.0 as usize),
            cons.on_segments.get(y.0 as usize),
        ) else {
            return false;
        };
        for &s in sx {
            for &t in sy {
                if s == t {
                    continue;
                }
                let [s0, s1] = cons.segments[s as usize];
                let [t0, t1] = cons.segments[t as usize];
                for apex in [s0, s1] {
                    if apex == x || apex == y || (apex != t0 && apex != t1) {
                        continue;
                    }
                    let pa = tr.point(apex);
                    let (dx, dy) = (tr.point(x).distance(pa), tr.point(y).distance(pa));
                    if dx < 1.001 * dy && dx > 0.999 * dy {
                        return true;
                    }
                }
            }
        }
        false
    }
}

impl MesherLevel<Delaunay2> for TriangleLevel {
    type Element = (CellId, [VertexId; 3]);

    fn name(&self) -> &'static str {
        "triangles"
    }

    fn pending(&self) -> usize {
        self.queue.len
    }

    fn scan(&mut self, tr: &Delaunay2) {
        self.labels.resize(tr.cell_capacity(), Label::Unknown);
        let cells: Vec<CellId> = tr.finite_cells().collect();
        for c in cells {
            self.assess(tr, c);
        }
    }

    fn next_element(&mut self, tr: &Delaunay2) -> Option<(CellId, [VertexId; 3])> {
        if !self.pending.is_empty() {
            self.resolve_labels(tr);
        }
        while let Some(&(c, v)) = self.queue.peek() {
            if tr.is_live(c) && tr.cell(c) == v {
                return Some((c, v));
            }
            self.queue.pop();
        }
        None
    }

    fn pop_element(&mut self) {
        self.queue.pop();
    }

    fn refinement_point(
        &mut self,
        tr: &Delaunay2,
        &(c, v): &(CellId, [VertexId; 3]),
    ) -> Option<Candidate<DVec2>> {
        let p = v.map(|x| tr.point(x));
        let center = tr.circumcenter(c);
        let i = shortest_edge(&p);
        // The triangle is counter-clockwise, so the left normal of its shortest edge points inside.
        let (a, b) = (p[i], p[(i + 1) % 3]);
        let d = b - a;
        let off = (a + b) * 0.5 + self.criteria.off_constant * d.perp();
        let point = if off.distance_squared(a) < center.distance_squared(a) {
            off
        } else {
            center
        };
        point.is_finite().then_some(Candidate {
            point,
            hint: Some(c),
        })
    }

    fn check(&mut self, _tr: &Delaunay2, _c: &Candidate<DVec2>, _own: bool) -> Check {
        Check::Accepted
    }

    fn after_insertion(&mut self, tr: &Delaunay2, _v: VertexId, report: &InsertReport, _own: bool) {
        if self.labels.len() < tr.cell_capacity() {
            self.labels.resize(tr.cell_capacity(), Label::Unknown);
        }
        for &c in &report.created {
            self.labels[c.0 as usize] = Label::Unknown;
            self.pending.push(c);
        }
    }
}

/// The index `i` of the start of the shortest edge (the edge `p[i] → p[i + 1]`).
fn shortest_edge(p: &[DVec2; 3]) -> usize {
    shortest_of(&[0, 1, 2].map(|i| p[i].distance_squared(p[(i + 1) % 3])))
}

/// Index of the smallest of three (squared) edge lengths, the first one on ties.
fn shortest_of(l: &[f64; 3]) -> usize {
    let mut i = 0;
    for j in 1..3 {
        if l[j] < l[i] {
            i = j;
        }
    }
    i
}

#[cfg(test)]
mod tests {
    use super::{BucketQueue, CellId, VertexId};

    /// Pops come out by bucket (shortest edges first) and first-in first-out within a bucket, as
    /// a stable sort by bucket gives, also when later pushes open buckets below the first one and
    /// when pushes and pops interleave.
    #[test]
    fn bucket_queue_pops_shortest_first_then_fifo() {
        let lengths = [1.0, 0.3, 5.0, 0.3, 1e-6, 2.0, 1.2, 1e-6, 40.0, 0.31];
        let entry = |k: usize| (CellId(k as u32), [VertexId(0); 3]);
        let mut queue = BucketQueue::default();
        let mut expected: Vec<(usize, usize)> = Vec::new();
        let mut popped = Vec::new();
        for (k, &l) in lengths.iter().enumerate() {
            queue.push(l, entry(k));
            expected.push((BucketQueue::bucket(l), k));
            if k == 4 {
                // Interleave: pop the current front.
                expected.sort_by_key(|&(b, _)| b);
                let (_, front) = expected.remove(0);
                assert_eq!(queue.peek().map(|e| e.0), Some(CellId(front as u32)));
                queue.pop();
                popped.push(front);
            }
        }
        expected.sort_by_key(|&(b, _)| b);
        let mut rest = Vec::new();
        while let Some(&(c, _)) = queue.peek() {
            rest.push(c.0 as usize);
            queue.pop();
        }
        assert_eq!(rest, expected.iter().map(|&(_, k)| k).collect::<Vec<_>>());
        assert_eq!(queue.len, 0);
        assert_eq!(popped.len() + rest.len(), lengths.len());
    }
}
