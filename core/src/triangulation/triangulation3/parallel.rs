//! Parallel bulk construction. A large BRIO round is cut into parts along the Hilbert curve
//! (vertex ids are Hilbert ranks, so a part is a range of ids and a compact region of space) and
//! each part is inserted by its own thread into the shared cell array.
//!
//! A cell *belongs* to a part when its four vertices are finite and in the part's range, and a
//! part changes only its own cells: a point whose walk or cavity reaches another cell, or whose
//! insertion needs more slots than the part has left, is deferred. Cells of two parts never share a facet (its three vertices would be in both ranges),
//! so the cells a part reaches from its own are its own or *mixed* (vertices of several parts, or
//! the infinite vertex). Mixed cells are neither destroyed nor created during a pass; a part only
//! writes the neighbour entry of a mixed cell that faces one of its own cells, and reads only
//! mixed cells' vertices. What a part does therefore depends on no other part: the cell numbering
//! is the same whatever the number of threads and their timing. New cells take the slots a part
//! freed, then fresh slots from a region reserved for it.
//!
//! Deferred points are tried again in a second pass whose part boundaries sit halfway between
//! the first pass's, treating the Hilbert order as a cycle (its ends are neighbouring corners of
//! the box); what remains is inserted sequentially.

use super::cavity::{ByteMarks, CellWriter, NewCell, Scratch, grow_cavity};
use super::{CellRecord, ConflictKernel, FREE, NO_CELL, Triangulation3, Walk, pack};
use std::ptr::{addr_of, addr_of_mut};

/// Parts per pass. A constant rather than the number of cores, so that every machine builds the
/// same cell array.
pub(super) const PARTS: usize = 2;
/// Rounds with fewer points are inserted sequentially: below this the deferred points near the
/// part boundaries are a large share of the round.
pub(super) const MIN_PARALLEL_ROUND: usize = 40_000;
/// Fresh cell slots reserved per point of a part: an insertion adds 6.75 cells on average in a
/// uniform point set, and a part that runs out defers its remaining points.
pub(super) const SLOTS_PER_POINT: f64 = 6.9;
/// Fresh slots reserved per part on top of those.
const SPARE_SLOTS: usize = 4096;
/// Cells searched around a part's middle point for a cell of the part to start walking from.
const START_SEARCH: usize = 4096;

/// The vertex ids `start, start + 1, …` taken cyclically modulo `n`, `len` of them.
#[derive(Clone, Copy, Debug)]
struct IdRange {
    start: u32,
    len: u32,
    n: u32,
}

impl IdRange {
    #[inline]
    fn contains(self, v: u32) -> bool {
        // The infinite vertex (u32::MAX) is in no range, as `n` stays below 2^27.
        let d = if v >= self.start {
            v - self.start
        } else {
            v + self.n - self.start
        };
        d < self.len
    }

    /// Whether the cell with vertices `v` belongs to the part of this range.
    #[inline]
    fn owns(self, v: [u32; 4]) -> bool {
        v.iter().all(|&x| self.contains(x))
    }
}

/// The cell array shared by the threads of a pass. Each access is sound under the ownership
/// rules of the module documentation: a part reads and writes its own cells and its own free
/// slots, reads the vertices of mixed cells next to its own, and writes the neighbour entries of
/// those mixed cells that face its own cells, which nothing else reads or writes during a pass.
#[derive(Clone, Copy)]
struct SharedCells(*mut CellRecord);

// SAFETY: the pointer is only dereferenced under the ownership rules above, which keep the
// threads' accesses to different memory.
unsafe impl Send for SharedCells {}
// SAFETY: as above.
unsafe impl Sync for SharedCells {}

impl SharedCells {
    /// # Safety
    /// `c` is a slot of the array that no other thread writes during the pass.
    #[inline]
    unsafe fn record(self, c: u32) -> CellRecord {
        // SAFETY: guaranteed by the caller.
        unsafe { self.0.add(c as usize).read() }
    }

    /// # Safety
    /// `c` is a slot of the array whose vertices no other thread writes during the pass.
    #[inline]
    unsafe fn vertices(self, c: u32) -> [u32; 4] {
        // SAFETY: guaranteed by the caller; only the vertex field is read.
        unsafe { addr_of!((*self.0.add(c as usize)).v).read() }
    }

    /// # Safety
    /// `c` is a slot of the array that no other thread reads or writes during the pass.
    #[inline]
    unsafe fn write(self, c: u32, r: CellRecord) {
        // SAFETY: guaranteed by the caller.
        unsafe { self.0.add(c as usize).write(r) }
    }

    /// Sets the neighbour entry `packed` (`cell << 2 | index`) to `value`.
    ///
    /// # Safety
    /// That entry is in the array and no other thread reads or writes it during the pass.
    #[inline]
    unsafe fn set_neighbor(self, packed: u32, value: u32) {
        // SAFETY: guaranteed by the caller; only the one entry is written.
        unsafe {
            let n = addr_of_mut!((*self.0.add((packed >> 2) as usize)).n);
            n.cast::<u32>().add((packed & 3) as usize).write(value);
        }
    }
}

/// Used only by [`Part::insert`] for the cells of its cavity.
impl CellWriter for SharedCells {
    #[inline]
    fn place(&mut self, nc: &NewCell) {
        // SAFETY: the new cells take slots of the part; the cells outside the cavity facets are
        // the part's or mixed cells whose entry facing the cavity only this part writes.
        unsafe {
            self.write(nc.id, nc.record());
            self.set_neighbor(nc.outside, pack(nc.id, nc.apex as usize));
        }
    }

    #[inline]
    fn link(&mut self, facet: u32, neighbor: u32) {
        // SAFETY: as in `place`, the facet is the cavity's, facing a cell only this part writes.
        unsafe { self.set_neighbor(facet, neighbor) }
    }
}

/// One part of a pass: its range, its slots and what became of its points.
struct Part<'a, K: ConflictKernel> {
    /// The triangulation with its cell array moved out (the cells are reached through `cells`).
    tri: &'a Triangulation3<K>,
    cells: SharedCells,
    range: IdRange,
    state: PartState,
}

/// A part's slots and what became of its insertions: what the pass keeps of a part.
struct PartState {
    /// Slots this part freed, reused first.
    free: Vec<u32>,
    /// The triangulation's free list (threaded through the slots) and its length: the first
    /// part's, used next.
    list: u32,
    list_len: usize,
    /// The next fresh slot of the part's region, and the region's end.
    next: u32,
    end: u32,
    /// Cells created minus cells destroyed.
    growth: isize,
    /// A cell of this part to start walks from.
    last: Option<u32>,
    deferred: Vec<u32>,
}

impl<K: ConflictKernel> Part<'_, K> {
    fn run(&mut self, vertices: &[u32], s: &mut Scratch) {
        for &v in vertices {
            if !self.insert(v, s) {
                self.state.deferred.push(v);
            }
        }
    }

    /// Inserts vertex `v` if its walk and its cavity stay in this part's cells and the part has
    /// the slots for it; otherwise changes nothing and returns false.
    fn insert(&mut self, v: u32, s: &mut Scratch) -> bool {
        let Some(from) = self.state.last else {
            return false;
        };
        let (tri, cells, range) = (self.tri, self.cells, self.range);
        let p = tri.points[v as usize];
        // The walk and the cavity search start in a cell of this part and step only from cells of
        // this part; what they step to is this part's or a mixed cell, of which they read the
        // vertices only.
        let c = match tri.walk(
            &tri.filter,
            p,
            from,
            // SAFETY: the walk records only the cells it steps from, which are this part's.
            |c| unsafe { cells.record(c) },
            // SAFETY: a cell stepped to is this part's or mixed; only its vertices are read.
            |c| !range.owns(unsafe { cells.vertices(c) }),
        ) {
            Walk::Found(c) => c,
            Walk::Stopped { before, .. } => {
                // The next point is probably close: start it from here rather than walk the
                // same way again.
                self.state.last = Some(before);
                return false;
            }
        };
        let mut marks = ByteMarks::new(&mut s.mark, 0);
        let grown = grow_cavity(
            c,
            &mut marks,
            &mut s.stack,
            &mut s.cavity,
            &mut s.boundary,
            // SAFETY: the search reads the neighbours of cavity cells only, which are this part's.
            |c| unsafe { cells.record(c) }.n,
            |n| {
                // SAFETY: a neighbour is this part's or mixed; only its vertices are read.
                let v = unsafe { cells.vertices(n) };
                let conflict = tri.conflicts(&tri.filter, v, p, 0.0);
                (!conflict || range.owns(v)).then_some(conflict)
            },
        );
        // SAFETY: the cavity cells are this part's.
        s.collect_new_cells(v, |c| unsafe { cells.record(c) });
        let (old, new) = (s.cavity.len(), s.new_cells.len());
        let fresh = (self.state.end - self.state.next) as usize;
        if !grown || new.saturating_sub(old) > self.state.free.len() + self.state.list_len + fresh {
            clear_marks(s);
            self.state.last = Some(c);
            return false;
        }
        let reused = old.min(new);
        for k in 0..new {
            s.new_cells[k].id = if k < reused {
                s.cavity[k]
            } else if let Some(f) = self.state.free.pop() {
                f
            } else if self.state.list_len > 0 {
                let f = self.state.list;
                // SAFETY: the slots of the free list are this part's.
                self.state.list = unsafe { cells.record(f) }.n[0];
                self.state.list_len -= 1;
                f
            } else {
                self.state.next += 1;
                self.state.next - 1
            };
        }
        s.link_new_cells(tri.points.len(), &mut { cells });
        self.state.free.extend_from_slice(&s.cavity[reused..]);
        self.state.growth += new as isize - old as isize;
        self.state.last = s.new_cells.last().map(|nc| nc.id);
        clear_marks(s);
        true
    }
}

/// Unmarks the cavity cells and the cells across its boundary.
fn clear_marks(s: &mut Scratch) {
    for &c in &s.cavity {
        s.mark[c as usize] = 0;
    }
    for nc in &s.new_cells {
        s.mark[(nc.outside >> 2) as usize] = 0;
    }
}

/// The vertices of a pass cut into parts: the part boundaries (offsets from `origin` along the
/// cyclic id order, `0` first and `n` last) and each part's vertices in walking order.
struct Partition {
    origin: u32,
    bounds: [u32; PARTS + 1],
    parts: Vec<Vec<u32>>,
}

impl Partition {
    /// Cuts `vertices` (distinct ids below `n`) into parts of equal size along the id cycle
    /// starting at `origin`, with each boundary halfway across the gap between two parts.
    fn new(vertices: &[u32], origin: u32, n: u32) -> Self {
        let offset = |v: u32| {
            if v >= origin {
                v - origin
            } else {
                v + n - origin
            }
        };
        let mut order: Vec<u32> = vertices.to_vec();
        order.sort_unstable_by_key(|&v| offset(v));
        let mut bounds = [n; PARTS + 1];
        bounds[0] = 0;
        let mut parts = Vec::with_capacity(PARTS);
        let mut begin = 0;
        for j in 0..PARTS {
            let end = order.len() * (j + 1) / PARTS;
            if j + 1 < PARTS {
                let before = if end > 0 { offset(order[end - 1]) } else { 0 };
                let after = order.get(end).map_or(n, |&v| offset(v));
                bounds[j + 1] = before + (after - before).div_ceil(2);
            }
            parts.push(order[begin..end].to_vec());
            begin = end;
        }
        Partition {
            origin,
            bounds,
            parts,
        }
    }

    fn range(&self, j: usize, n: u32) -> IdRange {
        IdRange {
            start: (self.origin + self.bounds[j]) % n.max(1),
            len: self.bounds[j + 1] - self.bounds[j],
            n,
        }
    }
}

/// Runs every part on its vertices, each in its own thread when `threaded`.
fn run_parts<K: ConflictKernel>(
    parts: &mut [Part<'_, K>],
    partition: &Partition,
    scratch: &mut [Scratch],
    threaded: bool,
) {
    let jobs = parts.iter_mut().zip(&partition.parts).zip(scratch);
    if threaded {
        std::thread::scope(|scope| {
            let handles: Vec<_> = jobs
                .map(|((part, vertices), s)| scope.spawn(move || part.run(vertices, s)))
                .collect();
            for h in handles {
                if let Err(panic) = h.join() {
                    std::panic::resume_unwind(panic);
                }
            }
        });
    } else {
        for ((part, vertices), s) in jobs {
            part.run(vertices, s);
        }
    }
}

impl<K: ConflictKernel> Triangulation3<K> {
    /// Inserts the vertices of a BRIO round (already in `points`, in cells that exist) in
    /// [`PARTS`] parts, one thread each when `threaded`, in two passes, then the deferred rest
    /// one by one. The cell array is kept within `budget` slots during the passes. The first
    /// part uses the triangulation's own buffers; `scratch` holds the others', kept between
    /// rounds.
    pub(super) fn insert_round_parallel(
        &mut self,
        round: &[u32],
        budget: usize,
        threaded: bool,
        scratch: &mut Vec<Scratch>,
    ) {
        scratch.resize_with(PARTS, Scratch::default);
        std::mem::swap(&mut scratch[0], &mut self.scratch);
        let n = self.points.len() as u32;
        let first = Partition::new(round, 0, n);
        let deferred = self.parallel_pass(&first, budget, threaded, scratch);
        let second = Partition::new(&deferred, first.bounds[1] / 2, n);
        let rest = self.parallel_pass(&second, budget, threaded, scratch);
        std::mem::swap(&mut scratch[0], &mut self.scratch);
        for v in rest {
            self.insert_new_vertex(v, None, None);
        }
    }

    /// Inserts the parts of `partition`, each in its own thread when `threaded`; returns the
    /// deferred vertices.
    fn parallel_pass(
        &mut self,
        partition: &Partition,
        budget: usize,
        threaded: bool,
        scratch: &mut [Scratch],
    ) -> Vec<u32> {
        if partition.parts.iter().all(Vec::is_empty) {
            return Vec::new();
        }
        let n = self.points.len() as u32;
        let starts: Vec<Option<u32>> = (0..PARTS)
            .map(|j| self.start_cell(&partition.parts[j], partition.range(j, n)))
            .collect();
        let base = self.cells.len();
        self.cells.reserve_exact(budget.saturating_sub(base));
        let list_len = self.free_list_len();
        let regions = self.region_sizes(partition, budget, list_len);
        let total = base + regions.iter().sum::<usize>();
        for s in scratch.iter_mut() {
            if s.mark.len() < total {
                s.mark.resize(total, 0);
            }
        }
        let mut cells = std::mem::take(&mut self.cells);
        // The regions lie in the reserved capacity beyond the length: slots are written before
        // they are read, and the length is set once every slot up to it is written.
        let shared = SharedCells(cells.as_mut_ptr());
        let mut next = base;
        let mut parts: Vec<Part<K>> = (0..PARTS)
            .map(|j| {
                let begin = next;
                next += regions[j];
                Part {
                    tri: &*self,
                    cells: shared,
                    range: partition.range(j, n),
                    state: PartState {
                        free: Vec::new(),
                        list: if j == 0 { self.free_head } else { NO_CELL },
                        list_len: if j == 0 { list_len } else { 0 },
                        next: begin as u32,
                        end: next as u32,
                        growth: 0,
                        last: starts[j],
                        deferred: Vec::new(),
                    },
                }
            })
            .collect();
        run_parts(&mut parts, partition, scratch, threaded);
        let states: Vec<PartState> = parts.into_iter().map(|p| p.state).collect();
        let unused = CellRecord {
            v: [FREE; 4],
            n: [NO_CELL; 4],
        };
        for state in &states[..PARTS - 1] {
            // SAFETY: the threads are done; the slots are in the reserved capacity.
            (state.next..state.end).for_each(|c| unsafe { shared.write(c, unused) });
        }
        // SAFETY: every slot below the end of the last part's used slots is written: before the
        // pass, by a part's insertions (each slot a part takes gets a cell), or just above.
        unsafe { cells.set_len(states[PARTS - 1].next as usize) };
        self.cells = cells;
        self.absorb(states)
    }

    /// Each part's region of fresh slots after the live ones: what its points are expected to
    /// take (the first part takes the free list's `list_len` slots first), shrunk so that all
    /// regions fit in `budget` cells.
    fn region_sizes(&self, partition: &Partition, budget: usize, list_len: usize) -> Vec<usize> {
        let room = budget.saturating_sub(self.cells.len());
        let mut regions: Vec<usize> = partition
            .parts
            .iter()
            .map(|p| (p.len() as f64 * SLOTS_PER_POINT) as usize + SPARE_SLOTS)
            .collect();
        regions[0] = regions[0].saturating_sub(list_len);
        let wanted: usize = regions.iter().sum();
        if wanted > room {
            regions.iter_mut().for_each(|r| *r = *r * room / wanted);
        }
        regions
    }

    /// Takes back what the parts of a pass did (counts, free slots, last cell); returns their
    /// deferred vertices.
    fn absorb(&mut self, states: Vec<PartState>) -> Vec<u32> {
        self.free_head = states[0].list;
        let mut deferred = Vec::new();
        for (j, state) in states.into_iter().enumerate() {
            // Every cell a part creates or destroys is finite.
            self.num_live = self.num_live.wrapping_add_signed(state.growth);
            self.num_finite = self.num_finite.wrapping_add_signed(state.growth);
            // The last part's unused slots are beyond the length.
            let unused = if j + 1 < PARTS {
                state.next..state.end
            } else {
                0..0
            };
            for c in state.free.into_iter().chain(unused) {
                self.release_slot(c);
            }
            if let Some(c) = state.last {
                self.last = c;
            }
            deferred.extend(state.deferred);
        }
        deferred
    }

    /// The number of slots on the free list.
    fn free_list_len(&self) -> usize {
        let mut len = 0;
        let mut c = self.free_head;
        while c != NO_CELL {
            len += 1;
            c = self.cells[c as usize].n[0];
        }
        len
    }

    /// A cell of the part with range `range` near its middle vertex, found before the threads
    /// start (so any cell may be read). Not near its first vertex: that one is on the part's
    /// boundary, where the part's cells can form pockets enclosed by mixed cells.
    fn start_cell(&self, vertices: &[u32], range: IdRange) -> Option<u32> {
        let &middle = vertices.get(vertices.len() / 2)?;
        let c = self.locate_cell(self.pt(middle), None);
        let mut seen = std::collections::HashSet::from([c]);
        let mut queue = std::collections::VecDeque::from([c]);
        while let Some(c) = queue.pop_front() {
            let r = &self.cells[c as usize];
            if range.owns(r.v) {
                return Some(c);
            }
            if seen.len() < START_SEARCH {
                for nb in r.n {
                    if seen.insert(nb >> 2) {
                        queue.push_back(nb >> 2);
                    }
                }
            }
        }
        None
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::Point3;
    use crate::random::XorShift;
    use crate::triangulation::validity::check_delaunay3;
    use crate::triangulation::{Delaunay3, Triangulation, VertexId};

    /// `n` pseudo-random points in the unit cube.
    fn scattered(n: usize) -> Vec<Point3> {
        let mut rng = XorShift::new(0x2545_F491_4F6C_DD1D);
        let mut coordinate = move || rng.next_f64();
        (0..n)
            .map(|_| Point3::new(coordinate(), coordinate(), coordinate()))
            .collect()
    }

    fn build(points: &[Point3], threaded: bool) -> Delaunay3 {
        let mut dt = Delaunay3::new();
        let mut vertex_of = vec![VertexId(0); points.len()];
        let budget = (points.len() as f64 * super::super::CELLS_PER_VERTEX) as usize + 64;
        dt.cells.reserve_exact(budget);
        dt.bulk = true;
        dt.insert_fresh(points, budget, threaded, &mut vertex_of);
        dt.bulk = false;
        dt.rebuild_vertex_cells();
        dt
    }

    #[test]
    fn threads_change_nothing_in_the_cell_array() {
        let points = scattered(60_000);
        let (one, two) = (build(&points, false), build(&points, true));
        assert_eq!(check_delaunay3(&two), Ok(()));
        assert_eq!(two.cells().count(), two.num_cells());
        assert_eq!(two.finite_cells().count(), two.num_finite_cells());
        assert_eq!(one.cells, two.cells);
        assert_eq!(
            (one.free_head, one.num_live, one.num_finite, one.last),
            (two.free_head, two.num_live, two.num_finite, two.last)
        );
    }

    #[test]
    fn parts_out_of_slots_defer_their_points() {
        let points = scattered(20_000);
        let mut dt = Delaunay3::new();
        for &p in &points {
            dt.push_vertex(p, 0.0);
        }
        dt.bulk = true;
        for v in 0..2_000 {
            dt.insert_new_vertex(v, None, None);
        }
        // Room for a few hundred insertions only: the parts stop early and the points they
        // could not insert go through the sequential path.
        let budget = dt.cells.len() + 3_000;
        let round: Vec<u32> = (2_000..points.len() as u32).collect();
        dt.insert_round_parallel(&round, budget, true, &mut Vec::new());
        dt.bulk = false;
        dt.rebuild_vertex_cells();
        assert_eq!(dt.num_vertices(), points.len());
        assert_eq!(check_delaunay3(&dt), Ok(()));
        assert_eq!(dt.cells().count(), dt.num_cells());
        assert_eq!(dt.finite_cells().count(), dt.num_finite_cells());
    }

    #[test]
    fn id_ranges_wrap_around_and_exclude_the_infinite_vertex() {
        let r = IdRange {
            start: 8,
            len: 4,
            n: 10,
        };
        let inside: Vec<u32> = (0..10).filter(|&v| r.contains(v)).collect();
        assert_eq!(inside, [0, 1, 8, 9]);
        assert!(!r.contains(u32::MAX));
        assert!(r.owns([8, 9, 0, 1]));
        assert!(!r.owns([8, 9, 0, 2]));
    }

    #[test]
    fn a_partition_splits_evenly_with_boundaries_in_the_gaps() {
        let vertices: Vec<u32> = (0..10).map(|k| 3 * k).collect();
        let p = Partition::new(&vertices, 0, 30);
        assert_eq!(p.parts, [vec![0, 3, 6, 9, 12], vec![15, 18, 21, 24, 27]]);
        assert_eq!(p.bounds, [0, 14, 30]);
        let shifted = Partition::new(&vertices, 7, 30);
        assert_eq!(shifted.parts[0], [9, 12, 15, 18, 21]);
        assert_eq!(shifted.parts[1], [24, 27, 0, 3, 6]);
        let r = shifted.range(1, 30);
        assert!((0..30).filter(|&v| r.contains(v)).eq((0..7).chain(23..30)));
    }
}
