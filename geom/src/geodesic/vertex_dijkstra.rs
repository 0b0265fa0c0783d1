//! Dijkstra over mesh vertices with Euclidean edge lengths, from one or many sources.

use super::heap::MinHeap;
use crate::error::{InputError, Result};
use crate::mesh::{FaceId, Mesh, VertexId};

/// Options for [`vertex_dijkstra`].
#[derive(Debug, Clone, Default)]
pub struct VertexDijkstraOptions<'a> {
    /// Only edges with at least one incident face in this set (indexed by face) are used.
    pub faces: Option<&'a [bool]>,
    /// Stop once every remaining vertex is farther than this.
    pub max_distance: Option<f64>,
    /// Stop as soon as this vertex is settled.
    pub target: Option<VertexId>,
    /// Stop as soon as every one of these vertices is settled (distances to them are final;
    /// farther vertices may be left unreached).
    pub until_settled: Option<&'a [VertexId]>,
    /// Vertices that may not be entered (indexed by vertex), except `target`: paths kept
    /// vertex-disjoint from earlier paths.
    pub blocked: Option<&'a [bool]>,
}

/// Distances and shortest-path tree.
#[derive(Debug, Clone)]
pub struct VertexDijkstraResult {
    /// Distance per vertex (`inf` where unreached).
    pub dist: Vec<f64>,
    /// Predecessor per vertex (`INVALID` for sources and unreached vertices).
    pub pred: Vec<VertexId>,
    /// Index of the source each vertex was reached from (`u32::MAX` where unreached).
    pub source: Vec<u32>,
}

impl VertexDijkstraResult {
    /// Vertices from the source to `v`, if `v` was reached.
    pub fn path_to(&self, v: VertexId) -> Option<Vec<VertexId>> {
        if !self.dist.get(v.idx())?.is_finite() {
            return None;
        }
        let mut p = vec![v];
        let mut c = v;
        while self.pred[c.idx()].is_valid() {
            c = self.pred[c.idx()];
            p.push(c);
        }
        p.reverse();
        Some(p)
    }
}

/// Multi-source Dijkstra over vertices; each source starts at its given offset distance.
///
/// # Errors
/// `InputError::OutOfRange` for a source outside the mesh, `Invalid` for a face mask of the
/// wrong length.
pub fn vertex_dijkstra(
    mesh: &Mesh,
    sources: &[(VertexId, f64)],
    opts: &VertexDijkstraOptions,
) -> Result<VertexDijkstraResult> {
    let nv = mesh.n_vertices();
    if let Some(m) = opts.faces
        && m.len() != mesh.n_faces()
    {
        return Err(
            InputError::Invalid(format!("face mask has {} entries for {} faces", m.len(), mesh.n_faces())).into()
        );
    }
    if let Some(b) = opts.blocked
        && b.len() != nv
    {
        return Err(InputError::Invalid(format!("vertex mask has {} entries for {nv} vertices", b.len())).into());
    }
    let mut dist = vec![f64::INFINITY; nv];
    let mut pred = vec![VertexId::INVALID; nv];
    let mut source = vec![u32::MAX; nv];
    let mut done = vec![false; nv];
    if let Some(b) = opts.blocked {
        for (d, &b) in done.iter_mut().zip(b) {
            *d = b;
        }
        if let Some(t) = opts.target
            && t.idx() < nv
        {
            done[t.idx()] = false;
        }
        for &(s, _) in sources {
            if s.idx() < nv {
                done[s.idx()] = false;
            }
        }
    }
    let mut heap = MinHeap::with_capacity(1024);
    for (i, &(s, d0)) in sources.iter().enumerate() {
        if s.idx() >= nv {
            return Err(InputError::OutOfRange { what: "source vertex", index: s.idx(), count: nv }.into());
        }
        if d0 < dist[s.idx()] {
            dist[s.idx()] = d0;
            source[s.idx()] = i as u32;
            heap.push(d0, s.0);
        }
    }
    let allowed = |f: FaceId| opts.faces.is_none_or(|m| m[f.idx()]);
    // Vertices still to settle before stopping early (each counted once).
    let mut waiting = vec![false; if opts.until_settled.is_some() { nv } else { 0 }];
    let mut left = 0usize;
    for &v in opts.until_settled.unwrap_or(&[]) {
        if v.idx() < nv && !std::mem::replace(&mut waiting[v.idx()], true) {
            left += 1;
        }
    }
    let max_d = opts.max_distance.unwrap_or(f64::INFINITY);
    while let Some((d, u)) = heap.pop() {
        let ui = u as usize;
        if done[ui] || d > dist[ui] {
            continue;
        }
        if d > max_d {
            break;
        }
        done[ui] = true;
        if opts.target == Some(VertexId(u)) {
            break;
        }
        if opts.until_settled.is_some() && std::mem::replace(&mut waiting[ui], false) {
            left -= 1;
            if left == 0 {
                break;
            }
        }
        let pu = mesh.position(VertexId(u));
        for h in mesh.outgoing(VertexId(u)) {
            // Edge h borders face(h) and, if interior, its twin's face.
            let f = h.face();
            if allowed(f) || mesh.twin(h).is_some_and(|t| allowed(t.face())) {
                relax(mesh, &mut dist, &mut pred, &mut source, &done, &mut heap, ui, d, pu, mesh.head(h));
            }
            // A boundary vertex's last neighbour is reached only through prev(h) of its last face.
            let p = h.prev();
            if mesh.twin(p).is_none() && allowed(f) {
                relax(mesh, &mut dist, &mut pred, &mut source, &done, &mut heap, ui, d, pu, mesh.tail(p));
            }
        }
    }
    Ok(VertexDijkstraResult { dist, pred, source })
}

#[allow(clippy::too_many_arguments)]
#[inline]
fn relax(
    mesh: &Mesh,
    dist: &mut [f64],
    pred: &mut [VertexId],
    source: &mut [u32],
    done: &[bool],
    heap: &mut MinHeap,
    u: usize,
    d: f64,
    pu: crate::mesh::P3,
    v: VertexId,
) {
    let vi = v.idx();
    if done[vi] {
        return;
    }
    let nd = d + (mesh.position(v) - pu).norm();
    if nd < dist[vi] {
        dist[vi] = nd;
        pred[vi] = VertexId(u as u32);
        source[vi] = source[u];
        heap.push(nd, v.0);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    /// Stopping once some vertices are settled leaves their distances as the full search's.
    #[test]
    fn stopping_once_vertices_are_settled_keeps_their_distances() {
        let m = shapes::icosphere(3);
        let full = vertex_dijkstra(&m, &[(VertexId(0), 0.0)], &Default::default()).unwrap();
        let want = [VertexId(5), VertexId(17), VertexId(5)];
        let opts = VertexDijkstraOptions { until_settled: Some(&want), ..Default::default() };
        let part = vertex_dijkstra(&m, &[(VertexId(0), 0.0)], &opts).unwrap();
        for v in want {
            assert_eq!(part.dist[v.idx()], full.dist[v.idx()]);
        }
        assert!(part.dist.iter().any(|d| d.is_infinite()), "the search did not stop early");
    }

    #[test]
    fn grid_distances_are_graph_distances() {
        let g = shapes::grid(4);
        let r = vertex_dijkstra(&g, &[(VertexId(0), 0.0)], &Default::default()).unwrap();
        // Opposite corner along the diagonal edges: 4 * sqrt(2) / 4.
        let far = VertexId::from_idx(24);
        assert!((r.dist[far.idx()] - 2f64.sqrt()).abs() < 1e-12);
        let p = r.path_to(far).unwrap();
        assert_eq!(p.first(), Some(&VertexId(0)));
        assert_eq!(p.last(), Some(&far));
        assert!(r.dist.iter().all(|d| d.is_finite()));
    }

    #[test]
    fn face_mask_restricts_search() {
        let g = shapes::grid(4);
        // Only the faces of the bottom row of squares.
        let mask: Vec<bool> = (0..g.n_faces()).map(|f| f < 8).collect();
        let r = vertex_dijkstra(
            &g,
            &[(VertexId(0), 0.0)],
            &VertexDijkstraOptions { faces: Some(&mask), ..Default::default() },
        )
        .unwrap();
        assert!(r.dist[24].is_infinite());
        assert!(r.dist[9].is_finite());
    }
}
