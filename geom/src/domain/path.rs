//! What the tracer and the walks share with the rest of the module: a layout path, the sector
//! of an anchor's ring, and union-find.

use crate::geodesic::NodeId;
use crate::topology::SurfacePoint;
use serde::{Deserialize, Serialize};

/// A path of a layout between anchors `a` and `b` (indices into the anchor list).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LayoutPath {
    pub a: u32,
    pub b: u32,
    pub nodes: Vec<NodeId>,
    pub points: Vec<SurfacePoint>,
    pub length: f64,
}

/// Root of `x` in a union-find forest (with path halving).
pub(crate) fn uf_find(p: &mut [usize], mut x: usize) -> usize {
    while p[x] != x {
        p[x] = p[p[x]];
        x = p[x];
    }
    x
}

/// A cyclic interval of ring keys around an anchor, both ends excluded; `from == to` means
/// every key but that one.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Sector {
    pub from: u32,
    pub to: u32,
}

impl Sector {
    pub fn contains(&self, k: u32) -> bool {
        match self.from.cmp(&self.to) {
            std::cmp::Ordering::Less => self.from < k && k < self.to,
            std::cmp::Ordering::Greater => k > self.from || k < self.to,
            std::cmp::Ordering::Equal => k != self.from,
        }
    }
}
