//! Stand-in for the shared refinement engine (`crate::refine`) until it is available to this
//! module: the same skeleton — levels in priority order, a point proposed by level i checked by
//! levels 0..=i, inserted when all accept, every level told of every insertion.

use crate::triangulation::Triangulation;
use crate::triangulation::delaunay2::{
    CellId, Delaunay2, InsertOutcome, InsertReport, TriangulationError, VertexId,
};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Check {
    Accepted,
    Rejected,
    RejectedForever,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Candidate<P> {
    pub point: P,
    pub hint: Option<CellId>,
}

/// The element-free view of a level.
pub(crate) trait Level {
    fn scan(&mut self, tr: &Delaunay2);
    fn next_candidate(&mut self, tr: &Delaunay2) -> Option<Candidate<glam::DVec2>>;
    fn pop(&mut self);
    fn check(&mut self, tr: &Delaunay2, c: &Candidate<glam::DVec2>, own: bool) -> Check;
    fn after_insertion(&mut self, tr: &Delaunay2, v: VertexId, report: &InsertReport, own: bool);
}

macro_rules! level {
    ($t:ty) => {
        impl Level for $t {
            fn scan(&mut self, tr: &Delaunay2) {
                <$t>::scan(self, tr)
            }
            fn next_candidate(&mut self, tr: &Delaunay2) -> Option<Candidate<glam::DVec2>> {
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
            fn check(&mut self, tr: &Delaunay2, c: &Candidate<glam::DVec2>, own: bool) -> Check {
                <$t>::check(self, tr, c, own)
            }
            fn after_insertion(
                &mut self,
                tr: &Delaunay2,
                v: VertexId,
                r: &InsertReport,
                own: bool,
            ) {
                <$t>::after_insertion(self, tr, v, r, own)
            }
        }
    };
}
level!(super::segments::SegmentLevel);
level!(super::triangles::TriangleLevel);

/// Why refinement stopped early.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RefineError {
    #[error("refinement needs more than {limit} vertices; raise the limit or coarsen the criteria")]
    TooManyVertices { limit: usize },
    #[error("a refinement point was refused by the triangulation: {0}")]
    Triangulation(#[from] TriangulationError),
}

/// Runs the levels until every queue is empty; returns the number of insertions.
pub(crate) fn refine(
    tr: &mut Delaunay2,
    levels: &mut [&mut dyn Level],
    max_vertices: usize,
) -> Result<usize, RefineError> {
    for level in levels.iter_mut() {
        level.scan(tr);
    }
    let mut report = InsertReport::default();
    let mut insertions = 0;
    let mut rejections_in_a_row = 0;
    loop {
        let Some((i, c)) = levels
            .iter_mut()
            .enumerate()
            .find_map(|(i, l)| l.next_candidate(tr).map(|c| (i, c)))
        else {
            return Ok(insertions);
        };
        let verdict = levels[..=i]
            .iter_mut()
            .enumerate()
            .map(|(j, l)| l.check(tr, &c, j == i))
            .find(|&v| v != Check::Accepted)
            .unwrap_or(Check::Accepted);
        match verdict {
            Check::Accepted => {
                if tr.num_vertices() >= max_vertices {
                    return Err(RefineError::TooManyVertices {
                        limit: max_vertices,
                    });
                }
                rejections_in_a_row = 0;
                levels[i].pop();
                if let InsertOutcome::Inserted(v) =
                    tr.insert_reporting(c.point, c.hint, &mut report)?
                {
                    insertions += 1;
                    for (j, level) in levels.iter_mut().enumerate() {
                        level.after_insertion(tr, v, &report, j == i);
                    }
                }
            }
            Check::Rejected => {
                rejections_in_a_row += 1;
                if rejections_in_a_row > 64 {
                    levels[i].pop();
                    rejections_in_a_row = 0;
                }
            }
            Check::RejectedForever => levels[i].pop(),
        }
    }
}
