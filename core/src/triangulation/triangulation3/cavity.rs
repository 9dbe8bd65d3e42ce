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

/// Open-addressing map from a cavity-boundary edge to the half-linked new facet waiting for its
/// twin. Every boundary edge is shared by exactly two new cells, so each key is inserted once and
/// found once per insertion: found entries stay in place (their key cannot come back), and a
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
        // 3/2 edges per facet in at least 4 slots per facet: probes stay short.
        let want = (facets * 4).next_power_of_two().max(64);
        if self.slots.len() < want || self.generation == u32::MAX {
            self.slots = vec![EdgeSlot::default(); want];
            self.generation = 0;
        }
        self.generation += 1;
    }

    /// If `key` is present, returns its value; otherwise stores `value` under it.
    #[inline]
    pub(super) fn find_or_insert(&mut self, key: u64, value: u32) -> Option<u32> {
        let mask = self.slots.len() - 1;
        let mut s = (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) as usize & mask;
        loop {
            let slot = &mut self.slots[s];
            if slot.generation != self.generation {
                *slot = EdgeSlot {
                    key,
                    value,
                    generation: self.generation,
                };
                return None;
            }
            if slot.key == key {
                return Some(slot.value);
            }
            s = (s + 1) & mask;
        }
    }
}

/// Buffers reused by every insertion.
#[derive(Clone, Debug, Default)]
pub(super) struct Scratch {
    pub(super) mark: Vec<u8>,
    pub(super) stack: Vec<u32>,
    pub(super) cavity: Vec<u32>,
    pub(super) boundary: Vec<(u32, u8)>,
    /// New cells: vertices, index of the new vertex's opposite facet, packed outside neighbour.
    pub(super) new_cells: Vec<([u32; 4], u8, u32)>,
    pub(super) edges: EdgeTable,
    /// Vertices swallowed by a weighted insertion.
    pub(super) swallowed: Vec<u32>,
    /// Per-vertex marks of the swallowed-vertex search: equal to `stamp` when seen this time.
    pub(super) vertex_stamp: Vec<u32>,
    pub(super) stamp: u32,
}
