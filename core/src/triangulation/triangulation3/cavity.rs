//! Reusable buffers of the cavity search and re-triangulation, so insertion does not allocate.

use std::collections::HashMap;

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
pub(super) struct HashMarks(HashMap<u32, bool>);

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

/// Open-addressing map from a directed cavity-boundary edge to the new facet that holds it.
///
/// The boundary of a cavity is an oriented closed surface, so each of its edges is seen once in
/// each direction by the two new cells sharing it. Linking runs in two passes — every new cell
/// stores its three directed edges, then looks up their reversals — so neither pass branches on
/// whether the twin came first (an unpredictable branch in a one-pass find-or-insert). A
/// generation stamp empties the whole table between insertions without touching it.
#[derive(Clone, Debug, Default)]
pub(super) struct EdgeTable {
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
    pub(super) fn clear(&mut self, facets: usize) {
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
    pub(super) fn insert(&mut self, key: u64, value: u32) {
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
    pub(super) fn get(&self, key: u64) -> Option<u32> {
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
}

/// Buffers reused by every insertion.
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    pub(super) mark: Vec<u8>,
    pub(super) stack: Vec<u32>,
    pub(super) cavity: Vec<u32>,
    pub(super) boundary: Vec<(u32, u8)>,
    pub(super) new_cells: Vec<NewCell>,
    pub(super) edges: EdgeTable,
    /// Vertices swallowed by a weighted insertion.
    pub(super) swallowed: Vec<u32>,
    /// Per-vertex marks of the swallowed-vertex search: equal to `stamp` when seen this time.
    pub(super) vertex_stamp: Vec<u32>,
    pub(super) stamp: u32,
}
