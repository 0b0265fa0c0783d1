//! Boundary loops: cycles of boundary half-edges, each listed in order.

use super::{HalfedgeId, Mesh};

/// Boundary loops, each a list of boundary half-edges in order (the head of one is the tail of
/// the next). The interior of the mesh lies to the left of each half-edge.
pub fn boundary_loops(mesh: &Mesh) -> Vec<Vec<HalfedgeId>> {
    let nh = mesh.n_halfedges();
    let mut seen = vec![false; nh];
    let mut loops = Vec::new();
    for h0 in 0..nh {
        let h0 = HalfedgeId::from_idx(h0);
        if seen[h0.idx()] || !mesh.is_boundary_halfedge(h0) {
            continue;
        }
        let mut lp = Vec::new();
        let mut h = h0;
        loop {
            seen[h.idx()] = true;
            lp.push(h);
            h = next_boundary(mesh, h);
            if h == h0 || seen[h.idx()] {
                break;
            }
        }
        loops.push(lp);
    }
    loops
}

/// The boundary half-edge that starts where `h` ends.
fn next_boundary(mesh: &Mesh, h: HalfedgeId) -> HalfedgeId {
    // Rotate around head(h) clockwise from next(h) until a boundary half-edge is found.
    let mut g = h.next();
    while let Some(t) = mesh.twin(g) {
        g = t.next();
    }
    g
}
