//! Regions of a layout from its rotation system: the face walks of the embedded graph of
//! anchors and paths. A walk turns, at every anchor it reaches, to the next path
//! counter-clockwise; its region lies to the right of each half it uses, inside the sector
//! between the reversed incoming half and the outgoing half.
//!
//! For a connected graph on a closed surface, `V - E + W = χ` holds exactly when every region
//! is a disk bounded by one walk (each non-disk region adds at least one walk or a handle).

use super::path::{Sector, uf_find};
use super::tracer::{Half, Tracer};

/// One face walk: `halves[i]` arrives where `halves[i + 1]` leaves.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Walk {
    pub halves: Vec<Half>,
}

/// The half that follows `h` in its walk.
pub fn next_half(t: &Tracer, h: Half) -> Half {
    let x = t.half_end(h);
    let r = t.rotation(x);
    let i = r.iter().position(|&(_, y)| y == h ^ 1).unwrap_or(0);
    r[(i + 1) % r.len()].1
}

/// All face walks, each starting at its smallest half, ordered by that half.
pub fn walks(t: &Tracer) -> Vec<Walk> {
    let nh = 2 * t.paths().len();
    let mut seen = vec![false; nh];
    let mut out = Vec::new();
    for start in 0..nh as Half {
        if seen[start as usize] {
            continue;
        }
        let mut halves = Vec::new();
        let mut h = start;
        while !seen[h as usize] {
            seen[h as usize] = true;
            halves.push(h);
            h = next_half(t, h);
        }
        out.push(Walk { halves });
    }
    out
}

impl Walk {
    /// Anchors at the corners: corner `i` is where `halves[i]` leaves.
    pub fn corners(&self, t: &Tracer) -> Vec<u32> {
        self.halves.iter().map(|&h| t.half_start(h)).collect()
    }
    /// The sector of corner `i` (at the anchor where `halves[i]` leaves).
    pub fn sector(&self, t: &Tracer, i: usize) -> Sector {
        let n = self.halves.len();
        let h_in = self.halves[(i + n - 1) % n];
        let h_out = self.halves[i];
        Sector { from: t.half_key(h_in ^ 1), to: t.half_key(h_out) }
    }
    /// A triangle with three distinct corners.
    pub fn is_triangle(&self, t: &Tracer) -> bool {
        let c = self.corners(t);
        c.len() == 3 && c[0] != c[1] && c[1] != c[2] && c[0] != c[2]
    }
}

/// Connected components of the layout graph (by anchor), and whether every anchor has a path.
pub fn graph_components(t: &Tracer) -> (usize, bool) {
    let na = t.anchors().len();
    let mut parent: Vec<usize> = (0..na).collect();
    for p in t.paths() {
        let (a, b) = (uf_find(&mut parent, p.a as usize), uf_find(&mut parent, p.b as usize));
        parent[a] = b;
    }
    let comps = (0..na).filter(|&i| uf_find(&mut parent, i) == i).count();
    let all = (0..na as u32).all(|a| !t.rotation(a).is_empty());
    (comps, all)
}

/// True when the layout is a cellular triangulation of a closed surface of Euler
/// characteristic `chi`: connected, every anchor used, every walk a triangle, `V - E + W = χ`.
pub fn is_complete(t: &Tracer, chi: i64) -> bool {
    let (comps, all) = graph_components(t);
    let w = walks(t);
    comps == 1
        && all
        && w.iter().all(|x| x.is_triangle(t))
        && t.anchors().len() as i64 - t.paths().len() as i64 + w.len() as i64 == chi
}
