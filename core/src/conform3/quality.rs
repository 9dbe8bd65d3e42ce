//! Quality refinement of a conforming tetrahedralisation (the cell level of Shewchuk's Delaunay
//! refinement of PLCs): a cell inside the domain whose radius-edge ratio or circumradius is too
//! large gets its circumcentre, unless that point's cavity would destroy a piece of an input
//! triangle. Then the centre is not inserted: the sub-segment of that piece it encroaches is
//! split, else the piece itself, as recovery refines a missing piece. Cells are refined in
//! rounds, worst first; between rounds recovery restores the pieces that surface points broke.
//!
//! Every insertion of a centre keeps every piece (its cavity holds none), so the pieces and the
//! cells' subdomains found at the start of a round stay true for the centres of that round; the
//! splits of the surface, which break pieces, wait for the end of the round.

use super::regions::{cell_subdomains, faces_to_move_across, key, piece_facets};
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
use crate::triangulation::{CellId, ConflictZone, Triangulation, VertexId};
use rustc_hash::{FxHashMap as HashMap, FxHashSet as HashSet};

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
pub(super) fn refine(
    r: &mut Recovery,
    faces: &mut Vec<Vec<[VertexId; 3]>>,
    oracle: &dyn Oracle,
    criteria: Option<&CellCriteria>,
    min_radius: f64,
) -> Result<(usize, Option<RefineError>), PreserveError> {
    let mut zone = ConflictZone::default();
    let mut inserted = 0;
    // Cells left as they are because refining them would refine the surface too finely: not
    // tried again while they exist.
    let mut kept: HashSet<[VertexId; 4]> = HashSet::default();
    for _ in 0..MAX_ROUNDS {
        if let Some(stop) = r.clock.stop() {
            return Ok((inserted, Some(stop)));
        }
        let facet_of = piece_facets(faces);
        let subdomain = cell_subdomains(&r.dt, &facet_of, oracle);
        let bad = bad_cells(r, &subdomain, &facet_of, criteria, min_radius);
        if bad.is_empty() {
            break;
        }
        let segment_of = sub_segments(r);
        let mut splits = Vec::new();
        let mut in_zone = vec![false; r.dt.cell_capacity()];
        let before = r.dt.num_vertices();
        for (cell, vertices) in bad {
            if !is_same_cell(&r.dt, cell, &vertices) || kept.contains(&vertices) {
                continue;
            }
            // The first candidate whose cavity keeps every piece, else the first candidate and
            // the pieces it would destroy.
            let mut chosen: Option<(Point3, Vec<Piece>)> = None;
            for center in refinement_points(r, cell, &vertices) {
                r.dt.conflict_zone(center, Some(cell), &mut zone);
                if zone.cells.is_empty() {
                    continue;
                }
                in_zone.resize(r.dt.cell_capacity(), false);
                for &c in &zone.cells {
                    in_zone[c.0 as usize] = true;
                }
                let destroyed = destroyed_pieces(r, &zone, &in_zone, &facet_of);
                for &c in &zone.cells {
                    in_zone[c.0 as usize] = false;
                }
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
                let v = match r.insert(center, vertices[0]) {
                    Err(PreserveError::Stopped(stop)) => return Ok((inserted, Some(stop))),
                    v => v?,
                };
                if let Some(v) = v {
                    r.inside.push(v);
                    inserted += 1;
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
                    Some(split) => splits.push(split),
                    None => {
                        kept.insert(vertices);
                    }
                }
            }
        }
        splits.sort_unstable();
        splits.dedup();
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
    }
    Ok((inserted, None))
}

/// The cells inside the domain that fail `criteria`, and the flat ones that will not move
/// outside when the complex is built (see [`faces_to_move_across`]), worst first, flat cells
/// before all (ties by vertices, so the order is the same on every run), each with its vertices
/// to tell whether it still exists.
fn bad_cells(
    r: &Recovery,
    subdomain: &[SubdomainId],
    facet_of: &HashMap<[VertexId; 3], usize>,
    criteria: Option<&CellCriteria>,
    min_radius: f64,
) -> Vec<(CellId, [VertexId; 4])> {
    let mut bad: Vec<(f64, CellId, [VertexId; 4])> = Vec::new();
    for c in r.dt.finite_cells() {
        if subdomain[c.0 as usize] == OUTSIDE {
            continue;
        }
        let vertices = cell_vertices(&r.dt, c);
        let p = vertices.map(|v| r.dt.point(v));
        if is_flat(&p) {
            let stays = faces_to_move_across(&r.dt, c, subdomain, facet_of).is_none();
            let radius = flat_cell_refinement_point(&r.dt, &vertices, 0).map(|(_, r2)| r2.sqrt());
            let floor = if is_flat_within(&p, CHECKER_FLAT_VOLUME) {
                FLAT_FLOOR * min_radius
            } else {
                min_radius
            };
            if stays && radius.is_some_and(|radius| radius >= floor) {
                bad.push((f64::INFINITY, c, vertices));
            }
            continue;
        }
        let Some(criteria) = criteria else {
            continue;
        };
        let sub = subdomain[c.0 as usize];
        let center = r.dt.circumcenter(c);
        let radius = center.distance(p[0]);
        if radius.is_nan() || radius < min_radius {
            continue;
        }
        let shortest = shortest_edge(&p);
        let shape = if criteria.radius_edge_ratio > 0.0 {
            radius / shortest / criteria.radius_edge_ratio
        } else {
            0.0
        };
        let worst = shape.max(radius / criteria.size.at(center, sub.0));
        if worst > 1.0 {
            bad.push((worst, c, vertices));
        }
    }
    bad.sort_unstable_by(|a, b| b.0.total_cmp(&a.0).then(a.2.cmp(&b.2)));
    bad.into_iter().map(|(_, c, v)| (c, v)).collect()
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

/// The pieces between two cells of `zone` (sorted vertices, with their input triangle): those
/// inserting the zone's point would destroy.
fn destroyed_pieces(
    r: &Recovery,
    zone: &ConflictZone,
    in_zone: &[bool],
    facet_of: &HashMap<[VertexId; 3], usize>,
) -> Vec<Piece> {
    let mut out = Vec::new();
    for &c in &zone.cells {
        let cell = cell_vertices(&r.dt, c);
        for i in 0..4 {
            let n = r.dt.neighbor(c, i);
            if n.0 < c.0 || !in_zone[n.0 as usize] {
                continue;
            }
            let face = key(facet_vertices(&cell, i));
            if let Some(&f) = facet_of.get(&face) {
                out.push((face, f));
            }
        }
    }
    out.sort_unstable();
    out
}

/// The finest a cell's shape may refine the surface, relative to the input itself: a sub-segment
/// longer than this fraction of its input edge, a piece whose circumradius exceeds this fraction
/// of its input triangle's longest edge (the size bound splits the surface down to the size).
/// The surface keeps the input's resolution, so small input angles, where splits of
/// neighbouring constraints would encroach each other without end, cannot make refinement
/// cascade; the cells there keep their shape.
const SURFACE_RESOLUTION: f64 = 0.5;

/// What to refine instead of inserting `center`, whose cavity holds the pieces `destroyed`: a
/// sub-segment of theirs that `center` encroaches (lies in its diametral ball), else the piece
/// whose diametral ball holds `center` (or the first); `None` when that would refine the surface
/// below [`SURFACE_RESOLUTION`] and below `size` (the cell size bound at `center`).
fn split_for(
    r: &Recovery,
    center: Point3,
    size: f64,
    destroyed: &[Piece],
    segment_of: &HashMap<[VertexId; 2], usize>,
) -> Option<Split> {
    for &(face, _) in destroyed {
        for k in 0..3 {
            let (a, b) = (face[k], face[(k + 1) % 3]);
            let pair = [a.min(b), a.max(b)];
            let Some(&e) = segment_of.get(&pair) else {
                continue;
            };
            let (pa, pb) = (r.dt.point(a), r.dt.point(b));
            if (pa - center).dot(pb - center) < 0.0 {
                let [p, q] = r.constraints.edges[e].points;
                let length = pa.distance(pb);
                let coarse = length > SURFACE_RESOLUTION * p.distance(q) || length > 2.0 * size;
                return coarse.then_some(Split::Segment(e, pair));
            }
        }
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
    let (face, f) = encroached.copied().unwrap_or(destroyed[0]);
    let corners = r.constraints.facets[f].corners.map(|v| r.dt.point(v));
    let longest = (0..3)
        .map(|k| corners[k].distance(corners[(k + 1) % 3]))
        .fold(0.0, f64::max);
    let radius = circle(face).1;
    (radius > SURFACE_RESOLUTION * longest || radius > size).then_some(Split::Piece(f, face))
}
