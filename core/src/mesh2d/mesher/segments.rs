//! Level 0 of the 2D mesher: constrained sub-segments. A sub-segment is refined while it is
//! encroached (a vertex in its diametral lens, or missing from the triangulation); a point
//! proposed by the triangle level that would encroach one is refused and the sub-segment queued.

use super::constraints::{Constraints, Encroachment, needs_split};
use crate::refine::{Candidate, Check, MesherLevel};
use crate::triangulation::Triangulation;
use crate::triangulation::delaunay2::{ConflictZone, Delaunay2, InsertReport, VertexId};
use glam::DVec2;
use std::cell::RefCell;
use std::collections::{HashSet, VecDeque};
use std::rc::Rc;

/// Input angles below this many degrees are "small": their sub-segments form a cluster.
pub(crate) const SMALL_ANGLE_DEG: f64 = 60.0;

/// Sub-segments at an input vertex where segments meet below this angle are split on concentric
/// shells. Ruppert's termination argument covers input angles of 90° and more, where midpoint
/// splitting gives fewer vertices (as in Triangle); the degree of slack keeps a right angle whose
/// rounded coordinates make it look a hair acute on midpoints.
const SHELL_ANGLE_DEG: f64 = 89.0;

pub(crate) struct SegmentLevel {
    cons: Rc<RefCell<Constraints>>,
    /// Sub-segments to split; `true` when a refused point encroached it (split it even though no
    /// vertex does).
    queue: VecDeque<(VertexId, VertexId, bool)>,
    queued: HashSet<(VertexId, VertexId)>,
    /// The sub-segment whose split point was proposed last (to record the split on insertion).
    proposed: Option<(VertexId, VertexId)>,
    /// Sub-segments shorter than this are never split (a guard against runaway refinement).
    min_length: f64,
    /// What encroaches a sub-segment; `None` while only sub-segments missing from the
    /// triangulation are split (segment recovery, before the domain sides are known).
    pub(crate) encroachment: Option<Encroachment>,
    zone: ConflictZone,
    /// Reused buffers of `after_insertion`: cavity boundary vertices, sub-segments at them.
    ends: Vec<VertexId>,
    pairs: Vec<(VertexId, VertexId)>,
    /// Per vertex, the insertion that last listed it in `ends` (deduplication without sorting).
    seen: Vec<u32>,
    stamp: u32,
}

impl SegmentLevel {
    pub(crate) fn new(cons: Rc<RefCell<Constraints>>, min_length: f64) -> Self {
        SegmentLevel {
            cons,
            queue: VecDeque::new(),
            queued: HashSet::new(),
            proposed: None,
            min_length,
            encroachment: None,
            zone: ConflictZone::default(),
            ends: Vec::new(),
            pairs: Vec::new(),
            seen: Vec::new(),
            stamp: 0,
        }
    }

    fn needs_split(&mut self, tr: &Delaunay2, a: VertexId, b: VertexId) -> bool {
        needs_split(tr, &self.cons.borrow(), a, b, self.encroachment.as_ref())
    }

    fn push(&mut self, a: VertexId, b: VertexId, forced: bool) {
        let key = (a.min(b), a.max(b));
        if self.queued.insert(key) {
            self.queue.push_back((a, b, forced));
        } else if forced {
            if let Some(e) = self
                .queue
                .iter_mut()
                .find(|e| (e.0.min(e.1), e.0.max(e.1)) == key)
            {
                e.2 = true;
            }
        }
    }

    /// Split point: the midpoint, or — when exactly one end is an input vertex where segments meet
    /// at an acute angle — the point at a power-of-two distance from it (Shewchuk's concentric
    /// shells), so that segments meeting at a small angle are split at matching radii.
    fn split_point(&self, tr: &Delaunay2, a: VertexId, b: VertexId) -> DVec2 {
        let cons = self.cons.borrow();
        let apex = |v: VertexId| cons.is_small_angle_apex(tr, v, SHELL_ANGLE_DEG);
        let (pa, pb) = (tr.point(a), tr.point(b));
        let len = pa.distance(pb);
        let t = match (apex(a), apex(b)) {
            (true, false) => shell_fraction(len),
            (false, true) => 1.0 - shell_fraction(len),
            _ => 0.5,
        };
        pa + (pb - pa) * t
    }

    /// Distance from the split point of `(a, b)` to its nearest vertex (which is a vertex of its
    /// conflict zone).
    fn insertion_radius(&mut self, tr: &Delaunay2, a: VertexId, b: VertexId) -> f64 {
        let m = self.split_point(tr, a, b);
        let mut zone = std::mem::take(&mut self.zone);
        tr.conflict_zone(m, None, &mut zone);
        let r = zone
            .cells
            .iter()
            .flat_map(|&c| tr.cell(c))
            .filter(|&v| !tr.is_infinite_vertex(v))
            .map(|v| tr.point(v).distance(m))
            .fold(f64::INFINITY, f64::min);
        self.zone = zone;
        r
    }
}

impl MesherLevel<Delaunay2> for SegmentLevel {
    type Element = (VertexId, VertexId);

    fn name(&self) -> &'static str {
        "sub-segments"
    }

    fn pending(&self) -> usize {
        self.queue.len()
    }

    fn scan(&mut self, tr: &Delaunay2) {
        let subs = self.cons.borrow().sorted();
        for s in subs {
            if self.needs_split(tr, s.a, s.b) {
                self.push(s.a, s.b, false);
            }
        }
    }

    fn next_element(&mut self, tr: &Delaunay2) -> Option<(VertexId, VertexId)> {
        while let Some(&(a, b, forced)) = self.queue.front() {
            let live = self.cons.borrow().get(a, b).is_some();
            if live && (forced || self.needs_split(tr, a, b)) {
                return Some((a, b));
            }
            self.pop_element();
        }
        None
    }

    fn pop_element(&mut self) {
        if let Some((a, b, _)) = self.queue.pop_front() {
            self.queued.remove(&(a.min(b), a.max(b)));
        }
    }

    fn refinement_point(
        &mut self,
        tr: &Delaunay2,
        &(a, b): &(VertexId, VertexId),
    ) -> Option<Candidate<DVec2>> {
        if tr.point(a).distance(tr.point(b)) < self.min_length {
            return None;
        }
        self.proposed = Some((a, b));
        let hint = tr.edge_cell(a, b).map(|(c, _)| c);
        Some(Candidate {
            point: self.split_point(tr, a, b),
            hint,
        })
    }

    /// A foreign point (a triangle's refinement point) is refused when it encroaches a
    /// sub-segment, which is queued. Shewchuk's rule for small input angles: a sub-segment of a
    /// segment that meets another at a small angle is not split when its split point would lie
    /// closer to an existing vertex than the triangle's shortest edge (the split would only shrink
    /// the local feature size and cascade); if every encroached sub-segment is spared this way,
    /// the triangle is given up (rejected forever).
    fn check(&mut self, tr: &Delaunay2, c: &Candidate<DVec2>, own: bool) -> Check {
        if own {
            return Check::Accepted;
        }
        let Some(encroachment) = self.encroachment else {
            return Check::Accepted;
        };
        let mut zone = std::mem::take(&mut self.zone);
        tr.conflict_zone(c.point, c.hint, &mut zone);
        let mut encroached = Vec::new();
        {
            let cons = self.cons.borrow();
            for &cell in &zone.cells {
                let v = tr.cell(cell);
                for i in 0..3 {
                    let (x, y) = (v[(i + 1) % 3], v[(i + 2) % 3]);
                    if tr.is_infinite_vertex(x) || tr.is_infinite_vertex(y) {
                        continue;
                    }
                    if let Some(s) = cons.get(x, y) {
                        let (px, py) = (tr.point(x), tr.point(y));
                        if encroachment.encroaches(c.point, px, py) {
                            encroached.push((s.a, s.b, s.origin));
                        }
                    }
                }
            }
        }
        self.zone = zone;
        if encroached.is_empty() {
            return Check::Accepted;
        }
        let shortest = c
            .hint
            .filter(|&h| tr.is_live(h) && !tr.is_infinite_cell(h))
            .map(|h| {
                let p = tr.cell(h).map(|v| tr.point(v));
                p[0].distance(p[1])
                    .min(p[1].distance(p[2]))
                    .min(p[2].distance(p[0]))
            });
        let mut queued = false;
        for (a, b, origin) in encroached {
            let in_cluster = {
                let cons = self.cons.borrow();
                cons.segments[origin as usize]
                    .iter()
                    .any(|&v| cons.is_small_angle_apex(tr, v, SMALL_ANGLE_DEG))
            };
            let protected =
                in_cluster && shortest.is_some_and(|l| self.insertion_radius(tr, a, b) < l);
            if !protected {
                self.push(a, b, true);
                queued = true;
            }
        }
        if queued {
            Check::Rejected
        } else {
            Check::RejectedForever
        }
    }

    fn after_insertion(&mut self, tr: &Delaunay2, v: VertexId, report: &InsertReport, own: bool) {
        if own {
            if let Some((a, b)) = self.proposed.take() {
                self.cons.borrow_mut().split(a, b, v);
            }
        }
        // A sub-segment can only have become encroached (or lost) if one of its ends is on the
        // cavity boundary, i.e. is a vertex of the new cells: an existing edge is lost only with
        // both ends there, but the halves of a split sub-segment start with one end at the new
        // vertex and may be missing from the start.
        self.seen.resize(tr.num_vertices(), 0);
        self.stamp = self.stamp.wrapping_add(1);
        if self.stamp == 0 {
            self.seen.fill(0);
            self.stamp = 1;
        }
        let mut ends = std::mem::take(&mut self.ends);
        ends.clear();
        for x in report.created.iter().flat_map(|&c| tr.cell(c)) {
            if !tr.is_infinite_vertex(x) && self.seen[x.0 as usize] != self.stamp {
                self.seen[x.0 as usize] = self.stamp;
                ends.push(x);
            }
        }
        let mut pairs = std::mem::take(&mut self.pairs);
        pairs.clear();
        {
            let cons = self.cons.borrow();
            let seen = &self.seen;
            let stamp = self.stamp;
            for &x in &ends {
                // Each pair once: from its lower end when both ends are on the cavity.
                pairs.extend(
                    cons.around(x)
                        .iter()
                        .filter(|&&y| x < y || seen[y.0 as usize] != stamp)
                        .map(|&y| (x.min(y), x.max(y))),
                );
            }
        }
        // Queue in the order of the lower end (the queue order decides the refinement order).
        pairs.sort_by_key(|&(x, _)| x);
        for &(x, y) in &pairs {
            if self.needs_split(tr, x, y) {
                self.push(x, y, false);
            }
        }
        self.ends = ends;
        self.pairs = pairs;
    }
}

/// Fraction of a sub-segment of length `len` at which to split it, measured from its apex end: a
/// power of two (in absolute units) between a third and two thirds of `len`, as in Triangle.
fn shell_fraction(len: f64) -> f64 {
    if !(len > 0.0 && len.is_finite()) {
        return 0.5;
    }
    let mut d = 2f64.powi(len.log2().floor() as i32);
    while len > 3.0 * d {
        d *= 2.0;
    }
    while len < 1.5 * d {
        d *= 0.5;
    }
    d / len
}

#[cfg(test)]
mod tests {
    use super::shell_fraction;

    #[test]
    fn shells_are_powers_of_two_in_the_middle_third() {
        for len in [0.001, 0.3, 1.0, 1.4, 2.9, 3.0, 7.5, 1e6] {
            let f = shell_fraction(len);
            assert!((1.0 / 3.0..=2.0 / 3.0).contains(&f), "{len}: {f}");
            let d = f * len;
            assert_eq!(d.log2().fract(), 0.0, "{len}: {d} is not a power of two");
        }
    }
}
