//! A mesh sliced open along some of its edges, built from the parent's connectivity in linear
//! time: faces keep their index and corner order, half-edges keep their twins except across
//! the cut, and no validation pass is needed (each vertex copy is one wedge of a manifold fan,
//! so the result is manifold by construction).

use super::{HalfedgeId, Mesh, P3, VertexAttributes, VertexId};

impl Mesh {
    /// The mesh with the same faces re-indexed to `faces` (one entry per face, corners in the
    /// same order) over `positions`, and with the edges flagged in `cut` (by parent edge) made
    /// boundary on both sides. The caller guarantees that `faces` assigns every wedge between
    /// cut edges around a vertex its own vertex, and nothing else: exactly what slicing does.
    pub(crate) fn sliced(&self, positions: Vec<P3>, faces: Vec<[VertexId; 3]>, cut: &[bool]) -> Mesh {
        let nh = self.twin.len();
        let twin: Vec<HalfedgeId> = (0..nh)
            .map(|h| {
                let e = self.edge_of[h];
                if cut.get(e.idx()).copied().unwrap_or(false) { HalfedgeId::INVALID } else { self.twin[h] }
            })
            .collect();
        let (edge_of, edge_he) = super::build::edges_from_twins(&twin);
        let mut vertex_he = vec![HalfedgeId::INVALID; positions.len()];
        for (f, t) in faces.iter().enumerate() {
            for (k, v) in t.iter().enumerate() {
                let h = HalfedgeId((3 * f + k) as u32);
                let slot = &mut vertex_he[v.idx()];
                if !slot.is_valid() || !twin[h.idx()].is_valid() {
                    *slot = h;
                }
            }
        }
        Mesh { positions, faces, twin, edge_of, edge_he, vertex_he, attributes: VertexAttributes::default() }
    }
}
