//! A min-heap of (distance, node) pairs for Dijkstra, ordered by `f64::total_cmp`.

use std::cmp::Ordering;
use std::collections::BinaryHeap;

#[derive(Clone, Copy, PartialEq)]
struct Entry(f64, u32);

impl Eq for Entry {}
impl Ord for Entry {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then_with(|| o.1.cmp(&self.1))
    }
}
impl PartialOrd for Entry {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Min-heap keyed by distance; stale entries are skipped by the caller (lazy deletion).
#[derive(Default)]
pub(crate) struct MinHeap(BinaryHeap<Entry>);

impl MinHeap {
    pub fn with_capacity(n: usize) -> Self {
        Self(BinaryHeap::with_capacity(n))
    }
    #[inline]
    pub fn push(&mut self, d: f64, n: u32) {
        self.0.push(Entry(d, n));
    }
    #[inline]
    pub fn pop(&mut self) -> Option<(f64, u32)> {
        self.0.pop().map(|e| (e.0, e.1))
    }
    pub fn clear(&mut self) {
        self.0.clear();
    }
}
