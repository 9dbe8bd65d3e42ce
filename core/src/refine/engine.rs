//! The refinement engine: the skeleton shared by all levels (thesis, ch. 5, `Mesher_level_base`).

use crate::triangulation::{
    CellId, InsertOutcome, InsertReport, Triangulation, TriangulationError, VertexId,
};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// Answer of a level asked whether a refinement point may be inserted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Check {
    /// The point may be inserted.
    Accepted,
    /// The point encroaches a constrained element of the checking level, which that level queued:
    /// the element refined first, the proposing element is kept and tried again later.
    Rejected,
    /// The point must never be inserted: the proposing element is dropped.
    RejectedForever,
}

/// A refinement point with a cell near it, so that checks and insertion walk a short way.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate<P> {
    /// The point to insert.
    pub point: P,
    /// A cell near it, where the walk starts.
    pub hint: Option<CellId>,
}

/// One rule of a Delaunay-refinement algorithm and the queue of elements it must refine.
///
/// The primitives of the thesis: `scan`, `next_element` / `pop_element` (the `to_be_refined`
/// queue), `refinement_point`, `check` and `after_insertion`. The engine provides the skeleton.
pub trait MesherLevel<T: Triangulation> {
    /// What this level refines (a facet, a cell, a segment...), as it sits in the queue.
    type Element;

    /// Short name for progress and reports.
    fn name(&self) -> &'static str;

    /// Fill the queue from the whole triangulation.
    fn scan(&mut self, tr: &T);

    /// The element to refine next, without removing it. Stale entries (elements destroyed by
    /// insertions since they were queued) are discarded here. `None` when nothing is left.
    fn next_element(&mut self, tr: &T) -> Option<Self::Element>;

    /// Remove the element last returned by `next_element`.
    fn pop_element(&mut self);

    /// Remove the element last returned by `next_element` because its refinement point was
    /// refused forever (or it bounced too long). A level that refuses other levels' points for
    /// its elements remembers it, so that an element nobody can refine blocks nothing.
    fn drop_element(&mut self) {
        self.pop_element()
    }

    /// Where to insert a point to refine `e`; `None` if `e` cannot be refined (it is then dropped).
    fn refinement_point(&mut self, tr: &T, e: &Self::Element) -> Option<Candidate<T::Point>>;

    /// May `c` be inserted? `own` is true when this level proposed it. A level that rejects a
    /// point of another level queues the element the point encroaches.
    fn check(&mut self, tr: &T, c: &Candidate<T::Point>, own: bool) -> Check;

    /// Update the queue after `v` was inserted (by this level when `own`), creating and
    /// destroying the cells listed in `report`.
    fn after_insertion(&mut self, tr: &T, v: VertexId, report: &InsertReport, own: bool);

    /// Number of queued elements (possibly including stale ones): for progress display only.
    fn pending(&self) -> usize;
}

/// The element-free view of a level that the engine stacks.
trait Level<T: Triangulation> {
    fn name(&self) -> &'static str;
    fn scan(&mut self, tr: &T);
    fn next_candidate(&mut self, tr: &T) -> Option<Candidate<T::Point>>;
    fn pop(&mut self);
    fn drop(&mut self);
    fn check(&mut self, tr: &T, c: &Candidate<T::Point>, own: bool) -> Check;
    fn after_insertion(&mut self, tr: &T, v: VertexId, report: &InsertReport, own: bool);
    fn pending(&self) -> usize;
}

impl<T: Triangulation, L: MesherLevel<T>> Level<T> for L {
    fn name(&self) -> &'static str {
        MesherLevel::name(self)
    }
    fn scan(&mut self, tr: &T) {
        MesherLevel::scan(self, tr)
    }
    fn next_candidate(&mut self, tr: &T) -> Option<Candidate<T::Point>> {
        loop {
            let e = self.next_element(tr)?;
            match self.refinement_point(tr, &e) {
                Some(c) => return Some(c),
                None => self.pop_element(),
            }
        }
    }
    fn pop(&mut self) {
        self.pop_element()
    }
    fn drop(&mut self) {
        self.drop_element()
    }
    fn check(&mut self, tr: &T, c: &Candidate<T::Point>, own: bool) -> Check {
        MesherLevel::check(self, tr, c, own)
    }
    fn after_insertion(&mut self, tr: &T, v: VertexId, report: &InsertReport, own: bool) {
        MesherLevel::after_insertion(self, tr, v, report, own)
    }
    fn pending(&self) -> usize {
        MesherLevel::pending(self)
    }
}

/// A flag that stops refinement from outside (another thread, a signal handler, a progress
/// callback): the run ends with [`RefineError::Cancelled`] at its next guard check. Clones share
/// the flag.
#[derive(Clone, Debug, Default)]
pub struct Cancel(Arc<AtomicBool>);

impl Cancel {
    /// A flag not raised yet.
    pub fn new() -> Self {
        Cancel::default()
    }

    /// Asks every run holding this flag (or a clone) to stop.
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }

    /// Whether [`cancel`](Self::cancel) was called.
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// When a run must end: a time bound from its start, a [`Cancel`] flag, both or neither. One
/// guard for refinement, the surface-keeping recovery and the optimisers.
#[derive(Clone, Debug, Default)]
pub(crate) struct Deadline {
    at: Option<std::time::Instant>,
    cancel: Option<Cancel>,
}

impl Deadline {
    /// The deadline `limit` from now, or raised by `cancel`.
    pub(crate) fn new(limit: Option<std::time::Duration>, cancel: Option<Cancel>) -> Self {
        Deadline {
            at: limit.map(|t| std::time::Instant::now() + t),
            cancel,
        }
    }

    /// Why the run must stop now, if it must (the time limit first).
    pub(crate) fn stop(&self) -> Option<RefineError> {
        if self.at.is_some_and(|d| std::time::Instant::now() >= d) {
            Some(RefineError::TimeLimit)
        } else if self.cancel.as_ref().is_some_and(Cancel::is_cancelled) {
            Some(RefineError::Cancelled)
        } else {
            None
        }
    }

    /// Whether the run must stop now.
    pub(crate) fn passed(&self) -> bool {
        self.stop().is_some()
    }
}

/// The same flag, not the same state: two runs with equal limits stop together.
impl PartialEq for Cancel {
    fn eq(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

/// Guards that make refinement terminate whatever the input.
#[derive(Clone, Debug, PartialEq)]
pub struct Limits {
    /// Refinement stops with [`RefineError::TooManyVertices`] past this many vertices.
    pub max_vertices: usize,
    /// A level whose elements are rejected this many times in a row without any insertion drops
    /// the one it proposes, so that levels cannot bounce elements between them forever (counted
    /// per level: a lower level's element that keeps making a higher one bounce is dropped too).
    pub max_rejections_in_a_row: usize,
    /// Refinement stops with [`RefineError::TimeLimit`] when it runs longer than this (and the
    /// protection of sharp features, when it does; `None`: no limit).
    pub time_limit: Option<std::time::Duration>,
    /// Refinement stops with [`RefineError::Cancelled`] once this flag is raised.
    pub cancel: Option<Cancel>,
}

impl Default for Limits {
    fn default() -> Self {
        Limits {
            max_vertices: 2_000_000,
            max_rejections_in_a_row: 64,
            time_limit: None,
            cancel: None,
        }
    }
}

/// A snapshot handed to the progress callback.
#[derive(Clone, Debug, PartialEq)]
pub struct Progress<'n> {
    /// Vertices in the triangulation.
    pub vertices: usize,
    /// Refinement points inserted so far.
    pub insertions: usize,
    /// `(level name, queued elements)` in priority order.
    pub pending: Vec<(&'n str, usize)>,
}

/// What happened during one refinement run.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RefineStats {
    /// Rounds of validity repairs after the criteria were met (flat cells, non-manifold spots,
    /// topology differences), each followed by refinement to the criteria again.
    pub repair_rounds: usize,
    /// Times the sharp features were protected again with smaller balls before the attempt kept
    /// (see `mesh_with_features`; the other counts are those of that attempt).
    pub reprotections: usize,
    /// Insertions per level, in priority order.
    pub insertions: Vec<usize>,
    /// Points rejected because they encroached a higher-priority element.
    pub rejections: usize,
    /// Elements dropped without refinement (rejected forever, duplicates, bouncing).
    pub dropped: usize,
}

impl RefineStats {
    /// Add the counts of a later run over the same levels.
    pub fn absorb(&mut self, other: &RefineStats) {
        if self.insertions.len() < other.insertions.len() {
            self.insertions.resize(other.insertions.len(), 0);
        }
        for (a, b) in self.insertions.iter_mut().zip(&other.insertions) {
            *a += b;
        }
        self.rejections += other.rejections;
        self.dropped += other.dropped;
        self.repair_rounds += other.repair_rounds;
    }
}

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[allow(missing_docs, reason = "each variant's #[error] message documents it")]
pub enum RefineError {
    #[error(
        "refinement needs more than {limit} vertices (max-vertices); raise the limit or coarsen \
         the criteria"
    )]
    TooManyVertices { limit: usize },
    #[error("meshing took longer than the time limit; raise --time-limit or coarsen the criteria")]
    TimeLimit,
    #[error("meshing was cancelled")]
    Cancelled,
    #[error("a refinement point was refused by the triangulation")]
    Triangulation(#[from] TriangulationError),
}

/// Levels in priority order (highest first) over one triangulation.
pub struct Engine<'a, T: Triangulation> {
    levels: Vec<&'a mut dyn Level<T>>,
    limits: Limits,
    report: InsertReport,
}

impl<'a, T: Triangulation> Engine<'a, T> {
    /// An engine without levels, under `limits`.
    pub fn new(limits: Limits) -> Self {
        Engine {
            levels: Vec::new(),
            limits,
            report: InsertReport::default(),
        }
    }

    /// Add a level below all the levels already added. The caller keeps ownership, so that the
    /// levels' state (restricted facets, cell labels...) can be read after refinement.
    pub fn push_level<L: MesherLevel<T> + 'a>(&mut self, level: &'a mut L) -> &mut Self {
        self.levels.push(level);
        self
    }

    /// Run all levels until every queue is empty or a guard trips. The triangulation is left as
    /// it is when an error is returned, so that callers can keep the partial mesh.
    pub fn refine(
        &mut self,
        tr: &mut T,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<RefineStats, RefineError> {
        for level in self.levels.iter_mut() {
            level.scan(tr);
        }
        self.resume(tr, progress)
    }

    /// Run all levels from their queues as they are, without scanning the triangulation: for a
    /// new round after elements were queued from outside (validity repairs of the complex).
    pub fn resume(
        &mut self,
        tr: &mut T,
        progress: &mut dyn FnMut(&Progress),
    ) -> Result<RefineStats, RefineError> {
        let mut stats = RefineStats {
            insertions: vec![0; self.levels.len()],
            ..RefineStats::default()
        };
        // Per level: a bounced element of one level cannot reset the count of another's.
        let mut rejections_in_a_row = vec![0usize; self.levels.len()];
        let mut total = 0usize;
        let deadline = Deadline::new(self.limits.time_limit, self.limits.cancel.clone());
        let mut steps = 0usize;
        while let Some((i, candidate)) = self.next_candidate(tr) {
            steps += 1;
            if steps % 256 == 0
                && let Some(stop) = deadline.stop()
            {
                return Err(stop);
            }
            match self.check_by_all_levels(tr, &candidate, i) {
                Check::Accepted => {
                    if tr.num_vertices() >= self.limits.max_vertices {
                        return Err(RefineError::TooManyVertices {
                            limit: self.limits.max_vertices,
                        });
                    }
                    self.levels[i].pop();
                    match tr.insert_reporting(candidate.point, candidate.hint, &mut self.report)? {
                        InsertOutcome::Inserted(v) => {
                            rejections_in_a_row.fill(0);
                            stats.insertions[i] += 1;
                            total += 1;
                            for (j, level) in self.levels.iter_mut().enumerate() {
                                level.after_insertion(tr, v, &self.report, j == i);
                            }
                            if total % 256 == 0 {
                                progress(&self.progress(tr, total));
                            }
                        }
                        // A hidden point (regular triangulations only) changed nothing either.
                        InsertOutcome::Duplicate(_) | InsertOutcome::Hidden(_) => {
                            stats.dropped += 1
                        }
                    }
                }
                Check::Rejected => {
                    stats.rejections += 1;
                    rejections_in_a_row[i] += 1;
                    if rejections_in_a_row[i] > self.limits.max_rejections_in_a_row {
                        self.levels[i].drop();
                        stats.dropped += 1;
                        rejections_in_a_row[i] = 0;
                    }
                }
                Check::RejectedForever => {
                    self.levels[i].drop();
                    stats.dropped += 1;
                }
            }
        }
        progress(&self.progress(tr, total));
        Ok(stats)
    }

    /// The refinement point of the first level (in priority order) with work left.
    fn next_candidate(&mut self, tr: &T) -> Option<(usize, Candidate<T::Point>)> {
        self.levels
            .iter_mut()
            .enumerate()
            .find_map(|(i, level)| level.next_candidate(tr).map(|c| (i, c)))
    }

    /// `check_refinement_point_by_all_levels`: levels 0..=i, stopping at the first refusal.
    fn check_by_all_levels(&mut self, tr: &T, c: &Candidate<T::Point>, i: usize) -> Check {
        for (j, level) in self.levels[..=i].iter_mut().enumerate() {
            match level.check(tr, c, j == i) {
                Check::Accepted => {}
                refused => return refused,
            }
        }
        Check::Accepted
    }

    fn progress(&self, tr: &T, insertions: usize) -> Progress<'_> {
        Progress {
            vertices: tr.num_vertices(),
            insertions,
            pending: self
                .levels
                .iter()
                .map(|l| (l.name(), l.pending()))
                .collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::Point3;
    use crate::triangulation::Delaunay3;

    /// One point to propose, and what the level does with other levels' points.
    struct Toy {
        point: Option<Point3>,
        /// Refuse forever every other level's point with x < 0 (a protecting ball).
        guard: bool,
        /// Refuse other levels' points within distance 2 of the origin while `point` is pending
        /// and was never dropped (a surface ball nobody can refine).
        ball: bool,
        dropped: bool,
    }

    impl MesherLevel<Delaunay3> for Toy {
        type Element = Point3;
        fn name(&self) -> &'static str {
            "toy"
        }
        fn scan(&mut self, _tr: &Delaunay3) {}
        fn next_element(&mut self, _tr: &Delaunay3) -> Option<Point3> {
            self.point
        }
        fn pop_element(&mut self) {
            self.point = None;
        }
        fn drop_element(&mut self) {
            self.point = None;
            self.dropped = true;
        }
        fn refinement_point(&mut self, _tr: &Delaunay3, p: &Point3) -> Option<Candidate<Point3>> {
            Some(Candidate {
                point: *p,
                hint: None,
            })
        }
        fn check(&mut self, _tr: &Delaunay3, c: &Candidate<Point3>, own: bool) -> Check {
            if own {
                Check::Accepted
            } else if self.guard && c.point.x < 0.0 {
                Check::RejectedForever
            } else if self.ball && !self.dropped && c.point.length() < 2.0 {
                Check::Rejected
            } else {
                Check::Accepted
            }
        }
        fn after_insertion(&mut self, _: &Delaunay3, _: VertexId, _: &InsertReport, _: bool) {}
        fn pending(&self) -> usize {
            usize::from(self.point.is_some())
        }
    }

    /// The middle level's only element is refused forever by the top level; once dropped it
    /// must stop refusing the bottom level's point, which is then inserted.
    #[test]
    fn an_element_refused_forever_refuses_no_lower_point() {
        let corners = [-4.0, 4.0].map(|x| [-4.0, 4.0].map(|y| [-4.0, 4.0].map(|z| (x, y, z))));
        let points: Vec<Point3> = corners
            .into_iter()
            .flatten()
            .flatten()
            .map(|(x, y, z)| Point3::new(x, y, z))
            .collect();
        let mut tr = Delaunay3::from_points(&points).expect("a cube's corners");
        let toy = |point: Option<Point3>, guard, ball| Toy {
            point,
            guard,
            ball,
            dropped: false,
        };
        let mut top = toy(None, true, false);
        let mut middle = toy(Some(Point3::new(-1.0, 0.0, 0.0)), false, true);
        let mut bottom = toy(Some(Point3::new(0.5, 0.0, 0.0)), false, false);
        let mut engine = Engine::new(Limits::default());
        engine
            .push_level(&mut top)
            .push_level(&mut middle)
            .push_level(&mut bottom);
        let stats = engine.refine(&mut tr, &mut |_| {}).expect("no guard trips");
        assert_eq!(stats.insertions, vec![0, 0, 1]);
        assert_eq!(stats.rejections, 0);
        assert!(middle.dropped);
    }
}
