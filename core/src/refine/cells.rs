//! The cell level: tetrahedra of the restricted Delaunay triangulation (circumcentre inside the
//! domain) that are too big or badly shaped (thesis, ch. 3, rule R3). Their circumcentre is the
//! refinement point; the surface level refuses it when it lies in a surface ball (R3.2).

use super::criteria::CellCriteria;
use super::engine::{Candidate, Check, MesherLevel};
use super::facets::ClearFacets;
use super::geometry::{
    FLAT_CANDIDATES, cell_vertices, crowds_a_vertex, flat_cell_refinement_point, is_flat,
    is_same_cell, power_distance, shortest_edge,
};
use super::queue::RefineQueue;
use crate::kernel::Point3;
use crate::oracle::{Aabb, OUTSIDE, Oracle, SubdomainId, SurfaceHit};
use crate::triangulation::{CellId, InsertReport, Triangulation, VertexId};

/// A queued cell and its vertices when queued (to detect that it was destroyed).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct QueuedCell {
    pub cell: CellId,
    pub vertices: [VertexId; 4],
    /// For a flat cell, which of its candidate refinement points to propose (see
    /// [`flat_cell_refinement_point`]): the next one is tried when a point is refused forever.
    pub attempt: u8,
}

pub struct CellLevel<'o> {
    oracle: &'o dyn Oracle,
    criteria: CellCriteria,
    /// Subdomain of each cell's circumcentre, indexed by `CellId` ([`OUTSIDE`] for infinite cells).
    subdomain: Vec<SubdomainId>,
    queue: RefineQueue<QueuedCell>,
    /// Squared circumradius of the cell whose circumcentre was last proposed.
    proposed_radius2: f64,
    /// Circumradius under which a cell that is not flat is never refined (see
    /// [`CellLevel::min_radius`]).
    min_radius: f64,
    /// The cell last proposed is flat (its point is one of several candidates).
    proposed_flat: bool,
    hits: Vec<SurfaceHit>,
    /// When set, a circumcentre outside this box is outside the domain without asking the
    /// oracle (see [`CellLevel::outside_box`]).
    domain_box: Option<Aabb>,
    /// The surface level's answers for dual edges (see [`CellLevel::share_clear_facets`]).
    clear_facets: Option<ClearFacets>,
}

impl<'o> CellLevel<'o> {
    pub fn new(oracle: &'o dyn Oracle, criteria: CellCriteria) -> Self {
        CellLevel {
            oracle,
            criteria,
            subdomain: Vec::new(),
            queue: RefineQueue::default(),
            proposed_radius2: 0.0,
            proposed_flat: false,
            min_radius: 0.0,
            hits: Vec::new(),
            domain_box: None,
            clear_facets: None,
        }
    }

    /// Take a new cell's subdomain from its old neighbour when the surface level found their
    /// shared facet's dual edge crossing no boundary, instead of querying that segment again.
    /// The surface level must come before this one in the engine, so that the facets of new cells
    /// are up to date when this level labels them.
    pub fn share_clear_facets(&mut self, clear: ClearFacets) {
        self.clear_facets = Some(clear);
    }

    /// Label circumcentres outside the domain's bounding box (enlarged) as outside directly. A
    /// regular triangulation has nearly flat cells with orthocentres ~1e13 away, where a
    /// segment query to a neighbour's centre has no digit left and could label them inside.
    pub fn outside_box(mut self) -> Self {
        let b = self.oracle.bounding_box();
        let margin = Point3::splat(0.1 * b.diagonal());
        self.domain_box = Some(Aabb {
            min: b.min - margin,
            max: b.max + margin,
        });
        self
    }

    /// Never refine a cell smaller than `r` for size or shape (flat cells still are): the
    /// surface level's floor ([`super::facets::SurfaceLevel::min_radius`]) for the cells, whose
    /// circumcentres near an unresolved seam would otherwise converge to it.
    pub fn min_radius(mut self, r: f64) -> Self {
        self.min_radius = r;
        self
    }

    /// Give cell `c` another label (the manifold relabelling, [`super::manifold`]); the queue is
    /// left as it is: relabelling comes after refinement.
    pub(crate) fn set_subdomain(&mut self, c: CellId, sub: SubdomainId) {
        if let Some(s) = self.subdomain.get_mut(c.0 as usize) {
            *s = sub;
        }
    }

    /// The subdomain a cell belongs to: the one containing its circumcentre.
    pub fn subdomain(&self, c: CellId) -> SubdomainId {
        self.subdomain.get(c.0 as usize).copied().unwrap_or(OUTSIDE)
    }

    /// Label and queue a new cell. `apex` is the vertex just inserted: the facet opposite it is
    /// on the cavity boundary, and the old cell across it has a known subdomain.
    fn update_cell<T: Triangulation<Point = Point3>>(
        &mut self,
        tr: &T,
        c: CellId,
        apex: Option<VertexId>,
    ) {
        let i = c.0 as usize;
        if self.subdomain.len() <= i {
            self.subdomain
                .resize(tr.cell_capacity().max(i + 1), OUTSIDE);
        }
        if tr.is_infinite_cell(c) {
            self.subdomain[i] = OUTSIDE;
            return;
        }
        let center = tr.circumcenter(c);
        // A flat cell has no circumcentre; it lies on a planar patch and is left outside.
        let sub = if !center.is_finite() || self.domain_box.is_some_and(|b| !b.contains(center)) {
            OUTSIDE
        } else if let Some(sub) =
            apex.and_then(|v| self.subdomain_from_old_neighbour(tr, c, center, v))
        {
            sub
        } else {
            self.oracle.subdomain(center)
        };
        self.subdomain[i] = sub;
        if sub == OUTSIDE {
            return;
        }
        let vertices = cell_vertices(tr, c);
        if let Some(priority) = self.badness(tr, &vertices, center, sub) {
            self.queue.push(
                priority,
                QueuedCell {
                    cell: c,
                    vertices,
                    attempt: 0,
                },
            );
        }
    }

    /// The subdomain of the old neighbour of `c` across the facet opposite `apex`, when the segment
    /// between the two circumcentres crosses no boundary: a short segment query instead of an
    /// inside test, which casts a ray out of the whole domain.
    fn subdomain_from_old_neighbour<T: Triangulation<Point = Point3>>(
        &mut self,
        tr: &T,
        c: CellId,
        center: Point3,
        apex: VertexId,
    ) -> Option<SubdomainId> {
        let i = tr.cell(c).as_ref().iter().position(|&v| v == apex)?;
        let n = tr.neighbor(c, i);
        if let Some(clear) = &self.clear_facets {
            // An infinite neighbour is outside: a clear dual ray leaves the domain.
            return clear.is_clear(c, i).then(|| self.subdomain(n));
        }
        if tr.is_infinite_cell(n) {
            return None;
        }
        let other = tr.circumcenter(n);
        if !other.is_finite() {
            return None;
        }
        self.hits.clear();
        self.oracle.segment_hits(center, other, &mut self.hits);
        self.hits.is_empty().then(|| self.subdomain(n))
    }

    /// Queue cell `c` whatever its quality, first in line (a flat cell found inside after
    /// refinement, or a cell at a non-manifold spot of the boundary).
    pub fn force<T: Triangulation<Point = Point3>>(&mut self, tr: &T, c: CellId) {
        if tr.is_live(c) && !tr.is_infinite_cell(c) {
            let vertices = cell_vertices(tr, c);
            self.queue.push(
                f64::INFINITY,
                QueuedCell {
                    cell: c,
                    vertices,
                    attempt: 0,
                },
            );
        }
    }

    /// How much a cell of subdomain `sub` violates the criteria (`None`: it satisfies them).
    /// A flat cell (four nearly coplanar vertices, often cocircular points on a planar patch
    /// whose radius-edge ratio is fine) is always bad: a solver cannot use it.
    fn badness<T: Triangulation<Point = Point3>>(
        &self,
        tr: &T,
        vertices: &[VertexId; 4],
        center: Point3,
        sub: SubdomainId,
    ) -> Option<f64> {
        let p = vertices.map(|v| tr.point(v));
        if is_flat(&p) {
            return Some(f64::INFINITY);
        }
        let radius = power_distance(tr, vertices[0], center).max(0.0).sqrt();
        if radius < self.min_radius {
            return None;
        }
        let size_excess = radius / self.criteria.size.at(center, sub.0);
        let shape_excess = if self.criteria.radius_edge_ratio > 0.0 {
            radius / shortest_edge(&p) / self.criteria.radius_edge_ratio
        } else {
            0.0
        };
        let worst = size_excess.max(shape_excess);
        (worst > 1.0).then_some(worst)
    }
}

impl<'o, T: Triangulation<Point = Point3>> MesherLevel<T> for CellLevel<'o> {
    type Element = QueuedCell;

    fn name(&self) -> &'static str {
        "cells"
    }

    fn scan(&mut self, tr: &T) {
        self.subdomain.resize(tr.cell_capacity(), OUTSIDE);
        let cells: Vec<CellId> = tr.finite_cells().collect();
        for c in cells {
            self.update_cell(tr, c, None);
        }
    }

    fn next_element(&mut self, tr: &T) -> Option<QueuedCell> {
        while let Some(&q) = self.queue.peek() {
            if is_same_cell(tr, q.cell, &q.vertices) {
                return Some(q);
            }
            self.queue.pop();
        }
        None
    }

    /// A flat cell is queued again with its next candidate point: when the point was inserted
    /// the cell is gone and the copy is discarded as stale, and when it was refused forever
    /// (inside a protecting ball) the next candidate is tried.
    fn pop_element(&mut self) {
        if let Some(&q) = self.queue.peek()
            && self.proposed_flat
            && usize::from(q.attempt) + 1 < FLAT_CANDIDATES
        {
            self.queue.pop();
            self.queue.push(
                f64::INFINITY,
                QueuedCell {
                    attempt: q.attempt + 1,
                    ..q
                },
            );
            return;
        }
        self.queue.pop();
    }

    fn refinement_point(&mut self, tr: &T, q: &QueuedCell) -> Option<Candidate<Point3>> {
        self.proposed_flat = is_flat(&q.vertices.map(|v| tr.point(v)));
        if self.proposed_flat {
            let (point, radius2) =
                flat_cell_refinement_point(tr, &q.vertices, usize::from(q.attempt))?;
            self.proposed_radius2 = radius2;
            return Some(Candidate {
                point,
                hint: Some(q.cell),
            });
        }
        let center = tr.circumcenter(q.cell);
        self.proposed_radius2 = power_distance(tr, q.vertices[0], center);
        Some(Candidate {
            point: center,
            hint: Some(q.cell),
        })
    }

    fn check(&mut self, tr: &T, c: &Candidate<Point3>, _own: bool) -> Check {
        if crowds_a_vertex(tr, c, self.proposed_radius2) {
            Check::RejectedForever
        } else {
            Check::Accepted
        }
    }

    fn after_insertion(&mut self, tr: &T, v: VertexId, report: &InsertReport, _own: bool) {
        for &c in &report.removed {
            if let Some(s) = self.subdomain.get_mut(c.0 as usize) {
                *s = OUTSIDE;
            }
        }
        for &c in &report.created {
            self.update_cell(tr, c, Some(v));
        }
    }

    fn pending(&self) -> usize {
        self.queue.len()
    }
}
