//! Moving a vertex (new position, new weight) of a 3D triangulation, as mesh optimisation needs.
//!
//! The vertex is first removed: its star is re-triangulated by the cells of the triangulation of
//! its link vertices that the vertex conflicts with. Those cells fill the hole exactly, because
//! the cells of the triangulation without the vertex that it conflicts with are empty of every
//! other point, so they belong to the small triangulation too, and the symbolic perturbation
//! orders points by position, so both triangulations break ties alike. It is then inserted at
//! its new place under the same id, so data indexed by vertex stays valid. The result is the
//! unique (perturbed) Delaunay or regular triangulation of the moved points.

use super::cavity::HashMarks;
use super::regular::validate_weight;
use super::{ConflictKernel, INFINITE, NO_CELL, Triangulation3, pack, validate_point};
use crate::kernel::{Point3, Sign, WeightedPoint3, orient3d};
use crate::triangulation::{CellId, InsertReport, Triangulation, TriangulationError, VertexId};
use rustc_hash::FxHashMap;

/// The net change of one [`Triangulation3::move_vertex`], refused moves included (a refused move
/// rebuilds the same cells, usually in other slots).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct MoveReport {
    /// Every destroyed cell that existed before the move: its slot (which the move may have
    /// reused) and its vertices in the orientation they had.
    pub removed: Vec<(CellId, [VertexId; 4])>,
    /// The cells created by the move and still live after it.
    pub created: Vec<CellId>,
}

impl MoveReport {
    fn clear(&mut self) {
        self.removed.clear();
        self.created.clear();
    }
}

/// One cell filling the hole of a removed vertex: its vertices and, for each facet, either the
/// index of another filling cell with the facet's index there, or the packed outside neighbour.
struct FillCell {
    verts: [u32; 4],
    links: [Link; 4],
}

#[derive(Clone, Copy)]
enum Link {
    Fill(usize, usize),
    Outside(u32),
}

/// A [`Link`] as planned, before the cells around the hole are known by slot: an outside
/// neighbour is named by the facet it shares (sorted vertices).
#[derive(Clone, Copy, Debug)]
enum PlannedLink {
    Fill(usize, usize),
    Outside([u32; 3]),
}

/// One planned filling cell: its vertices and links.
type PlannedCell = ([u32; 4], [PlannedLink; 4]);

/// A planned removal: the vertex, the sorted vertices of its star's link, the place (point,
/// weight) of the vertex and of each link vertex, which determine the fill, and the fill.
#[derive(Clone, Debug)]
pub(super) struct FillMemo {
    vertex: u32,
    link: Vec<u32>,
    places: Vec<(Point3, f64)>,
    cells: Vec<PlannedCell>,
}

/// The vertices of facet `i` of cell `q` (the three others than `q[i]`), sorted.
pub(super) fn sorted_facet(q: [u32; 4], i: usize) -> [u32; 3] {
    let mut f = [q[(i + 1) % 4], q[(i + 2) % 4], q[(i + 3) % 4]];
    f.sort_unstable();
    f
}

impl<K: ConflictKernel> Triangulation3<K> {
    /// Moves finite vertex `v` to `p` with weight `w` (the weight is ignored by a Delaunay
    /// triangulation). Returns `Ok(true)` when done; `Ok(false)`, with the triangulation as it
    /// was (cells possibly in other slots), when `v` is a vertex of the convex hull, when `p` is
    /// not inside a finite cell, or lies on a vertex or on the hull (a move may not change the
    /// hull or hit a vertex), or when the moved vertex would be hidden or would hide another one.
    /// `report` gets the net change either way.
    pub fn move_vertex(
        &mut self,
        v: VertexId,
        p: Point3,
        w: f64,
        report: &mut MoveReport,
    ) -> Result<bool, TriangulationError> {
        self.relocate(v, p, w, report, true)
    }

    /// Moves finite vertex `v` back to `place`, where it was a vertex of this triangulation
    /// before a move and every other vertex is where it was then (an undo). Such a place is
    /// neither on the hull nor on another vertex, so, unlike [`Self::move_vertex`], it is not
    /// checked (a check that refused it would keep a move the caller wanted undone).
    pub fn move_vertex_back(
        &mut self,
        v: VertexId,
        place: WeightedPoint3,
        report: &mut MoveReport,
    ) -> Result<bool, TriangulationError> {
        self.relocate(v, place.point, place.weight, report, false)
    }

    /// Undoes the move of `v` that `report` records (a [`Self::move_vertex`] that returned
    /// `Ok(true)`, with nothing changed since), `v` going back to `p` with weight `w`: the cells
    /// the move destroyed are put back as they were, linked to the cells around them by their
    /// facets, without a predicate or a search (an optimiser undoes most of its trial moves, and
    /// rebuilding the old star by [`Self::move_vertex_back`] cost as much as the move). `report`
    /// then records the undo. Returns false, with nothing changed, when `report` does not fit the
    /// triangulation (the caller then moves the vertex back instead).
    pub fn undo_move(&mut self, v: VertexId, p: Point3, w: f64, report: &mut MoveReport) -> bool {
        let index = v.0 as usize;
        if index >= self.points.len() || self.lower.is_some() || report.created.is_empty() {
            return false;
        }
        let created: Vec<u32> = report.created.iter().map(|c| c.0).collect();
        let mut members = created.clone();
        members.sort_unstable();
        if created
            .iter()
            .any(|&c| c as usize >= self.cells.len() || !self.live(c))
        {
            return false;
        }
        // The facets of the changed region's boundary: the cell outside each, seen from inside.
        let mut outside: FxHashMap<[u32; 3], u32> =
            FxHashMap::with_capacity_and_hasher(2 * created.len(), Default::default());
        for &c in &created {
            let r = self.cells[c as usize];
            for i in 0..4 {
                let nb = r.n[i] >> 2;
                if members.binary_search(&nb).is_err()
                    && outside.insert(sorted_facet(r.v, i), r.n[i]).is_some()
                {
                    return false;
                }
            }
        }
        // Each facet of the old cells is on that boundary or shared by two of them.
        let old: Vec<[u32; 4]> = report.removed.iter().map(|(_, q)| q.map(|x| x.0)).collect();
        let mut inner: FxHashMap<[u32; 3], usize> =
            FxHashMap::with_capacity_and_hasher(2 * old.len(), Default::default());
        let mut on_boundary = 0;
        for q in &old {
            for i in 0..4 {
                let f = sorted_facet(*q, i);
                if outside.contains_key(&f) {
                    on_boundary += 1;
                } else {
                    *inner.entry(f).or_default() += 1;
                }
            }
        }
        if on_boundary != outside.len() || inner.values().any(|&n| n != 2) {
            return false;
        }
        let finite = |q: &[u32; 4]| usize::from(!q.contains(&INFINITE));
        let mut undo = MoveReport::default();
        for &c in &created {
            let q = self.cells[c as usize].v;
            self.num_finite -= finite(&q);
            undo.removed.push((CellId(c), q.map(VertexId)));
            self.free_cell(c);
        }
        self.points[index] = p;
        self.filter.include(p);
        self.kernel.set_weight(v.0, w);
        self.kernel.unhide(v.0);
        let ids: Vec<u32> = old.iter().map(|&q| self.alloc_cell(q)).collect();
        let mut open: FxHashMap<[u32; 3], u32> =
            FxHashMap::with_capacity_and_hasher(old.len() * 2, Default::default());
        for (k, q) in old.iter().enumerate() {
            let c = ids[k];
            for i in 0..4 {
                let f = sorted_facet(*q, i);
                let link = match outside.get(&f) {
                    Some(&out) => out,
                    None => match open.remove(&f) {
                        Some(other) => other,
                        None => {
                            open.insert(f, pack(c, i));
                            continue;
                        }
                    },
                };
                self.cells[c as usize].n[i] = link;
                self.cells[(link >> 2) as usize].n[(link & 3) as usize] = pack(c, i);
            }
            self.num_finite += finite(q);
        }
        for &c in &ids {
            self.touch_vertices(c);
        }
        self.last = ids[0];
        undo.created = ids.into_iter().map(CellId).collect();
        *report = undo;
        true
    }

    fn relocate(
        &mut self,
        v: VertexId,
        p: Point3,
        w: f64,
        report: &mut MoveReport,
        check_place: bool,
    ) -> Result<bool, TriangulationError> {
        report.clear();
        let index = v.0 as usize;
        validate_point(p, index)?;
        if K::WEIGHTED {
            validate_weight(w, index)?;
        }
        if self.lower.is_some() || index >= self.points.len() || self.is_hidden(v) {
            return Ok(false);
        }
        let (old_p, old_w) = (self.pt(v.0), self.kernel.weight(v.0));
        if self.move_in_place(v.0, p, w, report) {
            return Ok(true);
        }
        if check_place && p != old_p && !self.inside_a_cell(p, v) {
            return Ok(false);
        }
        if !self.remove_interior(v.0, report) {
            return Ok(false);
        }
        match self.reinsert(v.0, p, w, report) {
            Some(hidden) if hidden.is_empty() => return Ok(true),
            Some(hidden) => {
                // It hid vertices: take it out again and bring them back, then put it back.
                let removed = self.remove_interior(v.0, report);
                debug_assert!(
                    removed,
                    "a vertex inside a cell and off the hull is not on the hull"
                );
                for x in hidden {
                    self.reinsert(x.0, self.pt(x.0), self.kernel.weight(x.0), report);
                }
            }
            None => {}
        }
        self.reinsert(v.0, old_p, old_w, report);
        Ok(false)
    }

    /// Moves interior vertex `v` to `(p, w)` keeping every cell, when the cells around it stay
    /// positively oriented and every facet of them stays locally regular (then the triangulation
    /// is still the perturbed regular one, so rebuilding the star would give the same cells):
    /// most optimiser moves are small, and this saves removing and reinserting the vertex.
    /// Returns false, with nothing changed, otherwise; on success `report` lists the cells of the
    /// star as both removed and created (their vertices are the same, their shape is not).
    fn move_in_place(&mut self, v: u32, p: Point3, w: f64, report: &mut MoveReport) -> bool {
        let mut star = Vec::new();
        self.incident_cells(VertexId(v), &mut star);
        let positive = |c: &CellId| {
            let r = &self.cells[c.0 as usize];
            !Self::is_infinite_record(r) && {
                let t = r.v.map(|x| if x == v { p } else { self.pt(x) });
                orient3d(t[0], t[1], t[2], t[3]) == Sign::Positive
            }
        };
        if star.is_empty() || !star.iter().all(positive) {
            return false;
        }
        let (old_p, old_w) = (self.pt(v), self.kernel.weight(v));
        self.points[v as usize] = p;
        self.filter.include(p);
        self.kernel.set_weight(v, w);
        let regular = star.iter().all(|&c| {
            let r = self.cells[c.0 as usize];
            r.n.iter().all(|&nb| {
                let x = self.cells[(nb >> 2) as usize].v[(nb & 3) as usize];
                x == INFINITE || !self.in_conflict(c.0, self.pt(x), self.kernel.weight(x))
            })
        });
        if !regular {
            self.points[v as usize] = old_p;
            self.kernel.set_weight(v, old_w);
            return false;
        }
        report.removed.extend(
            star.iter()
                .map(|&c| (c, self.cells[c.0 as usize].v.map(VertexId))),
        );
        report.created.extend_from_slice(&star);
        true
    }

    /// Whether `p` lies in a finite cell (found by walking from a cell of `v`) and can take a
    /// vertex there without touching the hull: strictly inside it, or on its boundary (a
    /// surface vertex moving in the plane of a planar patch lies in the plane of its facets)
    /// but on none of its vertices, none of which is on the hull.
    fn inside_a_cell(&self, p: Point3, v: VertexId) -> bool {
        let c = self.locate_cell_under(&self.query_filter(p), p, self.vertex_cell(v).map(|c| c.0));
        let r = self.cells[c as usize];
        if Self::is_infinite_record(&r) {
            return false;
        }
        let signs = (0..4).map(|i| {
            let mut t = r.v.map(|x| self.pt(x));
            t[i] = p;
            orient3d(t[0], t[1], t[2], t[3])
        });
        let mut on_boundary = false;
        for sign in signs {
            match sign {
                Sign::Positive => {}
                Sign::Zero => on_boundary = true,
                Sign::Negative => return false,
            }
        }
        !on_boundary || r.v.iter().all(|&x| self.pt(x) != p && !self.on_hull(x))
    }

    /// Whether vertex `x` is a vertex of an infinite cell.
    fn on_hull(&self, x: u32) -> bool {
        let mut cells = Vec::new();
        self.incident_cells(VertexId(x), &mut cells);
        cells
            .iter()
            .any(|c| Self::is_infinite_record(&self.cells[c.0 as usize]))
    }

    /// Removes interior vertex `v` (no-op returning false for a hull vertex or when the fill
    /// cannot be found), recording the change in `report`. `v` keeps its point and weight but is
    /// in no cell (hidden, for the weighted kernel).
    fn remove_interior(&mut self, v: u32, report: &mut MoveReport) -> bool {
        let Some(fill) = self.plan_fill(v) else {
            return false;
        };
        let mut star = Vec::new();
        self.incident_cells(VertexId(v), &mut star);
        for &c in &star {
            self.destroy(c.0, report);
        }
        self.num_finite -= star.len();
        let ids: Vec<u32> = fill.iter().map(|f| self.alloc_cell(f.verts)).collect();
        for (k, f) in fill.iter().enumerate() {
            for (i, link) in f.links.iter().enumerate() {
                self.cells[ids[k] as usize].n[i] = match *link {
                    Link::Fill(other, j) => pack(ids[other], j),
                    Link::Outside(out) => {
                        self.cells[(out >> 2) as usize].n[(out & 3) as usize] = pack(ids[k], i);
                        out
                    }
                };
            }
            self.touch_vertices(ids[k]);
        }
        self.num_finite += ids.len();
        self.vertex_cell[v as usize] = NO_CELL;
        self.kernel.hide(v);
        self.last = ids[0];
        report.created.extend(ids.into_iter().map(CellId));
        true
    }

    /// The cells filling the star of interior vertex `v` once removed, computed without touching
    /// the triangulation; `None` for a hull vertex (or, defensively, an inconsistent fill). The
    /// plan is kept: an optimiser tries several places for one vertex, undoing each trial, and
    /// the hole to fill is the same each time.
    fn plan_fill(&mut self, v: u32) -> Option<Vec<FillCell>> {
        let mut star = Vec::new();
        self.incident_cells(VertexId(v), &mut star);
        let mut outside: FxHashMap<[u32; 3], u32> =
            FxHashMap::with_capacity_and_hasher(star.len(), Default::default());
        let mut link = Vec::with_capacity(3 * star.len());
        for &c in &star {
            let r = self.cells[c.0 as usize];
            if Self::is_infinite_record(&r) {
                return None;
            }
            let i = r.v.iter().position(|&x| x == v)?;
            let f = sorted_facet(r.v, i);
            link.extend_from_slice(&f);
            outside.insert(f, r.n[i]);
        }
        link.sort_unstable();
        link.dedup();
        let places: Vec<(Point3, f64)> = std::iter::once(v)
            .chain(link.iter().copied())
            .map(|x| (self.pt(x), self.kernel.weight(x)))
            .collect();
        let memo = match self.fill_memo.take() {
            // The same points and weights have the same regular triangulation, so the same
            // star and the same fill.
            Some(m) if m.vertex == v && m.link == link && m.places == places => m,
            _ => Box::new(FillMemo {
                vertex: v,
                cells: self.triangulate_hole(v, &link, star.len())?,
                link,
                places,
            }),
        };
        let fill = memo
            .cells
            .iter()
            .map(|(verts, links)| {
                let mut resolved = [Link::Outside(0); 4];
                for (l, plan) in resolved.iter_mut().zip(links) {
                    *l = match *plan {
                        PlannedLink::Fill(k, j) => Link::Fill(k, j),
                        PlannedLink::Outside(f) => Link::Outside(*outside.get(&f)?),
                    };
                }
                Some(FillCell {
                    verts: *verts,
                    links: resolved,
                })
            })
            .collect();
        self.fill_memo = Some(memo);
        fill
    }

    /// The cells of the regular triangulation of `link` (the sorted vertices of the star of
    /// interior vertex `v`, whose `star_size` cells it replaces) that `v` conflicts with.
    fn triangulate_hole(&self, v: u32, link: &[u32], star_size: usize) -> Option<Vec<PlannedCell>> {
        let mut small = Self::new();
        for &x in link {
            let id = small.push_vertex(self.pt(x), self.kernel.weight(x));
            small.insert_new_vertex(id, None, None);
            if small.is_hidden(VertexId(id)) {
                return None;
            }
        }
        if small.lower.is_some() {
            return None;
        }
        let q = WeightedPoint3::new(self.pt(v), self.kernel.weight(v));
        let start = small.locate_cell(q.point, None);
        if !small.in_conflict(start, q.point, q.weight) {
            return None;
        }
        let (mut stack, mut cavity, mut boundary) = (Vec::new(), Vec::new(), Vec::new());
        let mut marks = HashMarks::default();
        small.find_cavity(
            (&small.filter, q),
            start,
            &mut marks,
            &mut stack,
            &mut cavity,
            &mut boundary,
        );
        if boundary.len() != star_size {
            return None;
        }
        let position: FxHashMap<u32, usize> =
            cavity.iter().enumerate().map(|(k, &c)| (c, k)).collect();
        let mut fill = Vec::with_capacity(cavity.len());
        for &c in &cavity {
            let r = small.cells[c as usize];
            if Self::is_infinite_record(&r) {
                return None;
            }
            let verts = r.v.map(|x| link[x as usize]);
            let mut links = [PlannedLink::Fill(0, 0); 4];
            for (i, l) in links.iter_mut().enumerate() {
                let nb = r.n[i] >> 2;
                *l = match position.get(&nb) {
                    Some(&k) => PlannedLink::Fill(k, (r.n[i] & 3) as usize),
                    None => PlannedLink::Outside(sorted_facet(verts, i)),
                };
            }
            fill.push((verts, links));
        }
        Some(fill)
    }

    /// Frees cell `c`, recording it in `report` as removed if it existed before the move (or
    /// forgetting it if the move created it).
    fn destroy(&mut self, c: u32, report: &mut MoveReport) {
        if let Some(k) = report.created.iter().position(|&x| x.0 == c) {
            report.created.swap_remove(k);
        } else {
            let verts = self.cells[c as usize].v.map(VertexId);
            report.removed.push((CellId(c), verts));
        }
        self.free_cell(c);
    }

    /// Inserts `v`, which is in no cell, at `p` with weight `w`, recording the change in
    /// `report`. Returns the vertices the insertion hid, or `None` when `v` itself is hidden.
    fn reinsert(
        &mut self,
        v: u32,
        p: Point3,
        w: f64,
        report: &mut MoveReport,
    ) -> Option<Vec<VertexId>> {
        self.points[v as usize] = p;
        self.filter.include(p);
        self.kernel.set_weight(v, w);
        self.kernel.unhide(v);
        let hint = report.created.last().copied();
        let start = self.locate_cell(p, hint.map(|c| c.0));
        if K::WEIGHTED && !self.in_conflict(start, p, w) {
            self.kernel.hide(v);
            return None;
        }
        let mut inserted = InsertReport::default();
        let MoveReport { removed, created } = report;
        self.star_from_seeing(v, start, Some(&mut inserted), |c, q| {
            if let Some(k) = created.iter().position(|&x| x.0 == c) {
                created.swap_remove(k);
            } else {
                removed.push((CellId(c), q.map(VertexId)));
            }
        });
        report.created.extend_from_slice(&inserted.created);
        Some(inserted.hidden)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::random::XorShift;
    use crate::triangulation::validity::{check_delaunay3, check_regular3};
    use crate::triangulation::{Delaunay3, Regular3};

    fn cube_points(n: usize, rng: &mut XorShift) -> Vec<Point3> {
        (0..n)
            .map(|_| Point3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()))
            .collect()
    }

    /// The Delaunay triangulation of `points`, inserted in order.
    fn delaunay(points: &[Point3]) -> Delaunay3 {
        let mut dt = Delaunay3::new();
        for &p in points {
            dt.insert(p).unwrap();
        }
        dt
    }

    /// The regular triangulation of `points` with `weights`, inserted in order.
    fn regular(points: &[Point3], weights: impl IntoIterator<Item = f64>) -> Regular3 {
        let mut rt = Regular3::new();
        let mut report = InsertReport::default();
        for (&p, w) in points.iter().zip(weights) {
            rt.insert_weighted(p, w, None, &mut report).unwrap();
        }
        rt
    }

    /// The finite cells as sorted vertex quadruples, sorted.
    fn cell_sets<K: ConflictKernel>(t: &Triangulation3<K>) -> Vec<[u32; 4]> {
        let mut cells: Vec<[u32; 4]> = t
            .finite_cells()
            .map(|c| {
                let mut q = t.cell(c).map(|v| v.0);
                q.sort_unstable();
                q
            })
            .collect();
        cells.sort_unstable();
        cells
    }

    #[test]
    fn moved_delaunay_vertices_give_the_triangulation_of_the_moved_points() {
        let mut rng = XorShift::new(0x1234_5678_9abc_def1);
        let mut pts = cube_points(300, &mut rng);
        let mut dt = delaunay(&pts);
        let mut report = MoveReport::default();
        let (mut moved, mut refused) = (0, 0);
        for k in 0..200 {
            let v = VertexId((k * 7 % 300) as u32);
            let delta = Point3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) - 0.5;
            let p = dt.point(v) + 0.1 * delta;
            if dt.move_vertex(v, p, 0.0, &mut report).unwrap() {
                pts[v.0 as usize] = p;
                moved += 1;
            } else {
                refused += 1;
            }
            assert!(report.created.iter().all(|&c| dt.is_live(c)));
        }
        assert!(moved > 0 && refused > 0, "{moved} moved, {refused} refused");
        assert_eq!(check_delaunay3(&dt), Ok(()));
        let fresh = delaunay(&pts);
        assert_eq!(cell_sets(&dt), cell_sets(&fresh));
    }

    #[test]
    fn reweighted_regular_vertices_keep_the_triangulation_regular() {
        let mut rng = XorShift::new(0x0fed_cba9_8765_4321);
        let pts = cube_points(300, &mut rng);
        let mut rt = regular(&pts, std::iter::repeat(0.0));
        let mut weights = vec![0.0; pts.len()];
        let mut moved = MoveReport::default();
        let mut changed = 0;
        for k in 0..300 {
            let v = VertexId(k as u32);
            // Large enough weights to hide neighbours now and then: those moves are refused.
            let w = 0.01 * rng.next_f64();
            if rt.move_vertex(v, pts[k], w, &mut moved).unwrap() {
                weights[k] = w;
                changed += 1;
            }
        }
        assert!(changed > 0);
        assert_eq!(check_regular3(&rt), Ok(()));
        assert_eq!(rt.hidden_vertices().count(), 0);
        let fresh = regular(&pts, weights);
        assert_eq!(cell_sets(&rt), cell_sets(&fresh));
    }

    /// An optimiser's pattern: a trial move of a vertex, undone; a kept move of one of its
    /// neighbours; another trial of the vertex, kept. The second trial may not reuse the removal
    /// planned for the first, whose hole had the neighbour elsewhere.
    #[test]
    fn trials_after_a_neighbour_moved_give_the_triangulation_of_the_moved_points() {
        let mut rng = XorShift::new(0x7777_1111_3333_5555);
        let mut pts = cube_points(300, &mut rng);
        let mut dt = delaunay(&pts);
        let mut report = MoveReport::default();
        let mut star = Vec::new();
        let mut step = |reach: f64| {
            reach * (Point3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) - 0.5)
        };
        let mut kept = 0;
        for k in 0..100 {
            let v = VertexId((k * 13 % 300) as u32);
            let p = dt.point(v);
            if dt.move_vertex(v, p + step(0.1), 0.0, &mut report).unwrap() {
                assert!(dt.undo_move(v, p, 0.0, &mut report));
            }
            dt.incident_cells(v, &mut star);
            let inf = dt.infinite_vertex();
            let Some(u) = dt.cell(star[0]).into_iter().find(|&x| x != v && x != inf) else {
                continue;
            };
            let q = dt.point(u) + step(0.03);
            if dt.move_vertex(u, q, 0.0, &mut report).unwrap() {
                pts[u.0 as usize] = q;
            }
            let q = p + step(0.1);
            if dt.move_vertex(v, q, 0.0, &mut report).unwrap() {
                pts[v.0 as usize] = q;
                kept += 1;
            }
            assert_eq!(cell_sets(&dt), cell_sets(&delaunay(&pts)), "after move {k}");
        }
        assert!(kept > 30, "{kept} moves kept");
    }

    /// Moves 200 vertices of a random regular triangulation by small moves (which keep the
    /// star's cells) and large ones (which change them), undoes each by `undo`, and checks that
    /// the cells, their count, the vertex and regularity are as before.
    fn check_undo(
        seed: u64,
        stride: usize,
        mut undo: impl FnMut(&mut Regular3, VertexId, Point3, f64, &mut MoveReport) -> bool,
    ) -> Regular3 {
        let mut rng = XorShift::new(seed);
        let pts = cube_points(300, &mut rng);
        let mut rt = regular(&pts, std::iter::repeat_with(|| 0.001 * rng.next_f64()));
        let mut report = MoveReport::default();
        let mut undone = 0;
        for k in 0..200 {
            let v = VertexId((k * stride % 300) as u32);
            let (p, w) = (rt.point(v), rt.weight(v));
            let reach = if k % 2 == 0 { 0.002 } else { 0.1 };
            let delta = Point3::new(rng.next_f64(), rng.next_f64(), rng.next_f64()) - 0.5;
            let before = cell_sets(&rt);
            let cells = rt.num_finite_cells();
            if rt
                .move_vertex(v, p + reach * delta, 0.5 * w, &mut report)
                .unwrap()
            {
                assert_eq!(check_regular3(&rt), Ok(()));
                assert!(undo(&mut rt, v, p, w, &mut report));
                assert_eq!((rt.point(v), rt.weight(v)), (p, w));
                assert_eq!(cell_sets(&rt), before);
                assert_eq!(rt.num_finite_cells(), cells);
                assert_eq!(check_regular3(&rt), Ok(()));
                undone += 1;
            }
        }
        assert!(undone > 100, "{undone} moves undone");
        rt
    }

    #[test]
    fn moving_back_restores_the_cells_of_small_and_large_moves() {
        check_undo(0x2468_ace0_1357_9bdf, 11, |rt, v, p, w, report| {
            rt.move_vertex_back(v, WeightedPoint3::new(p, w), report)
                .unwrap()
        });
    }

    #[test]
    fn undoing_a_move_restores_the_cells_without_a_search() {
        let mut rt = check_undo(0x1357_9bdf_2468_ace0, 7, |rt, v, p, w, report| {
            let moved = report.created.len();
            let done = rt.undo_move(v, p, w, report);
            assert_eq!(report.removed.len(), moved);
            done
        });
        // A report that does not fit changes nothing.
        let before = cell_sets(&rt);
        let v = VertexId(5);
        let (p, w) = (rt.point(v), rt.weight(v));
        let mut empty = MoveReport::default();
        assert!(!rt.undo_move(v, p, w, &mut empty));
        let mut half = MoveReport {
            removed: Vec::new(),
            created: vec![CellId(0)],
        };
        assert!(!rt.undo_move(v, p, w, &mut half));
        assert_eq!(cell_sets(&rt), before);
        assert_eq!(check_regular3(&rt), Ok(()));
    }

    #[test]
    fn a_vertex_moves_onto_a_plane_of_facets_but_not_onto_the_hull() {
        // A grid: its interior vertices have coplanar neighbours, so a move within a grid plane
        // ends on the boundary of the cell it lands in.
        let mut pts = Vec::new();
        for x in 0..5 {
            for y in 0..5 {
                for z in 0..5 {
                    pts.push(Point3::new(x as f64, y as f64, z as f64));
                }
            }
        }
        let mut dt = delaunay(&pts);
        let mut report = MoveReport::default();
        let inner = VertexId(2 * 25 + 2 * 5 + 2);
        let p = Point3::new(2.25, 2.0, 2.0);
        assert!(dt.move_vertex(inner, p, 0.0, &mut report).unwrap());
        pts[inner.0 as usize] = p;
        assert_eq!(check_delaunay3(&dt), Ok(()));
        let fresh = delaunay(&pts);
        assert_eq!(cell_sets(&dt), cell_sets(&fresh));
        // Onto a hull facet, or onto another vertex: refused, nothing changed.
        let before = cell_sets(&dt);
        let near_hull = VertexId(25 + 5 + 1);
        let on_hull = Point3::new(1.0, 1.5, 0.0);
        assert!(
            !dt.move_vertex(near_hull, on_hull, 0.0, &mut report)
                .unwrap()
        );
        assert!(!dt.move_vertex(near_hull, pts[0], 0.0, &mut report).unwrap());
        assert_eq!(cell_sets(&dt), before);
    }
}
