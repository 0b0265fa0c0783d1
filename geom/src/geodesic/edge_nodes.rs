//! Shortest paths over vertices plus adaptive edge nodes (Kwok, Zhang, Wang 2008, section 4).
//!
//! Each edge carries `e = max(b, ceil(b * l / l_bar))` evenly spaced nodes, where `l` is its
//! length and `l_bar` the mean length of the edges at its two endpoints (itself included);
//! `b = 3` by default. Inside a face, every two nodes that do not share an edge are joined by a
//! straight arc; along an edge, consecutive nodes are joined. Paths therefore cross faces and
//! are returned as surface points. The search is A* with the Euclidean distance to the target
//! (admissible and consistent, since every arc is a straight segment), restricted on request to
//! a face subset and to unblocked nodes. Arcs are enumerated on the fly; nothing is stored
//! per arc, and the per-search arrays are reused across queries through generation stamps.

use super::heap::MinHeap;
use crate::error::{InputError, Result};
use crate::mesh::{EdgeId, FaceId, Mesh, P3, VertexId};
use crate::topology::SurfacePoint;
use serde::{Deserialize, Serialize};
use std::cell::RefCell;

/// Options for building an [`EdgeNodeGraph`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EdgeNodeOptions {
    /// Minimal number of edge nodes per edge (`b` in the paper).
    pub min_nodes: u32,
    /// Upper bound per edge, against pathological slivers.
    pub max_nodes: u32,
    /// Edges around anchors carry `ring_factor * min_nodes` nodes (1: no extra nodes).
    pub ring_factor: u32,
}

impl Default for EdgeNodeOptions {
    fn default() -> Self {
        Self { min_nodes: 3, max_nodes: 64, ring_factor: 3 }
    }
}

/// A node: a vertex (`id < n_vertices`) or an edge node.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub struct NodeId(pub u32);

/// Options for one path search.
#[derive(Debug, Clone, Default)]
pub struct PathOptions<'a> {
    /// Only faces in this set may be crossed (indexed by face).
    pub faces: Option<&'a [bool]>,
    /// Nodes that may not be used (indexed by node), other than the two ends.
    pub blocked: Option<&'a [bool]>,
}

/// A path on the surface: its nodes, as surface points, and its length.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfacePath {
    pub nodes: Vec<NodeId>,
    pub points: Vec<SurfacePoint>,
    pub length: f64,
}

/// The graph of vertices and edge nodes of one mesh.
pub struct EdgeNodeGraph<'m> {
    mesh: &'m Mesh,
    /// Per edge: number of interior nodes.
    count: Vec<u32>,
    /// Per edge: id of its first interior node.
    first: Vec<u32>,
    /// Per node: the edge it lies on (edge nodes only, offset by `n_vertices`).
    node_edge: Vec<u32>,
    pos: Vec<P3>,
    scratch: RefCell<Scratch>,
}

#[derive(Default)]
struct Scratch {
    generation: u32,
    stamp: Vec<u32>,
    dist: Vec<f64>,
    pred: Vec<u32>,
    done: Vec<bool>,
    heap: MinHeap,
}

impl<'m> EdgeNodeGraph<'m> {
    /// Places the adaptive edge nodes.
    pub fn new(mesh: &'m Mesh, opts: &EdgeNodeOptions) -> Self {
        Self::with_minimum(mesh, opts, &|_| 0)
    }

    /// Places the adaptive edge nodes, with at least `min_count(e)` on edge `e` (used to give
    /// the rings of anchors room for many paths).
    pub fn with_minimum(mesh: &'m Mesh, opts: &EdgeNodeOptions, min_count: &dyn Fn(EdgeId) -> u32) -> Self {
        let nv = mesh.n_vertices();
        let ne = mesh.n_edges();
        let len: Vec<f64> = (0..ne).map(|e| mesh.edge_length(EdgeId::from_idx(e))).collect();
        let mut vsum = vec![0.0; nv];
        let mut vcnt = vec![0u32; nv];
        for (e, &l) in len.iter().enumerate() {
            for v in mesh.edge_vertices(EdgeId::from_idx(e)) {
                vsum[v.idx()] += l;
                vcnt[v.idx()] += 1;
            }
        }
        let b = opts.min_nodes.max(1);
        let mut count = Vec::with_capacity(ne);
        let mut first = Vec::with_capacity(ne);
        let mut next = nv as u32;
        for (e, &l) in len.iter().enumerate() {
            let [a, c] = mesh.edge_vertices(EdgeId::from_idx(e));
            let n = (vcnt[a.idx()] + vcnt[c.idx()] - 1).max(1);
            let lbar = (vsum[a.idx()] + vsum[c.idx()] - l) / f64::from(n);
            let adaptive = if lbar > 0.0 { (f64::from(b) * l / lbar).ceil() } else { f64::from(b) };
            let k = (adaptive as u32).clamp(b, opts.max_nodes.max(b)).max(min_count(EdgeId::from_idx(e)));
            count.push(k);
            first.push(next);
            next += k;
        }
        let mut pos = mesh.positions().to_vec();
        pos.reserve(next as usize - nv);
        let mut node_edge = Vec::with_capacity(next as usize - nv);
        for (e, &k) in count.iter().enumerate() {
            let h = mesh.edge_halfedge(EdgeId::from_idx(e));
            let (p, q) = (mesh.position(mesh.tail(h)), mesh.position(mesh.head(h)));
            for i in 0..k {
                let t = f64::from(i + 1) / f64::from(k + 1);
                pos.push(P3::from(p.coords * (1.0 - t) + q.coords * t));
                node_edge.push(e as u32);
            }
        }
        Self { mesh, count, first, node_edge, pos, scratch: RefCell::new(Scratch::default()) }
    }

    /// The mesh.
    pub fn mesh(&self) -> &'m Mesh {
        self.mesh
    }
    /// Total number of nodes (vertices + edge nodes).
    pub fn n_nodes(&self) -> usize {
        self.pos.len()
    }
    /// Number of interior nodes on an edge.
    pub fn edge_node_count(&self, e: EdgeId) -> u32 {
        self.count[e.idx()]
    }
    /// Node of a vertex.
    pub fn vertex_node(&self, v: VertexId) -> NodeId {
        NodeId(v.0)
    }
    /// The `i`-th interior node of edge `e`, counted from the tail of `edge_halfedge(e)`.
    pub fn edge_node(&self, e: EdgeId, i: u32) -> NodeId {
        NodeId(self.first[e.idx()] + i)
    }
    /// The vertex of a node, if it is one.
    pub fn as_vertex(&self, n: NodeId) -> Option<VertexId> {
        ((n.0 as usize) < self.mesh.n_vertices()).then_some(VertexId(n.0))
    }
    /// Edge and index of an edge node.
    pub fn as_edge_node(&self, n: NodeId) -> Option<(EdgeId, u32)> {
        let nv = self.mesh.n_vertices() as u32;
        (n.0 >= nv).then(|| {
            let e = self.node_edge[(n.0 - nv) as usize];
            (EdgeId(e), n.0 - self.first[e as usize])
        })
    }
    /// 3D position of a node.
    pub fn position(&self, n: NodeId) -> P3 {
        self.pos[n.0 as usize]
    }
    /// A node as a surface point.
    pub fn surface_point(&self, n: NodeId) -> SurfacePoint {
        match self.as_edge_node(n) {
            None => SurfacePoint::Vertex { vertex: VertexId(n.0) },
            Some((e, i)) => SurfacePoint::Edge {
                halfedge: self.mesh.edge_halfedge(e),
                t: f64::from(i + 1) / f64::from(self.count[e.idx()] + 1),
            },
        }
    }

    /// Calls `f(node)` for the interior nodes of edge `e`.
    fn for_edge_interior(&self, e: EdgeId, mut f: impl FnMut(NodeId)) {
        let s = self.first[e.idx()];
        for i in 0..self.count[e.idx()] {
            f(NodeId(s + i));
        }
    }

    /// Neighbours of `n`, each with the face its arc crosses (`None` for an arc along an edge);
    /// `allowed` filters faces.
    pub fn arcs(&self, n: NodeId, allowed: &dyn Fn(FaceId) -> bool, mut f: impl FnMut(NodeId, Option<FaceId>)) {
        let m = self.mesh;
        match self.as_edge_node(n) {
            None => {
                let v = VertexId(n.0);
                for h in m.outgoing(v) {
                    let face = h.face();
                    let e_out = m.edge(h);
                    let edge_ok = allowed(face) || m.twin(h).is_some_and(|t| allowed(t.face()));
                    if edge_ok {
                        // Along the outgoing edge: the nearest node on it.
                        f(self.first_along(e_out, v), None);
                    }
                    if allowed(face) {
                        // Across the face: interior nodes of the opposite edge.
                        self.for_edge_interior(m.edge(h.next()), |w| f(w, Some(face)));
                    }
                    let p = h.prev();
                    if m.twin(p).is_none() && allowed(face) {
                        f(self.first_along(m.edge(p), v), None);
                    }
                }
            }
            Some((e, i)) => {
                let k = self.count[e.idx()];
                let h = m.edge_halfedge(e);
                let edge_ok = allowed(h.face()) || m.twin(h).is_some_and(|t| allowed(t.face()));
                if edge_ok {
                    f(if i == 0 { NodeId(m.tail(h).0) } else { NodeId(n.0 - 1) }, None);
                    f(if i + 1 == k { NodeId(m.head(h).0) } else { NodeId(n.0 + 1) }, None);
                }
                for side in [Some(h), m.twin(h)].into_iter().flatten() {
                    if !allowed(side.face()) {
                        continue;
                    }
                    let face = side.face();
                    f(NodeId(m.tail(side.prev()).0), Some(face));
                    self.for_edge_interior(m.edge(side.next()), |w| f(w, Some(face)));
                    self.for_edge_interior(m.edge(side.prev()), |w| f(w, Some(face)));
                }
            }
        }
    }

    /// The interior node of edge `e` nearest to its endpoint `v` (or the other endpoint when
    /// the edge has no interior nodes).
    fn first_along(&self, e: EdgeId, v: VertexId) -> NodeId {
        let h = self.mesh.edge_halfedge(e);
        let k = self.count[e.idx()];
        if k == 0 {
            let o = if self.mesh.tail(h) == v { self.mesh.head(h) } else { self.mesh.tail(h) };
            return NodeId(o.0);
        }
        if self.mesh.tail(h) == v { NodeId(self.first[e.idx()]) } else { NodeId(self.first[e.idx()] + k - 1) }
    }

    /// Shortest path between two nodes, or `None` when the target cannot be reached.
    ///
    /// # Errors
    /// `InputError::Invalid` for masks of the wrong size or nodes out of range.
    pub fn shortest_path(&self, from: NodeId, to: NodeId, opts: &PathOptions) -> Result<Option<SurfacePath>> {
        let nn = self.n_nodes();
        if opts.faces.is_some_and(|m| m.len() != self.mesh.n_faces()) {
            return Err(InputError::Invalid("face mask size differs from the face count".into()).into());
        }
        if opts.blocked.is_some_and(|m| m.len() != nn) {
            return Err(InputError::Invalid("blocked-node mask size differs from the node count".into()).into());
        }
        self.shortest_path_filtered(from, to, opts)
    }

    /// Shortest path between two nodes under an arbitrary [`SearchFilter`] (A* with the
    /// Euclidean distance to `to`), or `None` when `to` cannot be reached.
    ///
    /// # Errors
    /// `InputError::OutOfRange` for nodes out of range.
    pub fn shortest_path_filtered(
        &self,
        from: NodeId,
        to: NodeId,
        filter: &dyn SearchFilter,
    ) -> Result<Option<SurfacePath>> {
        let nn = self.n_nodes();
        if from.0 as usize >= nn || to.0 as usize >= nn {
            return Err(
                InputError::OutOfRange { what: "path node", index: from.0.max(to.0) as usize, count: nn }.into()
            );
        }
        let allowed = |f: FaceId| filter.face_ok(f);
        let mut guard = self.scratch.borrow_mut();
        let s = &mut *guard;
        if s.stamp.len() != nn {
            s.stamp = vec![0; nn];
            s.dist = vec![f64::INFINITY; nn];
            s.pred = vec![u32::MAX; nn];
            s.done = vec![false; nn];
            s.generation = 0;
        }
        s.generation = s.generation.wrapping_add(1);
        if s.generation == 0 {
            s.stamp.fill(0);
            s.generation = 1;
        }
        let generation = s.generation;
        let goal = self.pos[to.0 as usize];
        let h = |n: u32| (self.pos[n as usize] - goal).norm();
        s.heap.clear();
        s.stamp[from.0 as usize] = generation;
        s.dist[from.0 as usize] = 0.0;
        s.pred[from.0 as usize] = u32::MAX;
        s.done[from.0 as usize] = false;
        s.heap.push(h(from.0), from.0);
        let mut found = false;
        while let Some((_, u)) = s.heap.pop() {
            let ui = u as usize;
            if s.done[ui] {
                continue;
            }
            s.done[ui] = true;
            if u == to.0 {
                found = true;
                break;
            }
            let du = s.dist[ui];
            let pu = self.pos[ui];
            let mut relax = |w: NodeId, face: Option<FaceId>| {
                let wi = w.0 as usize;
                if w != to && !filter.node_ok(w) {
                    return;
                }
                if s.stamp[wi] != generation {
                    s.stamp[wi] = generation;
                    s.dist[wi] = f64::INFINITY;
                    s.done[wi] = false;
                }
                if s.done[wi] {
                    return;
                }
                let nd = du + (self.pos[wi] - pu).norm() * filter.penalty(w);
                if nd < s.dist[wi] && filter.arc_ok(face, NodeId(u), w) {
                    s.dist[wi] = nd;
                    s.pred[wi] = u;
                    s.heap.push(nd + h(w.0), w.0);
                }
            };
            self.arcs(NodeId(u), &allowed, &mut relax);
        }
        if !found {
            return Ok(None);
        }
        let mut nodes = vec![to];
        let mut c = to.0;
        while s.pred[c as usize] != u32::MAX {
            c = s.pred[c as usize];
            nodes.push(NodeId(c));
        }
        nodes.reverse();
        let length = s.dist[to.0 as usize];
        drop(guard);
        let points = nodes.iter().map(|&n| self.surface_point(n)).collect();
        Ok(Some(SurfacePath { nodes, points, length }))
    }

    /// Cyclic position of node `n` on the boundary of face `f`: corner `k` is `k << 16`, and
    /// the nodes on the side from corner `k` to corner `k+1` follow it in order. `None` when
    /// `n` is not on the boundary of `f`. Chords between such positions cross exactly when
    /// their ends interleave, which makes intersection tests purely combinatorial.
    pub fn face_position(&self, f: FaceId, n: NodeId) -> Option<u32> {
        let m = self.mesh;
        for k in 0..3u32 {
            let h = crate::mesh::HalfedgeId::of(f, k as usize);
            match self.as_edge_node(n) {
                None => {
                    if m.tail(h).0 == n.0 {
                        return Some(k << 16);
                    }
                }
                Some((e, i)) => {
                    if m.edge(h) == e {
                        let c = self.count[e.idx()];
                        let off = if m.edge_halfedge(e) == h { i + 1 } else { c - i };
                        return Some((k << 16) | off);
                    }
                }
            }
        }
        None
    }

    /// Angular key of node `n` around vertex `v` (counter-clockwise order of
    /// [`Mesh::outgoing`]), if `n` is adjacent to `v`: every first step of a path leaving `v`
    /// lands on such a node, so keys order the paths at an anchor without any geometry.
    pub fn ring_key(&self, v: VertexId, n: NodeId) -> Option<u32> {
        let m = self.mesh;
        for (k, h) in m.outgoing(v).enumerate() {
            let k = k as u32;
            if self.first_along(m.edge(h), v) == n {
                return Some((2 * k) << 16);
            }
            let opp = h.next();
            if let Some((e, i)) = self.as_edge_node(n)
                && m.edge(opp) == e
            {
                let c = self.count[e.idx()];
                let j = if m.edge_halfedge(e) == opp { i } else { c - 1 - i };
                return Some(((2 * k + 1) << 16) | j);
            }
            let p = h.prev();
            if m.twin(p).is_none() && self.first_along(m.edge(p), v) == n {
                return Some(((2 * k + 1) << 16) | 0xffff);
            }
        }
        None
    }

    /// The nodes adjacent to vertex `v` (its ring), with their [`Self::ring_key`]s.
    pub fn ring(&self, v: VertexId) -> Vec<(NodeId, u32)> {
        let mut out = Vec::new();
        self.arcs(NodeId(v.0), &|_| true, |w, _| out.push(w));
        out.sort_unstable();
        out.dedup();
        out.into_iter().filter_map(|w| self.ring_key(v, w).map(|k| (w, k))).collect()
    }
}

/// Restrictions on a path search: which nodes, faces and arcs it may use.
pub trait SearchFilter {
    /// May the search pass through node `n`? (The target is always allowed.)
    fn node_ok(&self, _n: NodeId) -> bool {
        true
    }
    /// May the search cross face `f`?
    fn face_ok(&self, _f: FaceId) -> bool {
        true
    }
    /// May the search use the arc `from -> to`, which crosses `face` (`None`: along an edge)?
    fn arc_ok(&self, _face: Option<FaceId>, _from: NodeId, _to: NodeId) -> bool {
        true
    }
    /// Length multiplier (at least 1) of arcs entering node `n`: a soft preference.
    fn penalty(&self, _n: NodeId) -> f64 {
        1.0
    }
}

impl SearchFilter for PathOptions<'_> {
    fn node_ok(&self, n: NodeId) -> bool {
        self.blocked.is_none_or(|m| !m[n.0 as usize])
    }
    fn face_ok(&self, f: FaceId) -> bool {
        self.faces.is_none_or(|m| m[f.idx()])
    }
}

/// Convenience: shortest path between two vertices over a fresh edge-node graph.
///
/// # Errors
/// As [`EdgeNodeGraph::shortest_path`].
pub fn shortest_path(
    mesh: &Mesh,
    from: VertexId,
    to: VertexId,
    graph_opts: &EdgeNodeOptions,
    opts: &PathOptions,
) -> Result<Option<SurfacePath>> {
    let g = EdgeNodeGraph::new(mesh, graph_opts);
    g.shortest_path(g.vertex_node(from), g.vertex_node(to), opts)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geodesic::vertex_dijkstra;
    use crate::mesh::shapes;

    #[test]
    fn uniform_grid_has_b_nodes_per_edge() {
        let g = shapes::grid(4);
        let eg = EdgeNodeGraph::new(&g, &EdgeNodeOptions::default());
        // Diagonals are longer than their neighbours' mean, so they get more nodes.
        let min = (0..g.n_edges()).map(|e| eg.edge_node_count(EdgeId::from_idx(e))).min().unwrap();
        assert_eq!(min, 3);
        let max = (0..g.n_edges()).map(|e| eg.edge_node_count(EdgeId::from_idx(e))).max().unwrap();
        assert!(max >= 4);
    }

    #[test]
    fn path_is_shorter_than_vertex_path_and_crosses_faces() {
        let g = shapes::grid(6);
        // From (0,0) to (1, 0.5): not along grid edges or diagonals.
        let a = VertexId(0);
        let b = VertexId((3 * 7 + 6) as u32);
        let p = shortest_path(&g, a, b, &EdgeNodeOptions::default(), &PathOptions::default()).unwrap().unwrap();
        let straight = (g.position(b) - g.position(a)).norm();
        let vd = vertex_dijkstra(&g, &[(a, 0.0)], &Default::default()).unwrap();
        assert!(p.length >= straight - 1e-12);
        assert!(p.length < vd.dist[b.idx()] - 1e-6, "edge nodes shorten the path");
        assert!(p.length < straight * 1.03, "{} vs {}", p.length, straight);
        // Consecutive points are joined by a segment inside one face: length adds up.
        let sum: f64 = p.points.windows(2).map(|w| (w[1].position(&g) - w[0].position(&g)).norm()).sum();
        assert!((sum - p.length).abs() < 1e-12);
        assert!(p.points.iter().any(|q| matches!(q, SurfacePoint::Edge { .. })));
    }

    #[test]
    fn face_mask_and_blocked_nodes_are_respected() {
        let g = shapes::grid(4);
        let eg = EdgeNodeGraph::new(&g, &EdgeNodeOptions::default());
        let mask: Vec<bool> = (0..g.n_faces()).map(|f| f < 8).collect();
        let r = eg.shortest_path(NodeId(0), NodeId(24), &PathOptions { faces: Some(&mask), blocked: None }).unwrap();
        assert!(r.is_none());
        let free = eg.shortest_path(NodeId(0), NodeId(4), &PathOptions::default()).unwrap().unwrap();
        let mut blocked = vec![false; eg.n_nodes()];
        for n in &free.nodes[1..free.nodes.len() - 1] {
            blocked[n.0 as usize] = true;
        }
        let detour = eg
            .shortest_path(NodeId(0), NodeId(4), &PathOptions { faces: None, blocked: Some(&blocked) })
            .unwrap()
            .unwrap();
        assert!(detour.length > free.length);
        assert!(detour.nodes[1..detour.nodes.len() - 1].iter().all(|n| !blocked[n.0 as usize]));
    }
}
