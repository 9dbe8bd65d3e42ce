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
/// taken once per insertion.
#[derive(Clone, Debug, Default)]
pub(super) struct EdgeTable {
    keys: Vec<u64>,
    values: Vec<u32>,
    used: Vec<usize>,
}

const EMPTY: u64 = u64::MAX;
/// Marks a slot whose entry was taken (linear probing must not stop there).
const TAKEN: u64 = u64::MAX - 1;

impl EdgeTable {
    /// Forgets every entry; sizes the table for a cavity of `facets` boundary facets.
    pub(super) fn clear(&mut self, facets: usize) {
        for &s in &self.used {
            self.keys[s] = EMPTY;
        }
        self.used.clear();
        let want = (facets * 4).next_power_of_two().max(64);
        if self.keys.len() < want {
            self.keys = vec![EMPTY; want];
            self.values = vec![0; want];
        }
    }

    /// If `key` is present, removes and returns its value; otherwise stores `value` under it.
    #[inline]
    pub(super) fn take_or_insert(&mut self, key: u64, value: u32) -> Option<u32> {
        let mask = self.keys.len() - 1;
        let mut s = (key.wrapping_mul(0x9E37_79B9_7F4A_7C15) >> 40) as usize & mask;
        let mut free = None;
        loop {
            let k = self.keys[s];
            if k == key {
                self.keys[s] = TAKEN;
                return Some(self.values[s]);
            }
            if k == TAKEN && free.is_none() {
                free = Some(s);
            }
            if k == EMPTY {
                let slot = free.unwrap_or(s);
                self.keys[slot] = key;
                self.values[slot] = value;
                self.used.push(slot);
                return None;
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
}
