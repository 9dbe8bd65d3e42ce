//! A deterministic priority queue of elements to refine: the largest priority first, ties broken
//! by insertion order so that runs are reproducible.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

struct Entry<E> {
    priority: f64,
    seq: u64,
    element: E,
}

impl<E> PartialEq for Entry<E> {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl<E> Eq for Entry<E> {}
impl<E> PartialOrd for Entry<E> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl<E> Ord for Entry<E> {
    fn cmp(&self, other: &Self) -> Ordering {
        self.priority
            .total_cmp(&other.priority)
            .then_with(|| other.seq.cmp(&self.seq))
    }
}

pub(crate) struct RefineQueue<E> {
    heap: BinaryHeap<Entry<E>>,
    seq: u64,
}

impl<E> Default for RefineQueue<E> {
    fn default() -> Self {
        RefineQueue {
            heap: BinaryHeap::new(),
            seq: 0,
        }
    }
}

impl<E> RefineQueue<E> {
    pub(crate) fn push(&mut self, priority: f64, element: E) {
        self.seq += 1;
        self.heap.push(Entry {
            priority,
            seq: self.seq,
            element,
        });
    }

    pub(crate) fn peek(&self) -> Option<&E> {
        self.heap.peek().map(|e| &e.element)
    }

    pub(crate) fn pop(&mut self) {
        self.heap.pop();
    }

    pub(crate) fn len(&self) -> usize {
        self.heap.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn largest_first_then_fifo() {
        let mut q = RefineQueue::default();
        q.push(1.0, 'a');
        q.push(3.0, 'b');
        q.push(1.0, 'c');
        q.push(f64::INFINITY, 'd');
        let mut out = Vec::new();
        while let Some(&e) = q.peek() {
            out.push(e);
            q.pop();
        }
        assert_eq!(out, ['d', 'b', 'a', 'c']);
    }
}
