//! Slicing a mesh open along a set of edges: every vertex gets one copy per wedge of faces
//! between consecutive cut edges around it, so the cut edges become boundary edges (twice).

use crate::error::{Error, Result};
use crate::mesh::{EdgeId, HalfedgeId, Mesh, VertexId};

/// A mesh cut open, with the vertex each copy came from.
#[derive(Debug, Clone)]
pub struct CutMesh {
    pub mesh: Mesh,
    /// Per vertex of `mesh`: the vertex of the uncut mesh it copies.
    pub orig: Vec<VertexId>,
}

/// Cuts `mesh` along the edges flagged in `cut` (indexed by edge).
///
/// # Errors
/// `Internal` if a corner gets no copy (a bug). The sliced mesh reuses `mesh`'s connectivity
/// ([`Mesh::sliced`]), so slicing is linear and needs no validation pass.
pub fn cut_along(mesh: &Mesh, cut: &[bool]) -> Result<CutMesh> {
    let is_cut = |e: EdgeId| cut.get(e.idx()).copied().unwrap_or(false);
    // Copy id of each half-edge's tail, in the face of that half-edge.
    let mut corner_copy = vec![u32::MAX; mesh.n_halfedges()];
    let mut orig = Vec::with_capacity(mesh.n_vertices());
    for v in 0..mesh.n_vertices() {
        let v = VertexId::from_idx(v);
        let out: Vec<HalfedgeId> = mesh.outgoing(v).collect();
        if out.is_empty() {
            continue;
        }
        let boundary = mesh.is_boundary_vertex(v);
        // Interior vertices start right after a cut edge so the last wedge closes correctly.
        let start = if boundary { 0 } else { out.iter().position(|&h| is_cut(mesh.edge(h))).unwrap_or(0) };
        let d = out.len();
        orig.push(v);
        let mut copy = (orig.len() - 1) as u32;
        for k in 0..d {
            let h = out[(start + k) % d];
            if k > 0 && is_cut(mesh.edge(h)) {
                orig.push(v);
                copy = (orig.len() - 1) as u32;
            }
            corner_copy[h.idx()] = copy;
        }
    }
    let mut faces = Vec::with_capacity(mesh.n_faces());
    for f in 0..mesh.n_faces() {
        let mut t = [VertexId(0); 3];
        for (k, tk) in t.iter_mut().enumerate() {
            let c = corner_copy[3 * f + k];
            if c == u32::MAX {
                return Err(Error::Internal("cut: a corner was not assigned a copy".into()));
            }
            *tk = VertexId(c);
        }
        faces.push(t);
    }
    let pos = orig.iter().map(|&v| mesh.position(v)).collect();
    let cut_mesh = mesh.sliced(pos, faces, cut);
    debug_assert!(Mesh::from_triangles(cut_mesh.positions().to_vec(), &cut_mesh.face_indices()).is_ok());
    Ok(CutMesh { mesh: cut_mesh, orig })
}

/// The edge between `a` and `b`, if any.
pub fn edge_between(mesh: &Mesh, a: VertexId, b: VertexId) -> Option<EdgeId> {
    mesh.outgoing(a).find(|&h| mesh.head(h) == b).map(|h| mesh.edge(h)).or_else(|| {
        // A boundary vertex's last neighbour is reached by an incoming half-edge.
        mesh.outgoing(b).find(|&h| mesh.head(h) == a).map(|h| mesh.edge(h))
    })
}

/// Flags the edges of vertex paths (consecutive pairs).
///
/// # Errors
/// `Internal` when consecutive path vertices are not adjacent.
pub fn path_edges(mesh: &Mesh, paths: &[Vec<VertexId>]) -> Result<Vec<bool>> {
    let mut cut = vec![false; mesh.n_edges()];
    for p in paths {
        for w in p.windows(2) {
            let e = edge_between(mesh, w[0], w[1])
                .ok_or_else(|| Error::Internal(format!("path step {}-{} is not an edge", w[0].0, w[1].0)))?;
            cut[e.idx()] = true;
        }
    }
    Ok(cut)
}
