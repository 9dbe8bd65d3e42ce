//! Recovery of one input triangle: the in-plane Delaunay triangulation of the vertices on it
//! names the faces that should appear; the centres of the missing ones are inserted (or the
//! sub-segments they encroach split) until all are faces of the 3D triangulation.

use super::{PreserveError, Recovery};
use crate::kernel::predicates2d::{circumcenter, dot_sign, orient2d};
use crate::kernel::{Point2, Point3};
use crate::triangulation::{Delaunay2, InsertOutcome, Triangulation, VertexId};
use rustc_hash::FxHashSet;
use std::cmp::Ordering;

/// Facets with at least this many vertices keep their in-plane triangulation between steps.
const KEPT_PLANE: usize = 8;

/// The in-plane Delaunay triangulation of a facet with many vertices, kept between its steps
/// (facets at a small angle can take thousands of steps, each adding a vertex or two): the
/// vertices on a facet are only ever added to, so the new ones are inserted instead of the whole
/// triangulation being built again.
pub(super) struct Plane {
    dt: Delaunay2,
    /// Per vertex of `dt`: the triangulation vertex and its edge bits.
    vertices: Vec<(VertexId, u8)>,
    /// The triangulation vertices in `dt`.
    known: FxHashSet<VertexId>,
    /// Per cell of `dt`: the insertion epoch at which its piece was last found to be a face. A
    /// cell made by a later insertion into `dt` has a vertex newer than that, so a stamp left
    /// on a reused cell is never trusted.
    found: Vec<Option<u64>>,
}

/// What one step on a facet did.
pub(super) enum FacetStep {
    /// Every piece is a face: these faces make up the triangle.
    Recovered(Vec<[VertexId; 3]>),
    /// Points were inserted on the triangle or on its edges.
    Refined,
}

/// A vertex on the facet: which of the facet's edges it lies on (bit `k` for edge `k`; both
/// edges of a corner, none inside) and its in-plane coordinates.
struct OnFacet {
    vertex: VertexId,
    edges: u8,
    at: Point2,
}

/// An orthonormal frame of the facet's plane, at its first corner.
struct Frame {
    origin: Point3,
    u: Point3,
    v: Point3,
}

impl Frame {
    fn new([a, b, c]: [Point3; 3]) -> Self {
        let u = (b - a).normalize();
        let v = (b - a).cross(c - a).cross(u).normalize();
        Frame { origin: a, u, v }
    }

    fn project(&self, p: Point3) -> Point2 {
        let d = p - self.origin;
        Point2::new(d.dot(self.u), d.dot(self.v))
    }

    fn lift(&self, p: Point2) -> Point3 {
        self.origin + self.u * p.x + self.v * p.y
    }
}

/// A refinement planned for this step.
enum Action {
    /// Split the sub-segment between two vertices of this input edge.
    Split(usize, [VertexId; 2]),
    /// Insert this point of the plane inside the facet.
    Insert(Point2, VertexId),
}

/// The vertices on facet `f`: its corners, the Steiner points of its edges, those inside.
fn vertices_on(r: &Recovery, f: usize) -> Vec<(VertexId, u8)> {
    let mut out = Vec::new();
    for k in 0..3 {
        let corner = 1 << k | 1 << ((k + 2) % 3);
        let mut along: Vec<VertexId> = r.constraints.facet_edge(f, k).collect();
        along.pop();
        for (j, v) in along.into_iter().enumerate() {
            out.push((v, if j == 0 { corner } else { 1 << k }));
        }
    }
    out.extend(r.constraints.facets[f].interior.iter().map(|&v| (v, 0)));
    out
}

/// The vertices `on` facet `f` with their coordinates in its plane.
fn on_facet(r: &Recovery, f: usize, on: Vec<(VertexId, u8)>) -> Vec<OnFacet> {
    let frame = Frame::new(r.constraints.facets[f].corners.map(|v| r.dt.point(v)));
    on.into_iter()
        .map(|(vertex, edges)| OnFacet {
            vertex,
            edges,
            at: frame.project(r.dt.point(vertex)),
        })
        .collect()
}

/// Whether facet `f` is a union of triangulation faces (inserting nothing).
pub(super) fn is_recovered(r: &mut Recovery, f: usize) -> bool {
    matches!(pieces(r, f), Ok((_, _, missing)) if missing.is_empty())
}

/// The vertices on facet `f` in its plane, the pieces of their in-plane Delaunay triangulation
/// that are faces, and those that are not (as indices into the vertices).
#[allow(clippy::type_complexity)]
fn pieces(
    r: &mut Recovery,
    f: usize,
) -> Result<(Vec<OnFacet>, Vec<[VertexId; 3]>, Vec<[usize; 3]>), PreserveError> {
    let on = vertices_on(r, f);
    if on.len() >= KEPT_PLANE {
        return kept_pieces(r, f, on_facet(r, f, on));
    }
    if on.len() == 3 {
        let corners = r.constraints.facets[f].corners;
        return Ok(if r.has_face(corners) {
            (Vec::new(), vec![corners], Vec::new())
        } else {
            (on_facet(r, f, on), Vec::new(), vec![[0, 1, 2]])
        });
    }
    let on = on_facet(r, f, on);
    let planar: Vec<Point2> = on.iter().map(|o| o.at).collect();
    let (dt2, outcomes) = Delaunay2::from_points(&planar)?;
    let mut local = vec![usize::MAX; dt2.num_vertices()];
    for (i, outcome) in outcomes.iter().enumerate() {
        let slot = &mut local[outcome.vertex().0 as usize];
        if *slot != usize::MAX {
            return Err(PreserveError::Coincident(f));
        }
        *slot = i;
    }
    let (mut faces, mut missing) = (Vec::new(), Vec::new());
    for c in dt2.finite_cells() {
        let tri = dt2.cell(c).map(|v| local[v.0 as usize]);
        if on[tri[0]].edges & on[tri[1]].edges & on[tri[2]].edges != 0 {
            // Three points of one input edge: a sliver of rounding, not a piece of the facet.
            continue;
        }
        let face = tri.map(|i| on[i].vertex);
        if r.has_face(face) {
            faces.push(face);
        } else {
            missing.push(tri);
        }
    }
    Ok((on, faces, missing))
}

/// [`pieces`] on the kept plane of facet `f`: the new vertices `on` it are inserted, and a
/// piece whose vertices no insertion has touched since it was found to be a face still is one.
#[allow(clippy::type_complexity)]
fn kept_pieces(
    r: &mut Recovery,
    f: usize,
    on: Vec<OnFacet>,
) -> Result<(Vec<OnFacet>, Vec<[VertexId; 3]>, Vec<[usize; 3]>), PreserveError> {
    let mut plane = r.planes[f].take().map_or_else(
        || Plane {
            dt: Delaunay2::new(),
            vertices: Vec::new(),
            known: FxHashSet::default(),
            found: Vec::new(),
        },
        |kept| *kept,
    );
    let fresh: Vec<&OnFacet> = on
        .iter()
        .filter(|o| !plane.known.contains(&o.vertex))
        .collect();
    let planar: Vec<Point2> = fresh.iter().map(|o| o.at).collect();
    for (o, outcome) in fresh.iter().zip(plane.dt.insert_points(&planar)?) {
        let InsertOutcome::Inserted(v) = outcome else {
            return Err(PreserveError::Coincident(f));
        };
        let slot = v.0 as usize;
        if plane.vertices.len() <= slot {
            plane.vertices.resize(slot + 1, (VertexId(u32::MAX), 0));
        }
        plane.vertices[slot] = (o.vertex, o.edges);
        plane.known.insert(o.vertex);
    }
    let (mut faces, mut missing) = (Vec::new(), Vec::new());
    for c in plane.dt.finite_cells() {
        let [a, b, d] = plane.dt.cell(c).map(|v| plane.vertices[v.0 as usize]);
        if a.1 & b.1 & d.1 != 0 {
            continue;
        }
        let face = [a.0, b.0, d.0];
        let slot = c.0 as usize;
        if plane.found.len() <= slot {
            plane.found.resize(slot + 1, None);
        }
        let kept =
            plane.found[slot].is_some_and(|t| face.iter().all(|v| r.touched[v.0 as usize] <= t));
        if kept || r.has_face(face) {
            faces.push(face);
            plane.found[slot] = Some(r.epoch);
        } else {
            missing.push(face.map(|v| on.iter().position(|o| o.vertex == v).unwrap_or(0)));
            plane.found[slot] = None;
        }
    }
    r.planes[f] = Some(Box::new(plane));
    Ok((on, faces, missing))
}

/// One step on facet `f`: its faces if it is recovered, else refinement of its missing pieces
/// (an independent set: no planned point inside another planned piece's circle).
pub(super) fn facet_step(r: &mut Recovery, f: usize) -> Result<FacetStep, PreserveError> {
    let (on, faces, missing) = pieces(r, f)?;
    if missing.is_empty() {
        return Ok(FacetStep::Recovered(faces));
    }
    let mut plan = Plan::new(r, f, &on);
    for tri in missing {
        plan.add(&on, tri);
    }
    if plan.apply(r, f)? == 0 {
        // Nothing to insert for pieces that are missing: another pass would do the same.
        return Err(PreserveError::Stuck(f));
    }
    Ok(FacetStep::Refined)
}

/// Refines the piece `face` of facet `f` as a missing one would be (its centre, or the
/// sub-segment that centre encroaches): the cell level asks it of a piece that a cell's centre
/// would destroy. Returns how many points were inserted (none when `face` is not made of
/// vertices on `f`).
pub(super) fn split_piece(
    r: &mut Recovery,
    f: usize,
    face: [VertexId; 3],
) -> Result<usize, PreserveError> {
    let on = on_facet(r, f, vertices_on(r, f));
    let index = |v: VertexId| on.iter().position(|o| o.vertex == v);
    let (Some(a), Some(b), Some(c)) = (index(face[0]), index(face[1]), index(face[2])) else {
        return Ok(0);
    };
    let mut plan = Plan::new(r, f, &on);
    plan.add(&on, [a, b, c]);
    plan.apply(r, f)
}

/// The refinements planned for pieces of one facet.
struct Plan {
    corners: Vec<Point2>,
    boundary: Vec<Boundary>,
    planned: Vec<Point2>,
    actions: Vec<Action>,
}

impl Plan {
    fn new(r: &Recovery, f: usize, on: &[OnFacet]) -> Self {
        Plan {
            corners: (0..3).map(|k| on[corner_index(on, k)].at).collect(),
            boundary: boundary_segments(r, f, on),
            planned: Vec::new(),
            actions: Vec::new(),
        }
    }

    /// Plans the refinement of the piece `tri` (indices into `on`).
    fn add(&mut self, on: &[OnFacet], tri: [usize; 3]) {
        let [a, b, c] = tri.map(|i| on[i].at);
        let center = circumcenter(a, b, c);
        if !center.is_finite() {
            return;
        }
        let corners = &self.corners;
        let encroached = self
            .boundary
            .iter()
            .find(|s| dot_sign(center, s.ends[0], s.ends[1]) == Ordering::Less)
            .or_else(|| {
                // Outside the triangle without encroaching: split the longest sub-segment of an
                // edge the centre lies beyond.
                (0..3)
                    .filter(|&k| {
                        orient2d(corners[k], corners[(k + 1) % 3], center) != Ordering::Greater
                    })
                    .flat_map(|k| self.boundary.iter().filter(move |s| s.side == k))
                    .max_by(|s, t| s.length2().total_cmp(&t.length2()))
            });
        match encroached {
            // Splits of distinct sub-segments do not interfere.
            Some(s) => {
                let split = Action::Split(s.edge, s.vertices);
                if !self
                    .actions
                    .iter()
                    .any(|a| matches!(a, Action::Split(e, v) if *e == s.edge && *v == s.vertices))
                {
                    self.actions.push(split);
                }
            }
            None => {
                let radius2 = (center - a).length_squared();
                if !self
                    .planned
                    .iter()
                    .any(|q| (*q - center).length_squared() < radius2)
                {
                    self.planned.push(center);
                    self.actions.push(Action::Insert(center, on[tri[0]].vertex));
                }
            }
        }
    }

    /// Carries the plan out; returns how many points were inserted.
    fn apply(self, r: &mut Recovery, f: usize) -> Result<usize, PreserveError> {
        let frame = Frame::new(r.constraints.facets[f].corners.map(|v| r.dt.point(v)));
        let before = r.dt.num_vertices();
        for action in self.actions {
            match action {
                Action::Split(e, pair) => r.split(e, pair)?,
                Action::Insert(at, near) => {
                    let v = r
                        .insert(frame.lift(at), near)?
                        .ok_or(PreserveError::Coincident(f))?;
                    r.constraints.facets[f].interior.push(v);
                    r.join_facet(v, f);
                    r.facet_steiner += 1;
                }
            }
        }
        Ok(r.dt.num_vertices() - before)
    }
}

/// Index in `on` of corner `k` (the vertices come edge by edge, each edge from its corner).
fn corner_index(on: &[OnFacet], k: usize) -> usize {
    let mask = 1 << k | 1 << ((k + 2) % 3);
    on.iter().position(|o| o.edges == mask).unwrap_or(0)
}

/// A sub-segment on the boundary of a facet.
struct Boundary {
    /// The facet's edge (0..3) it lies on.
    side: usize,
    /// Its input edge.
    edge: usize,
    vertices: [VertexId; 2],
    ends: [Point2; 2],
}

impl Boundary {
    fn length2(&self) -> f64 {
        (self.ends[1] - self.ends[0]).length_squared()
    }
}

/// The sub-segments on the boundary of facet `f`. `on` starts with that boundary, side by side,
/// each side from its first corner (see [`vertices_on`]): a sub-segment joins each of those
/// vertices to the next, and the last to the first.
fn boundary_segments(r: &Recovery, f: usize, on: &[OnFacet]) -> Vec<Boundary> {
    let facet = &r.constraints.facets[f];
    let sides = facet.edges.map(|e| {
        r.constraints.edges[e as usize]
            .chain
            .len()
            .saturating_sub(1)
    });
    let count: usize = sides.iter().sum();
    let mut out = Vec::with_capacity(count);
    let mut i = 0;
    for (side, &along) in sides.iter().enumerate() {
        for _ in 0..along {
            let (a, b) = (&on[i], &on[(i + 1) % count]);
            out.push(Boundary {
                side,
                edge: facet.edges[side] as usize,
                vertices: [a.vertex, b.vertex],
                ends: [a.at, b.at],
            });
            i += 1;
        }
    }
    out
}
