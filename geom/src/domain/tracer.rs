//! The path tracer of one mesh: a growing set of non-crossing paths between anchors over the
//! adaptive edge-node graph (Kwok et al., section 4), with its rotation system.
//!
//! Intersection prevention is topological, as in the paper's Fig. 7: every path arc that
//! crosses a face is recorded as a chord between two cyclic positions on the face's boundary
//! (corners and edge nodes). A new arc may cross a face only if its ends do not interleave with
//! an existing chord of that face, i.e. both ends lie in the same region of the split face;
//! nodes a path passes through are used up. No floating-point predicate is involved.
//!
//! Around each anchor the paths are ordered by the ring key of their first node
//! ([`EdgeNodeGraph::ring_key`]), which gives the rotation system of the layout graph; its
//! face walks ([`super::walks`]) are the regions of the layout.

use super::path::{LayoutPath, Sector};
use crate::error::{Error, InputError, Result};
use crate::geodesic::{EdgeNodeGraph, EdgeNodeOptions, NodeId, SearchFilter};
use crate::mesh::{FaceId, Mesh, VertexId};

/// Half of a path: `2p` runs from `paths[p].a` to `paths[p].b`, `2p + 1` back.
pub type Half = u32;

/// A request to trace one path.
#[derive(Debug, Clone, Default)]
pub struct TraceRequest<'a> {
    /// Anchor indices of the two ends.
    pub a: u32,
    pub b: u32,
    /// Only these faces may be crossed.
    pub faces: Option<&'a [bool]>,
    /// Extra nodes the path may not use.
    pub blocked: &'a [NodeId],
    /// Allowed angular sector of the first step at `a` and of the last step at `b`.
    pub sector_a: Option<Sector>,
    pub sector_b: Option<Sector>,
}

/// Paths on one mesh, kept free of crossings.
pub struct Tracer<'m> {
    graph: EdgeNodeGraph<'m>,
    anchors: Vec<VertexId>,
    anchor_of: Vec<u32>,
    used: Vec<bool>,
    tmp_block: Vec<bool>,
    /// Ring nodes next (in ring order) to a used ring node of the traced path's anchors.
    near: Vec<bool>,
    chords: Vec<Vec<(u32, u32)>>,
    paths: Vec<LayoutPath>,
    /// Per anchor: (ring key, half leaving the anchor), sorted by key.
    rot: Vec<Vec<(u32, Half)>>,
    /// Per node: the anchor whose ring it belongs to (`MAX`: none, `MAX - 1`: several).
    ring_owner: Vec<u32>,
    /// Per anchor: its ring nodes sorted by key.
    rings: Vec<Vec<(NodeId, u32)>>,
    opts: EdgeNodeOptions,
    /// Paths `0..fixed` were given ([`Tracer::fix`]): never re-traced, flipped or removed.
    fixed: u32,
    /// Faces no traced path may cross (the inside of a cap, already split by fixed paths).
    closed: Vec<bool>,
}

struct Filter<'a, 't> {
    t: &'a Tracer<'t>,
    faces: Option<&'a [bool]>,
    ends: [u32; 2],
}

/// Arc-length factor for stepping next to an existing path (along an edge, or beside one at
/// an anchor): paths keep a free node between them where they can, so that no region between
/// two paths is left without nodes to pass through, yet may touch where they must.
const CLEARANCE_PENALTY: f64 = 4.0;
const RING_PENALTY: f64 = 1000.0;

impl Filter<'_, '_> {
    fn next_to_used(&self, n: NodeId) -> bool {
        let g = &self.t.graph;
        let Some((e, i)) = g.as_edge_node(n) else { return false };
        let k = g.edge_node_count(e);
        let [a, b] = self.t.graph.mesh().edge_vertices(e);
        let (tail, head) = {
            let h = self.t.graph.mesh().edge_halfedge(e);
            let t = self.t.graph.mesh().tail(h);
            if t == a { (a, b) } else { (b, a) }
        };
        let before = if i == 0 { g.vertex_node(tail) } else { g.edge_node(e, i - 1) };
        let after = if i + 1 == k { g.vertex_node(head) } else { g.edge_node(e, i + 1) };
        self.t.used[before.0 as usize] || self.t.used[after.0 as usize]
    }
}

impl SearchFilter for Filter<'_, '_> {
    fn node_ok(&self, n: NodeId) -> bool {
        let i = n.0 as usize;
        !self.t.used[i] && !self.t.tmp_block[i] && (i >= self.t.anchor_of.len() || self.t.anchor_of[i] == u32::MAX)
    }
    fn face_ok(&self, f: FaceId) -> bool {
        !self.t.closed[f.idx()] && self.faces.is_none_or(|m| m[f.idx()])
    }
    fn arc_ok(&self, face: Option<FaceId>, from: NodeId, to: NodeId) -> bool {
        let Some(f) = face else { return true };
        let ch = &self.t.chords[f.idx()];
        if ch.is_empty() {
            return true;
        }
        let (Some(p), Some(q)) = (self.t.graph.face_position(f, from), self.t.graph.face_position(f, to)) else {
            return false;
        };
        !ch.iter().any(|&(a, b)| crosses((a, b), (p, q)))
    }
    fn penalty(&self, n: NodeId) -> f64 {
        let owner = self.t.ring_owner[n.0 as usize];
        if owner < u32::MAX - 1 && owner != self.ends[0] && owner != self.ends[1] {
            // Passing right next to another anchor crowds its sectors.
            CLEARANCE_PENALTY
        } else if self.t.near[n.0 as usize] {
            // Leaving an anchor right beside one of its paths would leave a sector without a
            // free ring node: only as a last resort.
            RING_PENALTY
        } else if self.next_to_used(n) {
            CLEARANCE_PENALTY
        } else {
            1.0
        }
    }
}

/// Do chords `x` and `y` of one convex polygon (cyclic positions) cross? Chords sharing an
/// end do not.
pub fn crosses(x: (u32, u32), y: (u32, u32)) -> bool {
    let (a, b) = (x.0.min(x.1), x.0.max(x.1));
    let (c, d) = y;
    if c == a || c == b || d == a || d == b {
        return false;
    }
    let inside = |p: u32| a < p && p < b;
    inside(c) != inside(d)
}

impl<'m> Tracer<'m> {
    /// A tracer with no paths. Anchors must be distinct vertices of `mesh`.
    ///
    /// # Errors
    /// `InputError::Anchors` for anchors out of range or repeated.
    pub fn new(mesh: &'m Mesh, anchors: &[VertexId], opts: &EdgeNodeOptions) -> Result<Self> {
        let nv = mesh.n_vertices();
        let mut anchor_of = vec![u32::MAX; nv];
        for (i, a) in anchors.iter().enumerate() {
            if a.idx() >= nv {
                return Err(InputError::Anchors(format!("anchor {i} is vertex {}, but the mesh has {nv}", a.0)).into());
            }
            if anchor_of[a.idx()] != u32::MAX {
                return Err(InputError::Anchors(format!(
                    "anchors {} and {i} are the same vertex {}",
                    anchor_of[a.idx()],
                    a.0
                ))
                .into());
            }
            anchor_of[a.idx()] = i as u32;
        }
        // An anchor's ring must hold a free node between any two of its paths, and anchors can
        // carry a dozen paths: the edges of anchor stars (and their opposite edges) get
        // `ring_factor` times the minimal node count.
        let mut boost = vec![false; mesh.n_edges()];
        for a in anchors {
            for h in mesh.outgoing(*a) {
                boost[mesh.edge(h).idx()] = true;
                boost[mesh.edge(h.next()).idx()] = true;
            }
        }
        let ring_min = opts.ring_factor.max(1) * opts.min_nodes.max(1);
        let graph = EdgeNodeGraph::with_minimum(mesh, opts, &|e| if boost[e.idx()] { ring_min } else { 0 });
        let nn = graph.n_nodes();
        let mut ring_owner = vec![u32::MAX; nn];
        let mut rings = Vec::with_capacity(anchors.len());
        for (i, &a) in anchors.iter().enumerate() {
            let mut r = graph.ring(a);
            r.sort_unstable_by_key(|x| x.1);
            for &(n, _) in &r {
                let o = &mut ring_owner[n.0 as usize];
                *o = if *o == u32::MAX { i as u32 } else { u32::MAX - 1 };
            }
            rings.push(r);
        }
        Ok(Self {
            graph,
            anchors: anchors.to_vec(),
            anchor_of,
            used: vec![false; nn],
            tmp_block: vec![false; nn],
            near: vec![false; nn],
            chords: vec![Vec::new(); mesh.n_faces()],
            paths: Vec::new(),
            rot: vec![Vec::new(); anchors.len()],
            ring_owner,
            rings,
            opts: *opts,
            fixed: 0,
            closed: vec![false; mesh.n_faces()],
        })
    }

    /// Gives the tracer its fixed paths (inserted as paths `0..paths.len()`, in order) and the
    /// faces no later path may cross. Must come before any other path.
    ///
    /// # Errors
    /// `Error::Internal` when paths exist already or a fixed path is not a chain of arcs.
    pub fn fix(&mut self, paths: Vec<LayoutPath>, closed: &[FaceId]) -> Result<()> {
        if !self.paths.is_empty() {
            return Err(Error::Internal("fixed paths must come first".into()));
        }
        for p in paths {
            self.insert(p)?;
        }
        self.fixed = self.paths.len() as u32;
        for f in closed {
            self.closed[f.idx()] = true;
        }
        Ok(())
    }

    /// A tracer on the same mesh, anchors and options holding only the fixed paths.
    ///
    /// # Errors
    /// As [`Tracer::new`] and [`Tracer::fix`].
    pub fn fresh(&self) -> Result<Tracer<'m>> {
        let mut t = Tracer::new(self.mesh(), &self.anchors, &self.opts)?;
        let closed: Vec<FaceId> =
            self.closed.iter().enumerate().filter(|x| *x.1).map(|(f, _)| FaceId::from_idx(f)).collect();
        t.fix(self.paths[..self.fixed as usize].to_vec(), &closed)?;
        Ok(t)
    }

    /// The faces paths may cross (`None`: all of them).
    pub fn open_faces(&self) -> Option<Vec<bool>> {
        self.closed.iter().any(|&c| c).then(|| self.closed.iter().map(|&c| !c).collect())
    }

    /// Number of fixed paths (they are paths `0..n`).
    pub fn n_fixed(&self) -> u32 {
        self.fixed
    }

    /// Was path `id` given as fixed?
    pub fn is_fixed(&self, id: u32) -> bool {
        id < self.fixed
    }

    /// Is the anchor pair `{a, b}` joined by a fixed path?
    pub fn linked_by_fixed(&self, a: u32, b: u32) -> bool {
        self.paths[..self.fixed as usize].iter().any(|p| (p.a == a && p.b == b) || (p.a == b && p.b == a))
    }

    /// Does anchor `a` lie inside closed faces only (a cap's apex, which no traced path reaches)?
    pub fn is_enclosed(&self, a: u32) -> bool {
        let m = self.mesh();
        m.vertex_faces(self.anchors[a as usize]).all(|f| self.closed[f.idx()])
    }

    /// The edge-node options the graph was built with.
    pub fn edge_node_options(&self) -> EdgeNodeOptions {
        self.opts
    }
    pub fn graph(&self) -> &EdgeNodeGraph<'m> {
        &self.graph
    }
    pub fn mesh(&self) -> &'m Mesh {
        self.graph.mesh()
    }
    pub fn anchors(&self) -> &[VertexId] {
        &self.anchors
    }
    pub fn paths(&self) -> &[LayoutPath] {
        &self.paths
    }
    /// Rotation at anchor `a`: (ring key, half leaving `a`), counter-clockwise.
    pub fn rotation(&self, a: u32) -> &[(u32, Half)] {
        &self.rot[a as usize]
    }
    /// Is node `n` on a path?
    pub fn is_used(&self, n: NodeId) -> bool {
        self.used[n.0 as usize]
    }
    /// Chords of face `f` (cyclic boundary positions of path arcs across it).
    pub fn chords(&self, f: FaceId) -> &[(u32, u32)] {
        &self.chords[f.idx()]
    }
    /// Anchor index at vertex `v`, if any.
    pub fn anchor_at(&self, v: VertexId) -> Option<u32> {
        self.anchor_of.get(v.idx()).copied().filter(|&a| a != u32::MAX)
    }

    /// Traces the shortest admissible path for `req` without inserting it.
    ///
    /// # Errors
    /// `InputError::Anchors` for anchor indices out of range or equal ends.
    pub fn trace(&mut self, req: &TraceRequest) -> Result<Option<LayoutPath>> {
        let na = self.anchors.len() as u32;
        if req.a >= na || req.b >= na || req.a == req.b {
            return Err(InputError::Anchors(format!("cannot link anchors {} and {}", req.a, req.b)).into());
        }
        self.trace_once(req, false)
    }

    fn trace_once(&mut self, req: &TraceRequest, hard_gap: bool) -> Result<Option<LayoutPath>> {
        let mut marked: Vec<NodeId> = req.blocked.to_vec();
        let mut near: Vec<NodeId> = Vec::new();
        for (anchor, sector) in [(req.a, req.sector_a), (req.b, req.sector_b)] {
            let ring = &self.rings[anchor as usize];
            if let Some(s) = sector {
                for &(n, key) in ring {
                    if !s.contains(key) {
                        marked.push(n);
                    }
                }
            }
            let k = ring.len();
            for (i, &(n, _)) in ring.iter().enumerate() {
                if self.used[n.0 as usize] {
                    near.push(ring[(i + 1) % k].0);
                    near.push(ring[(i + k - 1) % k].0);
                }
            }
        }
        if hard_gap {
            marked.extend_from_slice(&near);
            near.clear();
        }
        for n in &near {
            self.near[n.0 as usize] = true;
        }
        for n in &marked {
            self.tmp_block[n.0 as usize] = true;
        }
        let from = self.graph.vertex_node(self.anchors[req.a as usize]);
        let to = self.graph.vertex_node(self.anchors[req.b as usize]);
        let found =
            self.graph.shortest_path_filtered(from, to, &Filter { t: self, faces: req.faces, ends: [req.a, req.b] });
        for n in &marked {
            self.tmp_block[n.0 as usize] = false;
        }
        for n in &near {
            self.near[n.0 as usize] = false;
        }
        let m = self.graph.mesh();
        Ok(found?.map(|p| {
            // The search length includes clearance penalties; report the geometric one.
            let length = p.points.windows(2).map(|w| (w[1].position(m) - w[0].position(m)).norm()).sum();
            LayoutPath { a: req.a, b: req.b, nodes: p.nodes, points: p.points, length }
        }))
    }

    /// Traces and inserts; returns the new path's index.
    ///
    /// # Errors
    /// As [`Self::trace`].
    pub fn trace_insert(&mut self, req: &TraceRequest) -> Result<Option<u32>> {
        match self.trace(req)? {
            Some(p) => self.insert(p).map(Some),
            None => Ok(None),
        }
    }

    /// Inserts a traced path: uses its nodes, records its chords and its place in the
    /// rotations at both ends.
    ///
    /// # Errors
    /// `Error::Internal` if the path is not a valid chain of arcs.
    pub fn insert(&mut self, p: LayoutPath) -> Result<u32> {
        let id = self.paths.len() as u32;
        self.place(id, &p)?;
        self.paths.push(p);
        Ok(id)
    }

    /// Records path `p` as path `id`: chords, used nodes, rotation entries.
    fn place(&mut self, id: u32, p: &LayoutPath) -> Result<()> {
        let k = p.nodes.len();
        if k < 3 {
            return Err(Error::Internal(format!("path of {k} nodes")));
        }
        let va = self.anchors[p.a as usize];
        let vb = self.anchors[p.b as usize];
        let ka = self.graph.ring_key(va, p.nodes[1]).ok_or_else(|| Error::Internal("path leaves its anchor".into()))?;
        let kb =
            self.graph.ring_key(vb, p.nodes[k - 2]).ok_or_else(|| Error::Internal("path enters its anchor".into()))?;
        for w in p.nodes.windows(2) {
            if let Some((f, pa, pb)) = self.arc_face(w[0], w[1]) {
                self.chords[f.idx()].push((pa.min(pb), pa.max(pb)));
            }
        }
        for n in &p.nodes[1..k - 1] {
            self.used[n.0 as usize] = true;
        }
        for (anchor, key, half) in [(p.a, ka, 2 * id), (p.b, kb, 2 * id + 1)] {
            let r = &mut self.rot[anchor as usize];
            let pos = r.partition_point(|&(k2, _)| k2 < key);
            r.insert(pos, (key, half));
        }
        Ok(())
    }

    /// Removes path `id` from the surface (chords, nodes, rotations) but keeps its record, and
    /// returns the sectors it occupied at its two ends (between its rotation neighbours).
    fn lift(&mut self, id: u32) -> (Option<Sector>, Option<Sector>) {
        let p = self.paths[id as usize].clone();
        let k = p.nodes.len();
        for w in p.nodes.windows(2) {
            if let Some((f, pa, pb)) = self.arc_face(w[0], w[1]) {
                let c = (pa.min(pb), pa.max(pb));
                let ch = &mut self.chords[f.idx()];
                if let Some(i) = ch.iter().position(|&x| x == c) {
                    ch.swap_remove(i);
                }
            }
        }
        for n in &p.nodes[1..k - 1] {
            self.used[n.0 as usize] = false;
        }
        let mut sectors = [None, None];
        for (i, (anchor, half)) in [(p.a, 2 * id), (p.b, 2 * id + 1)].into_iter().enumerate() {
            let r = &mut self.rot[anchor as usize];
            if let Some(pos) = r.iter().position(|&(_, h)| h == half) {
                r.remove(pos);
            }
            sectors[i] = self.sector_around_removed(anchor, &p, i);
        }
        (sectors[0], sectors[1])
    }

    /// After a lift: the sector at the `i`-th end of `p` between the remaining paths around the
    /// ring key where `p` left.
    fn sector_around_removed(&self, anchor: u32, p: &LayoutPath, i: usize) -> Option<Sector> {
        let r = &self.rot[anchor as usize];
        if r.is_empty() {
            return None;
        }
        let first = if i == 0 { p.nodes[1] } else { p.nodes[p.nodes.len() - 2] };
        let key = self.graph.ring_key(self.anchors[anchor as usize], first)?;
        let pos = r.partition_point(|&(k2, _)| k2 < key);
        let n = r.len();
        Some(Sector { from: r[(pos + n - 1) % n].0, to: r[pos % n].0 })
    }

    /// Deletes path `id`; the last path takes its index.
    pub fn remove(&mut self, id: u32) {
        debug_assert!(!self.is_fixed(id), "fixed paths are never removed");
        let _ = self.lift(id);
        let last = self.paths.len() as u32 - 1;
        if id != last {
            for r in &mut self.rot {
                for (_, h) in r.iter_mut() {
                    if *h / 2 == last {
                        *h = 2 * id + *h % 2;
                    }
                }
            }
        }
        self.paths.swap_remove(id as usize);
    }

    /// Re-traces path `id` as the shortest path in the same sectors at both ends (so within the
    /// two regions beside it); keeps the old path when no shorter one is found.
    ///
    /// # Errors
    /// `Error::Internal` if the old path cannot be put back.
    pub fn retrace(&mut self, id: u32) -> Result<bool> {
        if self.is_fixed(id) {
            return Ok(false);
        }
        let old = self.paths[id as usize].clone();
        let (sector_a, sector_b) = self.lift(id);
        let req = TraceRequest { a: old.a, b: old.b, sector_a, sector_b, ..Default::default() };
        let new = self.trace_once(&req, false)?;
        match new {
            Some(p) if p.length < old.length * (1.0 - 1e-9) => {
                self.place(id, &p)?;
                self.paths[id as usize] = p;
                Ok(true)
            }
            _ => {
                self.place(id, &old)?;
                Ok(false)
            }
        }
    }

    /// Replaces path `id` by a path from anchor `a` to `b` leaving and entering in the given
    /// sectors (a flip). Returns the old path, or `None` (and keeps it) when no path is found.
    ///
    /// # Errors
    /// `Error::Internal` if a path cannot be placed.
    pub fn replace(
        &mut self,
        id: u32,
        a: u32,
        b: u32,
        sector_a: Sector,
        sector_b: Sector,
    ) -> Result<Option<LayoutPath>> {
        if self.is_fixed(id) {
            return Ok(None);
        }
        let old = self.paths[id as usize].clone();
        let _ = self.lift(id);
        let req = TraceRequest { a, b, sector_a: Some(sector_a), sector_b: Some(sector_b), ..Default::default() };
        match self.trace(&req)? {
            Some(p) => {
                self.place(id, &p)?;
                self.paths[id as usize] = p;
                Ok(Some(old))
            }
            None => {
                self.place(id, &old)?;
                Ok(None)
            }
        }
    }

    /// Puts `old` back as path `id` (undoing [`Tracer::replace`]).
    ///
    /// # Errors
    /// `Error::Internal` if the path cannot be placed.
    pub fn restore(&mut self, id: u32, old: LayoutPath) -> Result<()> {
        let _ = self.lift(id);
        self.place(id, &old)?;
        self.paths[id as usize] = old;
        Ok(())
    }

    /// The face an arc crosses and the cyclic positions of its ends, or `None` for an arc along
    /// an edge.
    pub fn arc_face(&self, u: NodeId, w: NodeId) -> Option<(FaceId, u32, u32)> {
        let m = self.graph.mesh();
        let faces_of = |n: NodeId| -> Vec<FaceId> {
            match self.graph.as_edge_node(n) {
                None => m.vertex_faces(VertexId(n.0)).collect(),
                Some((e, _)) => {
                    let (f, g) = m.edge_faces(e);
                    std::iter::once(f).chain(g).collect()
                }
            }
        };
        let on_edge = |a: NodeId, b: NodeId| match (self.graph.as_edge_node(a), self.graph.as_edge_node(b)) {
            (Some((e1, _)), Some((e2, _))) => e1 == e2,
            (None, Some((e, _))) | (Some((e, _)), None) => {
                let v = if self.graph.as_vertex(a).is_some() { a } else { b };
                m.edge_vertices(e).contains(&VertexId(v.0))
            }
            (None, None) => true,
        };
        if on_edge(u, w) {
            return None;
        }
        for f in faces_of(u) {
            if let (Some(pa), Some(pb)) = (self.graph.face_position(f, u), self.graph.face_position(f, w)) {
                return Some((f, pa, pb));
            }
        }
        None
    }

    /// Renumbers the paths: the path inserted `k`-th becomes path `new_id[k]`.
    ///
    /// # Errors
    /// `Error::Internal` unless `new_id` is a permutation of the path indices.
    pub fn renumber(&mut self, new_id: &[u32]) -> Result<()> {
        let n = self.paths.len();
        let mut seen = vec![false; n];
        if new_id.len() != n
            || new_id.iter().any(|&i| (i as usize) >= n || std::mem::replace(&mut seen[i as usize], true))
        {
            return Err(Error::Internal("path renumbering is not a permutation".into()));
        }
        let mut paths: Vec<Option<LayoutPath>> = (0..n).map(|_| None).collect();
        for (k, p) in std::mem::take(&mut self.paths).into_iter().enumerate() {
            paths[new_id[k] as usize] = Some(p);
        }
        self.paths = paths.into_iter().flatten().collect();
        for r in &mut self.rot {
            for (_, h) in r.iter_mut() {
                *h = 2 * new_id[(*h / 2) as usize] + *h % 2;
            }
        }
        Ok(())
    }

    /// The present half at anchor `a` after which (counter-clockwise) a path leaving through
    /// ring node `first` would sit, or `None` when `a` has no paths.
    pub fn sector_for_new(&self, a: u32, first: &NodeId) -> Option<Half> {
        let r = &self.rot[a as usize];
        if r.is_empty() {
            return None;
        }
        let key = self.graph.ring_key(self.anchors[a as usize], *first)?;
        let pos = r.partition_point(|&(k, _)| k < key);
        Some(r[(pos + r.len() - 1) % r.len()].1)
    }

    /// The key of half `h` in the rotation at the anchor it leaves.
    pub fn half_key(&self, h: Half) -> u32 {
        let a = self.half_start(h);
        self.rot[a as usize].iter().find(|&&(_, x)| x == h).map_or(0, |&(k, _)| k)
    }
    /// Anchor a half leaves.
    pub fn half_start(&self, h: Half) -> u32 {
        let p = &self.paths[(h / 2) as usize];
        if h.is_multiple_of(2) { p.a } else { p.b }
    }
    /// Anchor a half reaches.
    pub fn half_end(&self, h: Half) -> u32 {
        self.half_start(h ^ 1)
    }

    /// The sector of anchor `a` in which a new path must leave so that, among the paths present
    /// at `a`, it sits right after the half `after` (counter-clockwise). `None` (any direction)
    /// when `a` has no paths.
    pub fn sector_after(&self, a: u32, after: Option<Half>) -> Option<Sector> {
        let r = &self.rot[a as usize];
        if r.is_empty() {
            return None;
        }
        let i = after.and_then(|h| r.iter().position(|&(_, x)| x == h)).unwrap_or(0);
        let (k1, _) = r[i];
        let (k2, _) = r[(i + 1) % r.len()];
        Some(Sector { from: k1, to: k2 })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chord_crossing_is_interleaving() {
        assert!(crosses((1, 5), (3, 7)));
        assert!(crosses((3, 7), (1, 5)));
        assert!(!crosses((1, 5), (2, 4)));
        assert!(!crosses((1, 5), (6, 9)));
        assert!(!crosses((1, 5), (5, 9)), "shared end");
    }
}
