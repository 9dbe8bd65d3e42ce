//! The cavity search and re-triangulation, written once for the sequential insertion and for
//! the parts of a parallel build, and the buffers they reuse so that insertion does not allocate.

use super::{CellRecord, NO_CELL, SIDE_EDGE};
use rustc_hash::FxHashMap;

/// Per-cell state of a cavity search: unvisited, in conflict, or tested and outside.
pub(super) trait CavityMarks {
    /// `Some(true)` in the cavity, `Some(false)` tested outside, `None` not tested yet.
    fn get(&self, c: u32) -> Option<bool>;
    fn set_in(&mut self, c: u32);
    fn set_out(&mut self, c: u32);
}

/// Marks as one byte per cell slot (0 untested, 1 in the cavity, 2 outside). A byte keeps the
/// array small enough to stay in cache; the insertion clears the marks it set (cavity cells and
/// their outside neighbours) once done, so a search starts from a clean array.
pub(super) struct ByteMarks<'a>(&'a mut [u8]);

impl<'a> ByteMarks<'a> {
    pub(super) fn new(mark: &'a mut Vec<u8>, num_cells: usize) -> Self {
        if mark.len() < num_cells {
            mark.resize(num_cells, 0);
        }
        ByteMarks(mark)
    }
}

impl CavityMarks for ByteMarks<'_> {
    #[inline]
    fn get(&self, c: u32) -> Option<bool> {
        match self.0[c as usize] {
            0 => None,
            1 => Some(true),
            _ => Some(false),
        }
    }

    #[inline]
    fn set_in(&mut self, c: u32) {
        self.0[c as usize] = 1;
    }

    #[inline]
    fn set_out(&mut self, c: u32) {
        self.0[c as usize] = 2;
    }
}

/// Marks in a map, for read-only queries that cannot touch the triangulation's stamp array.
#[derive(Default)]
pub(super) struct HashMarks(FxHashMap<u32, bool>);

impl CavityMarks for HashMarks {
    fn get(&self, c: u32) -> Option<bool> {
        self.0.get(&c).copied()
    }

    fn set_in(&mut self, c: u32) {
        self.0.insert(c, true);
    }

    fn set_out(&mut self, c: u32) {
        self.0.insert(c, false);
    }
}

/// Open-addressing map from a directed cavity-boundary edge to the new facet that holds it, for
/// cavities too large for [`EdgeLinker`]'s dense table. A generation stamp empties the whole
/// table between insertions without touching it.
#[derive(Clone, Debug, Default)]
struct EdgeTable {
    slots: Vec<EdgeSlot>,
    generation: u32,
}

#[derive(Clone, Copy, Debug, Default)]
struct EdgeSlot {
    key: u64,
    value: u32,
    /// The slot is occupied iff this equals the table's generation.
    generation: u32,
}

impl EdgeTable {
    /// Forgets every entry; sizes the table for a cavity of `facets` boundary facets.
    #[inline]
    fn clear(&mut self, facets: usize) {
        // 3 directed edges per facet in at least 8 slots per facet: probes stay short.
        let want = (facets * 8).next_power_of_two().max(64);
        if self.slots.len() < want || self.generation == u32::MAX {
            self.slots = vec![EdgeSlot::default(); want];
            self.generation = 0;
        }
        self.generation += 1;
    }

    #[inline]
    fn home(&self, key: u64) -> usize {
        (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) as usize & (self.slots.len() - 1)
    }

    /// Stores `value` under `key`, which must not be present.
    #[inline]
    fn insert(&mut self, key: u64, value: u32) {
        let mask = self.slots.len() - 1;
        let mut s = self.home(key);
        while self.slots[s].generation == self.generation {
            s = (s + 1) & mask;
        }
        self.slots[s] = EdgeSlot {
            key,
            value,
            generation: self.generation,
        };
    }

    /// The value stored under `key`, if any.
    #[inline]
    fn get(&self, key: u64) -> Option<u32> {
        let mask = self.slots.len() - 1;
        let mut s = self.home(key);
        loop {
            let slot = &self.slots[s];
            if slot.generation != self.generation {
                return None;
            }
            if slot.key == key {
                return Some(slot.value);
            }
            s = (s + 1) & mask;
        }
    }
}

/// Links the side facets of the new cells of a cavity. Boundary vertices get local numbers
/// `0..count` (a per-vertex stamp, so no clearing between insertions); a directed edge `x → y`
/// then indexes a dense `count × count` table directly, without hashing or probing. Every slot read
/// was written by the same insertion (each edge has its twin), so the table is never cleared
/// either. Cavities with too many boundary vertices for a dense table use the hash table.
#[derive(Clone, Debug, Default)]
pub(super) struct EdgeLinker {
    /// Per vertex, at index `vertex + 1` (the infinite vertex `u32::MAX` wraps to 0): the
    /// generation that numbered it and its local number then.
    local: Vec<(u32, u32)>,
    generation: u32,
    count: u32,
    dense: Vec<u32>,
    use_dense: bool,
    table: EdgeTable,
}

/// Largest number of boundary vertices linked through the dense table (256 KiB of slots).
const MAX_DENSE: u32 = 256;

impl EdgeLinker {
    /// Starts numbering the boundary vertices of a new cavity in a triangulation of
    /// `num_vertices` finite vertices.
    #[inline]
    pub(super) fn begin(&mut self, num_vertices: usize) {
        if self.local.len() <= num_vertices {
            self.local.resize(num_vertices + 1, (0, 0));
        }
        if self.generation == u32::MAX {
            self.local.fill((0, 0));
            self.generation = 0;
        }
        self.generation += 1;
        self.count = 0;
    }

    /// The local number of vertex `x` in this cavity (branch-free: whether `x` was seen before
    /// is a coin toss for the branch predictor).
    #[inline]
    pub(super) fn number(&mut self, x: u32) -> u32 {
        let slot = &mut self.local[x.wrapping_add(1) as usize];
        let seen = slot.0 == self.generation;
        let l = if seen { slot.1 } else { self.count };
        self.count += u32::from(!seen);
        *slot = (self.generation, l);
        l
    }

    /// Ends the numbering and prepares the table for `facets` boundary facets.
    #[inline]
    pub(super) fn prepare(&mut self, facets: usize) {
        self.use_dense = self.count <= MAX_DENSE;
        if self.use_dense {
            let want = (self.count * self.count) as usize;
            if self.dense.len() < want {
                self.dense.resize(want, 0);
            }
        } else {
            self.table.clear(facets);
        }
    }

    /// Records `value` for the directed edge `x → y` with local numbers `lx`, `ly`.
    #[inline]
    pub(super) fn put(&mut self, (x, lx): (u32, u32), (y, ly): (u32, u32), value: u32) {
        if self.use_dense {
            self.dense[(lx * self.count + ly) as usize] = value;
        } else {
            self.table.insert(edge_key(x, y), value);
        }
    }

    /// The value recorded for the directed edge `x → y` in this cavity.
    #[inline]
    pub(super) fn get(&self, (x, lx): (u32, u32), (y, ly): (u32, u32)) -> Option<u32> {
        if self.use_dense {
            self.dense.get((lx * self.count + ly) as usize).copied()
        } else {
            self.table.get(edge_key(x, y))
        }
    }
}

/// Hash key of the directed edge `x → y`.
#[inline]
fn edge_key(x: u32, y: u32) -> u64 {
    (u64::from(x) << 32) | u64::from(y)
}

/// A cell to create when starring a cavity: built from a boundary facet before any cavity slot
/// is overwritten.
#[derive(Clone, Copy, Debug)]
pub(super) struct NewCell {
    /// The boundary facet's vertices with the new vertex in place of the cavity cell's.
    pub(super) verts: [u32; 4],
    /// Position of the new vertex (the facet on the cavity boundary).
    pub(super) apex: u8,
    /// Packed reference to the cell outside the cavity across the boundary facet.
    pub(super) outside: u32,
    /// The slot the cell gets.
    pub(super) id: u32,
    /// Local numbers of the boundary vertices (see [`EdgeLinker`]; unused at `apex`).
    pub(super) local: [u32; 4],
}

/// Grows the conflict zone from `start` (which conflicts) through the neighbour lists given by
/// `neighbors`, filling `cavity` and the `boundary` facets `(cavity cell, index)`. `test(n)` tells
/// whether cell `n` conflicts, or `None` when the caller may not touch `n` although it might:
/// the search then stops and returns false, leaving in `cavity` and `boundary` what it marked.
pub(super) fn grow_cavity<M: CavityMarks>(
    start: u32,
    marks: &mut M,
    stack: &mut Vec<u32>,
    cavity: &mut Vec<u32>,
    boundary: &mut Vec<(u32, u8)>,
    neighbors: impl Fn(u32) -> [u32; 4],
    mut test: impl FnMut(u32) -> Option<bool>,
) -> bool {
    stack.clear();
    cavity.clear();
    boundary.clear();
    marks.set_in(start);
    stack.push(start);
    cavity.push(start);
    while let Some(c) = stack.pop() {
        for (i, &nb) in neighbors(c).iter().enumerate() {
            let n = nb >> 2;
            match marks.get(n) {
                Some(true) => {}
                Some(false) => boundary.push((c, i as u8)),
                None => match test(n) {
                    Some(true) => {
                        marks.set_in(n);
                        stack.push(n);
                        cavity.push(n);
                    }
                    Some(false) => {
                        marks.set_out(n);
                        boundary.push((c, i as u8));
                    }
                    None => return false,
                },
            }
        }
    }
    true
}

/// Buffers reused by every insertion.
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    pub(super) mark: Vec<u8>,
    pub(super) stack: Vec<u32>,
    pub(super) cavity: Vec<u32>,
    pub(super) boundary: Vec<(u32, u8)>,
    pub(super) new_cells: Vec<NewCell>,
    pub(super) edges: EdgeLinker,
    /// Vertices swallowed by a weighted insertion.
    pub(super) swallowed: Vec<u32>,
    /// Per-vertex marks of the swallowed-vertex search: equal to `stamp` when seen this time.
    pub(super) vertex_stamp: Vec<u32>,
    pub(super) stamp: u32,
}

impl Scratch {
    /// Records the cells that star the cavity boundary from new vertex `v`, reading the cavity
    /// cells through `record`: done before any cavity slot is overwritten.
    #[inline]
    pub(super) fn collect_new_cells(&mut self, v: u32, record: impl Fn(u32) -> CellRecord) {
        self.new_cells.clear();
        for &(c, i) in &self.boundary {
            let r = record(c);
            let i = i as usize;
            // The vertex array is built by selection, not by storing into a copy: a scalar store
            // followed by a vector load of the same bytes stalls store forwarding.
            self.new_cells.push(NewCell {
                verts: std::array::from_fn(|k| {
                    // Branch-free select: `i` varies unpredictably from one facet to the next.
                    let here = u32::from(k == i).wrapping_neg();
                    (r.v[k] & !here) | (v & here)
                }),
                apex: i as u8,
                outside: r.n[i],
                id: NO_CELL,
                local: [0; 4],
            });
        }
    }

    /// Writes the new cells (whose `id` is assigned) through `out`: each cell with its link
    /// across the cavity boundary, then the links between new cells, in a triangulation of
    /// `num_vertices` finite vertices.
    ///
    /// The boundary of the cavity is an oriented closed surface: each of its edges is listed once
    /// in each direction by the two new cells sharing it. Every new cell stores its three directed
    /// edges, then looks up their reversals, so neither pass branches on whether the twin came
    /// first. The links are stored one by one into the written cells: gathering them into an
    /// array first would store scalars and load them back as a vector, which stalls store
    /// forwarding.
    #[inline]
    pub(super) fn link_new_cells(&mut self, num_vertices: usize, out: &mut impl CellWriter) {
        self.edges.begin(num_vertices);
        for nc in &mut self.new_cells {
            // The side facets' positions are the boundary vertices' positions.
            for &(k, _, _) in &SIDE_EDGE[nc.apex as usize] {
                nc.local[k] = self.edges.number(nc.verts[k]);
            }
        }
        self.edges.prepare(self.new_cells.len());
        for nc in &self.new_cells {
            out.place(nc);
            let (i, verts) = (nc.apex as usize, nc.verts);
            for &(j, a, b) in &SIDE_EDGE[i] {
                let (x, y) = ((verts[a], nc.local[a]), (verts[b], nc.local[b]));
                self.edges.put(x, y, super::pack(nc.id, j));
            }
        }
        for nc in &self.new_cells {
            let (i, verts) = (nc.apex as usize, nc.verts);
            for &(j, a, b) in &SIDE_EDGE[i] {
                let (x, y) = ((verts[a], nc.local[a]), (verts[b], nc.local[b]));
                let twin = self.edges.get(y, x).unwrap_or(NO_CELL);
                out.link(super::pack(nc.id, j), twin);
            }
        }
    }
}

/// Where [`Scratch::link_new_cells`] writes the new cells.
pub(super) trait CellWriter {
    /// Writes cell `nc.id` (its side links still unset) and the link to it from outside.
    fn place(&mut self, nc: &NewCell);
    /// Sets the neighbour entry `facet` (`cell << 2 | index`) to `neighbor`.
    fn link(&mut self, facet: u32, neighbor: u32);
}

impl NewCell {
    /// The cell record, linked across the boundary facet only.
    #[inline]
    pub(super) fn record(&self) -> CellRecord {
        let apex = self.apex as usize;
        CellRecord {
            v: self.verts,
            // Built by selection, as the vertices are (see `collect_new_cells`).
            n: std::array::from_fn(|k| {
                let here = u32::from(k == apex).wrapping_neg();
                (self.outside & here) | (NO_CELL & !here)
            }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Numbers `n` vertices (among them the infinite one) and links consecutive pairs.
    fn link_chain(linker: &mut EdgeLinker, n: u32) {
        linker.begin(10 * n as usize);
        let vertices: Vec<(u32, u32)> = (0..n)
            .map(|k| if k == 0 { u32::MAX } else { 7 * k })
            .map(|x| (x, linker.number(x)))
            .collect();
        let locals: Vec<u32> = vertices.iter().map(|v| v.1).collect();
        assert_eq!(locals, (0..n).collect::<Vec<_>>(), "fresh local numbers");
        assert_eq!(linker.number(vertices[1].0), 1, "a vertex keeps its number");
        linker.prepare(n as usize);
        assert_eq!(linker.use_dense, n <= MAX_DENSE);
        for (k, w) in vertices.windows(2).enumerate() {
            linker.put(w[0], w[1], k as u32);
        }
        for (k, w) in vertices.windows(2).enumerate() {
            assert_eq!(linker.get(w[0], w[1]), Some(k as u32));
        }
    }

    #[test]
    fn directed_edges_are_found_in_the_dense_and_the_hashed_table() {
        let mut linker = EdgeLinker::default();
        link_chain(&mut linker, 20);
        link_chain(&mut linker, MAX_DENSE + 40);
        link_chain(&mut linker, 5);
    }

    #[test]
    fn the_hashed_table_tells_missing_edges() {
        let mut table = EdgeTable::default();
        table.clear(10);
        table.insert(edge_key(1, 2), 5);
        assert_eq!(table.get(edge_key(1, 2)), Some(5));
        assert_eq!(table.get(edge_key(2, 1)), None);
        table.clear(10);
        assert_eq!(table.get(edge_key(1, 2)), None);
    }
}
