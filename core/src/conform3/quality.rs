//! Quality refinement of a conforming tetrahedralisation (the cell level of Shewchuk's Delaunay
//! refinement of PLCs): a cell inside the domain whose radius-edge ratio or circumradius is too
//! large gets its circumcentre, unless that point's cavity would destroy a piece of an input
//! triangle or the point encroaches a piece on the cavity's boundary (lies in its diametral
//! ball: inserted, it would leave a cell flattened against the surface, which the next cells'
//! centres would only make flatter). Then the centre is not inserted: the sub-segment of that
//! piece it encroaches is split, else the piece itself, as recovery refines a missing piece.
//! Cells are refined in rounds; between rounds recovery restores the pieces that surface points
//! broke.
//!
//! Every insertion of a centre keeps every piece (its cavity holds none), so the pieces and the
//! cells' subdomains found at the start of a round stay true for the centres of that round: a
//! round takes the bad cells worst first from a queue, and the cells each centre creates take
//! its cavity's subdomain and join the queue; the splits of the surface, which break pieces,
//! wait for the end of the round. (Refining only the cells found at a round's start took
//! fandisk at radius-edge 1.414 past 200 rounds and 57,000 vertices; the queue and the
//! encroachment test end it in 56 rounds with 24,000.)

use super::regions::{Pieces, cell_subdomains, faces_to_move_across, key, label_cells};
use super::{PreserveError, Recovery, facet};
use crate::kernel::Point3;
use crate::oracle::{OUTSIDE, Oracle, SubdomainId};
use crate::refine::RefineError;
use crate::refine::criteria::CellCriteria;
use crate::refine::{
    CHECKER_FLAT_VOLUME, FLAT_CANDIDATES, cell_vertices, facet_vertices,
    flat_cell_refinement_point, is_flat, is_flat_within, is_same_cell, shortest_edge,
    triangle_circumcenter,
};
use crate::triangulation::{CellId, Triangulation, VertexId};
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};
use std::collections::BinaryHeap;

/// Most rounds; each refines every bad cell found at its start, so far fewer are needed.
const MAX_ROUNDS: usize = 200;

/// The floor under the cells that checkers count as flat, relative to the one under the
/// criteria: such a cell is a defect, not a shape to improve, and the ones rounding makes among
/// the points where crossing input triangles were cut, or that the cell level leaves between
/// close Steiner points of a CAD part's surface (fandisk with radius-edge 1.414: 13 at 1e-3), are
/// far smaller than the floor the criteria keep. Cells only nearly that flat keep the criteria's
/// floor: on CAD parts they are many, and refining them all below it multiplies the vertices.
const FLAT_FLOOR: f64 = 1e-5;

/// A piece of an input triangle (its vertices sorted) with that triangle.
type Piece = ([VertexId; 3], usize);

/// The refinement of one round that breaks pieces, planned while centres are inserted.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Split {
    /// The sub-segment between these vertices of this input edge.
    Segment(usize, [VertexId; 2]),
    /// This piece (sorted vertices) of this input triangle.
    Piece(usize, [VertexId; 3]),
}

/// Refines the cells inside the domain until each meets `criteria` (if any) or has a
/// circumradius below `min_radius`, and, criteria or not, until no cell away from the outside is
/// flat; `faces` (the pieces of each input triangle) is kept up to date. Returns how many
/// centres were inserted, and why it stopped early, if the clock stopped it at a round's start or
/// at a centre (the pieces are then whole; past that, the run fails).
///
/// A round takes the bad cells worst first and inserts every centre whose cavity keeps the
/// pieces, queueing the bad cells each insertion creates (they lie in the cavity's region, so
/// they take its subdomain) until none is left; only the surface splits wait for the round's end.
pub(super) fn refine(
    r: &mut Recovery,
    faces: &mut Vec<Vec<[VertexId; 3]>>,
    oracle: &dyn Oracle,
    criteria: Option<&CellCriteria>,
    min_radius: f64,
) -> Result<(usize, Option<RefineError>), PreserveError> {
    let mut cavity = Cavity::default();
    let mut inserted = 0;
    // Cells left as they are because refining them would refine the surface too finely: not
    // tried again while they exist.
    let mut kept: HashSet<[VertexId; 4]> = HashSet::default();
    let bounds = Bounds {
        criteria,
        min_radius,
    };
    let mut subdomain = Vec::new();
    // The cells the last round's splits and recovery created (`None` before the first round),
    // and the cells that asked for those splits.
    let mut created: Option<Vec<CellId>> = None;
    let mut asked: Vec<([VertexId; 4], CellId)> = Vec::new();
    for _ in 0..MAX_ROUNDS {
        if let Some(stop) = r.clock.stop() {
            return Ok((inserted, Some(stop)));
        }
        let pieces = Pieces::new(faces);
        let candidates = round_cells(r, &pieces, oracle, created.take(), &asked, &mut subdomain);
        asked.clear();
        let mut queue: BinaryHeap<Bad> = candidates
            .into_iter()
            .filter_map(|c| bounds.badness(r, c, &subdomain, &pieces))
            .collect();
        if queue.is_empty() {
            break;
        }
        let segment_of = sub_segments(r);
        let mut splits = Vec::new();
        let before = r.dt.num_vertices();
        while let Some(Bad { cell, vertices, .. }) = queue.pop() {
            if !is_same_cell(&r.dt, cell, &vertices) || kept.contains(&vertices) {
                continue;
            }
            // The first candidate whose cavity keeps every piece, else the first candidate and
            // the pieces it would destroy.
            let mut chosen: Option<(Point3, Vec<Piece>)> = None;
            for center in refinement_points(r, cell, &vertices) {
                let Some(destroyed) = cavity.destroyed_pieces(r, center, cell, &pieces) else {
                    continue;
                };
                let keeps = destroyed.is_empty();
                if keeps || chosen.is_none() {
                    chosen = Some((center, destroyed));
                }
                if keeps {
                    break;
                }
            }
            let Some((center, destroyed)) = chosen else {
                kept.insert(vertices);
                continue;
            };
            if destroyed.is_empty() {
                let region = subdomain[cell.0 as usize];
                let v = match r.insert(center, vertices[0]) {
                    Err(PreserveError::Stopped(stop)) => return Ok((inserted, Some(stop))),
                    v => v?,
                };
                if v.is_some() {
                    r.inside.extend(v);
                    inserted += 1;
                    subdomain.resize(r.dt.cell_capacity(), OUTSIDE);
                    for &c in &r.report.created {
                        subdomain[c.0 as usize] = region;
                    }
                    for &c in &r.report.created {
                        queue.extend(bounds.badness(r, c, &subdomain, &pieces));
                    }
                }
            } else {
                // A flat cell is refined whatever the surface's resolution (the radius floor
                // bounds it): no solver can use it.
                let size = if is_flat(&vertices.map(|v| r.dt.point(v))) {
                    0.0
                } else {
                    criteria.map_or(f64::INFINITY, |c| {
                        c.size.at(center, subdomain[cell.0 as usize].0)
                    })
                };
                match split_for(r, center, size, &destroyed, &segment_of) {
                    Some(split) => {
                        splits.push(split);
                        asked.push((vertices, cell));
                    }
                    None => {
                        kept.insert(vertices);
                    }
                }
            }
        }
        splits.sort_unstable();
        splits.dedup();
        r.created = Some(Vec::new());
        // Sub-segments first: a piece's split may itself fall on one of them.
        for split in splits {
            let done = match split {
                Split::Segment(e, pair) => r.split(e, pair),
                Split::Piece(f, face) if r.has_face(face) => {
                    facet::split_piece(r, f, face).map(|_| ())
                }
                Split::Piece(..) => Ok(()),
            };
            match done {
                // A piece that would be shorter than floating point resolves, or a point that
                // falls on a vertex: the cell that asked for it stays as it is.
                Err(PreserveError::TooShort { .. } | PreserveError::Coincident(_)) | Ok(()) => {}
                Err(e) => return Err(e),
            }
        }
        if r.dt.num_vertices() == before {
            break;
        }
        r.run(faces)?;
        created = r.created.take();
    }
    r.created = None;
    Ok((inserted, None))
}

/// The cells a round looks at, with `subdomain` brought up to date: every cell at the first
/// round (`created` is `None`), or when the new cells joined two regions (see [`label_cells`]);
/// else the cells `created` since the last round that are still there, their neighbours (whether
/// a flat cell moves outside depends on them) and the cells that `asked` for splits. No other
/// cell changed its shape, its subdomain or its faces since it was last found good or kept; a
/// pass over the whole mesh per round was a fifth of fandisk's refinement.
pub(super) fn round_cells(
    r: &Recovery,
    pieces: &Pieces,
    oracle: &dyn Oracle,
    created: Option<Vec<CellId>>,
    asked: &[([VertexId; 4], CellId)],
    subdomain: &mut Vec<SubdomainId>,
) -> Vec<CellId> {
    if let Some(mut created) = created {
        created.retain(|&c| r.dt.is_live(c));
        created.sort_unstable();
        created.dedup();
        if label_cells(&r.dt, pieces, oracle, &created, subdomain) {
            let mut cells: Vec<CellId> = created
                .iter()
                .flat_map(|&c| (0..4).map(move |i| r.dt.neighbor(c, i)))
                .chain(created.iter().copied())
                .chain(
                    asked
                        .iter()
                        .filter(|(vertices, c)| is_same_cell(&r.dt, *c, vertices))
                        .map(|&(_, c)| c),
                )
                .filter(|&c| !r.dt.is_infinite_cell(c))
                .collect();
            cells.sort_unstable();
            cells.dedup();
            return cells;
        }
    }
    *subdomain = cell_subdomains(&r.dt, pieces, oracle);
    r.dt.finite_cells().collect()
}

/// A cell to refine: flat cells first, then the worst, ties by vertices (so the order is the
/// same on every run), with its vertices to tell whether it still exists.
struct Bad {
    worst: f64,
    cell: CellId,
    vertices: [VertexId; 4],
}

impl Ord for Bad {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.worst
            .total_cmp(&other.worst)
            .then_with(|| other.vertices.cmp(&self.vertices))
    }
}

impl PartialOrd for Bad {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Bad {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other).is_eq()
    }
}

impl Eq for Bad {}

/// What makes a cell bad: the criteria, the radius floor under them.
struct Bounds<'c> {
    criteria: Option<&'c CellCriteria>,
    min_radius: f64,
}

impl Bounds<'_> {
    /// Cell `c` if it is inside the domain and fails the criteria, or is flat and will not move
    /// outside when the complex is built (see [`faces_to_move_across`]).
    fn badness(
        &self,
        r: &Recovery,
        c: CellId,
        subdomain: &[SubdomainId],
        pieces: &Pieces,
    ) -> Option<Bad> {
        if r.dt.is_infinite_cell(c) || subdomain[c.0 as usize] == OUTSIDE {
            return None;
        }
        let vertices = cell_vertices(&r.dt, c);
        let bad = |worst| Bad {
            worst,
            cell: c,
            vertices,
        };
        let p = vertices.map(|v| r.dt.point(v));
        if is_flat(&p) {
            let stays = faces_to_move_across(&r.dt, c, subdomain, pieces).is_none();
            let radius = flat_cell_refinement_point(&r.dt, &vertices, 0).map(|(_, r2)| r2.sqrt());
            let floor = if is_flat_within(&p, CHECKER_FLAT_VOLUME) {
                FLAT_FLOOR * self.min_radius
            } else {
                self.min_radius
            };
            return (stays && radius.is_some_and(|radius| radius >= floor))
                .then(|| bad(f64::INFINITY));
        }
        let criteria = self.criteria?;
        let sub = subdomain[c.0 as usize];
        let center = r.dt.circumcenter(c);
        let radius = center.distance(p[0]);
        if radius.is_nan() || radius < self.min_radius {
            return None;
        }
        let shortest = shortest_edge(&p);
        let shape = if criteria.radius_edge_ratio > 0.0 {
            radius / shortest / criteria.radius_edge_ratio
        } else {
            0.0
        };
        let worst = shape.max(radius / criteria.size.at(center, sub.0));
        (worst > 1.0).then(|| bad(worst))
    }
}

/// Scratch space of the search for the pieces a point's cavity would destroy.
#[derive(Default)]
struct Cavity {
    /// Per cell, `3 * search` when found in conflict by that search (and explored), `+ 1` when
    /// found not to be, `+ 2` when found in conflict behind a piece (not explored from there).
    marks: Vec<u64>,
    search: u64,
    stack: Vec<CellId>,
}

impl Cavity {
    /// The pieces (sorted, with their input triangles) that inserting `p` would destroy or
    /// encroach, found from `start`'s side of the surface: those between a cell of the cavity
    /// (the cells in conflict with `p`, connected) reached from `start` without crossing a piece
    /// and a cell in conflict, and those on that part's boundary with `p` in their diametral
    /// ball. The search stops at pieces: a cavity that reaches past one destroys it, so whether
    /// `p` keeps every piece is decided on this side, and the split chosen is one of this
    /// side's pieces (the cavities of slivers' far centres span much of the mesh behind them).
    /// `None` when `start` is not in conflict with `p`.
    fn destroyed_pieces(
        &mut self,
        r: &Recovery,
        p: Point3,
        start: CellId,
        pieces: &Pieces,
    ) -> Option<Vec<Piece>> {
        if !r.dt.is_in_conflict(start, p) {
            return None;
        }
        self.search += 1;
        let (inside, outside, behind) = (3 * self.search, 3 * self.search + 1, 3 * self.search + 2);
        self.marks.resize(r.dt.cell_capacity(), 0);
        self.marks[start.0 as usize] = inside;
        self.stack.clear();
        self.stack.push(start);
        let mut out = Vec::new();
        while let Some(c) = self.stack.pop() {
            for i in 0..4 {
                let n = r.dt.neighbor(c, i);
                let face = facet_vertices(&cell_vertices(&r.dt, c), i);
                let piece = pieces.triangle_of(face);
                let mut mark = self.marks[n.0 as usize];
                if mark != inside && mark != outside && mark != behind {
                    mark = if !r.dt.is_in_conflict(n, p) {
                        outside
                    } else if piece.is_some() {
                        behind
                    } else {
                        self.stack.push(n);
                        inside
                    };
                    self.marks[n.0 as usize] = mark;
                } else if mark == behind && piece.is_none() {
                    // Reached around the pieces after all: explored from here.
                    self.stack.push(n);
                    self.marks[n.0 as usize] = inside;
                }
                if let Some(f) = piece {
                    let face = key(face);
                    if mark != outside || encroaches(r, p, face) {
                        out.push((face, f));
                    }
                }
            }
        }
        // A piece between two explored cells is seen from both.
        out.sort_unstable();
        out.dedup();
        Some(out)
    }
}

/// Whether `p` lies strictly inside the diametral ball of the piece `face`: inserted, it
/// would leave a cell too thin against the surface.
fn encroaches(r: &Recovery, p: Point3, face: [VertexId; 3]) -> bool {
    let [a, b, c] = face.map(|v| r.dt.point(v));
    let center = triangle_circumcenter(a, b, c);
    p.distance_squared(center) < a.distance_squared(center)
}

/// The points that destroy `cell`, best first: its circumcentre, or for a flat cell (whose
/// circumcentre rounding puts anywhere) the points off its plane inside its circumsphere that
/// the refinement engine tries, on both sides.
fn refinement_points(r: &Recovery, cell: CellId, vertices: &[VertexId; 4]) -> Vec<Point3> {
    if is_flat(&vertices.map(|v| r.dt.point(v))) {
        (0..FLAT_CANDIDATES)
            .filter_map(|attempt| flat_cell_refinement_point(&r.dt, vertices, attempt))
            .map(|(p, _)| p)
            .collect()
    } else {
        vec![r.dt.circumcenter(cell)]
    }
}

/// Every sub-segment (its vertices sorted) with its input edge.
fn sub_segments(r: &Recovery) -> HashMap<[VertexId; 2], usize> {
    let mut out = HashMap::default();
    for (e, edge) in r.constraints.edges.iter().enumerate() {
        for w in edge.chain.windows(2) {
            let (a, b) = (w[0].1, w[1].1);
            out.insert([a.min(b), a.max(b)], e);
        }
    }
    out
}

/// The finest a cell's shape may refine the surface, relative to the input itself: a sub-segment
/// longer than this fraction of its input edge, a piece whose circumradius exceeds this fraction
/// of its input triangle's longest edge (the size bound splits the surface down to the size).
/// The surface keeps the input's resolution, so small input angles, where splits of
/// neighbouring constraints would encroach each other without end, cannot make refinement
/// cascade; the cells there keep their shape.
const SURFACE_RESOLUTION: f64 = 0.5;

/// What to refine instead of inserting `center`, whose cavity holds the pieces `destroyed`: the
/// longest sub-segment of theirs that `center` encroaches (lies in its diametral ball), the
/// coarsest edge near `center` (the first in vertex order gave fandisk at radius-edge 1.414 40 %
/// more vertices), else the piece whose diametral ball holds `center` (or the first; the largest
/// instead gave 30 % more on mpi_triang); `None` when that would refine the surface below
/// [`SURFACE_RESOLUTION`] and below the cell size bound `size` at `center` (a sub-segment no
/// longer than `size`, a piece of circumradius at most `size / 2`). A cell larger than the size
/// bound never stops there: its circumball is empty, so a sub-segment (a piece) whose
/// diametral ball holds its centre is longer than its circumradius (has a circumradius above
/// half of it), and the size bound alone cannot split the surface below those lengths.
fn split_for(
    r: &Recovery,
    center: Point3,
    size: f64,
    destroyed: &[Piece],
    segment_of: &HashMap<[VertexId; 2], usize>,
) -> Option<Split> {
    // The longest encroached sub-segment: the coarsest part of the surface near `center`.
    let mut segment: Option<(f64, usize, [VertexId; 2])> = None;
    for &(face, _) in destroyed {
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            let pair = [a.min(b), a.max(b)];
            let Some(&e) = segment_of.get(&pair) else {
                continue;
            };
            let (pa, pb) = (r.dt.point(a), r.dt.point(b));
            let length = pa.distance(pb);
            if (pa - center).dot(pb - center) < 0.0 && segment.is_none_or(|(l, ..)| length > l) {
                segment = Some((length, e, pair));
            }
        }
    }
    if let Some((length, e, pair)) = segment {
        let [p, q] = r.constraints.edges[e].points;
        let coarse = length > SURFACE_RESOLUTION * p.distance(q) || length > size;
        return coarse.then_some(Split::Segment(e, pair));
    }
    let circle = |face: [VertexId; 3]| {
        let p = face.map(|v| r.dt.point(v));
        let c = triangle_circumcenter(p[0], p[1], p[2]);
        (c, p[0].distance(c))
    };
    let encroached = destroyed.iter().find(|(face, _)| {
        let (c, radius) = circle(*face);
        center.distance(c) < radius
    });
    let (face, f) = encroached.copied().unwrap_or(*destroyed.first()?);
    let radius = circle(face).1;
    let corners = r.constraints.facets[f].corners.map(|v| r.dt.point(v));
    let longest = (0..3)
        .map(|k| corners[k].distance(corners[(k + 1) % 3]))
        .fold(0.0, f64::max);
    (radius > SURFACE_RESOLUTION * longest || radius > 0.5 * size).then_some(Split::Piece(f, face))
}
