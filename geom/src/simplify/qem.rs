//! Quadric-error half-edge-collapse decimation (Garland & Heckbert 1997, with the half-edge
//! collapse of Hoppe's progressive meshes: the surviving vertex keeps its position, so every
//! vertex of the result is a vertex of the input).
//!
//! Each vertex carries the area-weighted sum of its face-plane quadrics; boundary edges add a
//! heavy quadric of the plane through the edge perpendicular to its face, so outlines stay put.
//! A collapse `u -> v` costs `(Q_u + Q_v)(p_v)` and is legal when
//! - `u` is not protected, and a boundary `u` only slides along a boundary edge to `v`;
//! - the link condition holds (the common neighbours of `u` and `v` are exactly the apexes of
//!   the faces on edge `uv`), so the topology (genus, boundary loops) never changes;
//! - no face around `u` turns over or degenerates (its normal keeps within 90° - ε of before).
//!
//! Candidates live in a binary heap with lazy invalidation: one entry per vertex (its cheapest
//! outgoing collapse), tagged with a per-vertex stamp that every change of its star bumps.

use crate::mesh::{Mesh, P3, V3, VertexId};
use crate::{Error, InputError, Result};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Options of [`decimate`].
#[derive(Debug, Clone)]
pub struct DecimateOptions {
    /// Stop when this many vertices remain (or no legal collapse is left).
    pub target_vertices: usize,
    /// Vertices that must survive (anchors, patch corners, feature points).
    pub protected: Vec<VertexId>,
    /// Weight of the boundary-plane quadrics relative to face quadrics.
    pub boundary_weight: f64,
    /// Smallest cosine between a face normal before and after a collapse.
    pub min_normal_cos: f64,
    /// Refuse collapses that would create an edge between two held vertices (boundary or
    /// protected) that the input does not have: with the boundary fixed on a convex polygon a
    /// chord can lie along a side, and its faces would be degenerate in the plane; an edge
    /// from a held feature to another held vertex leaves no free vertex between them, so
    /// moving the feature (`quad`'s alignment) could not go around the other one.
    pub no_chords: bool,
}

impl Default for DecimateOptions {
    fn default() -> Self {
        Self {
            target_vertices: 0,
            protected: Vec::new(),
            boundary_weight: 100.0,
            min_normal_cos: 0.2,
            no_chords: false,
        }
    }
}

/// One half-edge collapse: `from` disappears into `to` (both indices of the input mesh).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Collapse {
    pub from: VertexId,
    pub to: VertexId,
}

/// Output of [`decimate`].
#[derive(Debug, Clone)]
pub struct DecimateResult {
    /// The simplified mesh.
    pub mesh: Mesh,
    /// For each vertex of `mesh`, its vertex in the input (positions are identical).
    pub kept: Vec<VertexId>,
    /// The collapses in the order they were made (a progressive mesh read backwards).
    pub collapses: Vec<Collapse>,
    /// Everything needed to undo the collapses one by one (vertex splits).
    pub history: CollapseHistory,
}

/// The face soup of the decimation in input vertex ids, and per collapse the faces it deleted
/// and the faces it rewrote (`from` replaced by `to`). Undoing collapses in reverse order
/// (revive the deleted faces, put `from` back into the rewritten ones) replays the
/// progressive mesh from the base mesh up to the input.
#[derive(Debug, Clone, Default)]
pub struct CollapseHistory {
    /// Every input face, as it stands after the last collapse (dead faces as they were when
    /// they died).
    pub faces: Vec<[u32; 3]>,
    /// Whether each face is in the base mesh.
    pub alive: Vec<bool>,
    /// Per collapse (same order as `collapses`): deleted face ids.
    pub deleted: Vec<Vec<u32>>,
    /// Per collapse: rewritten face ids.
    pub rewritten: Vec<Vec<u32>>,
}

/// Symmetric 4x4 quadric, upper triangle row by row.
#[derive(Debug, Clone, Copy, Default)]
struct Quadric([f64; 10]);

impl Quadric {
    fn plane(n: V3, p: P3, w: f64) -> Self {
        let d = -n.dot(&p.coords);
        let (a, b, c) = (n.x, n.y, n.z);
        Quadric([a * a, a * b, a * c, a * d, b * b, b * c, b * d, c * c, c * d, d * d].map(|x| x * w))
    }
    fn add(&mut self, o: &Quadric) {
        for (a, b) in self.0.iter_mut().zip(o.0) {
            *a += b;
        }
    }
    fn eval(&self, q: &Quadric, p: P3) -> f64 {
        let m: [f64; 10] = std::array::from_fn(|i| self.0[i] + q.0[i]);
        let (x, y, z) = (p.x, p.y, p.z);
        m[0] * x * x
            + 2.0 * m[1] * x * y
            + 2.0 * m[2] * x * z
            + 2.0 * m[3] * x
            + m[4] * y * y
            + 2.0 * m[5] * y * z
            + 2.0 * m[6] * y
            + m[7] * z * z
            + 2.0 * m[8] * z
            + m[9]
    }
}

#[derive(Debug, PartialEq)]
struct Candidate {
    cost: f64,
    from: u32,
    to: u32,
    stamp: u32,
}
impl Eq for Candidate {}
impl Ord for Candidate {
    fn cmp(&self, o: &Self) -> Ordering {
        o.cost.total_cmp(&self.cost).then_with(|| o.from.cmp(&self.from))
    }
}
impl PartialOrd for Candidate {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}

/// Mutable face soup with vertex -> face incidence, the working state of the decimation.
struct Work<'a> {
    pos: &'a [P3],
    faces: Vec<[u32; 3]>,
    alive: Vec<bool>,
    vf: Vec<Vec<u32>>,
    boundary: Vec<bool>,
    protected: Vec<bool>,
    q: Vec<Quadric>,
    stamp: Vec<u32>,
    min_cos: f64,
    no_chords: bool,
}

impl Work<'_> {
    fn neighbors(&self, v: u32, out: &mut Vec<u32>) {
        out.clear();
        for &f in &self.vf[v as usize] {
            for w in self.faces[f as usize] {
                if w != v && !out.contains(&w) {
                    out.push(w);
                }
            }
        }
    }

    /// Faces containing both `a` and `b`.
    fn edge_faces(&self, a: u32, b: u32) -> impl Iterator<Item = u32> + '_ {
        self.vf[a as usize].iter().copied().filter(move |&f| self.faces[f as usize].contains(&b))
    }

    fn is_boundary_edge(&self, a: u32, b: u32) -> bool {
        self.edge_faces(a, b).count() == 1
    }

    fn normal(&self, t: [u32; 3]) -> V3 {
        let [a, b, c] = t.map(|i| self.pos[i as usize]);
        (b - a).cross(&(c - a))
    }

    fn legal(&self, u: u32, v: u32, nu: &[u32], nv: &[u32]) -> bool {
        if self.protected[u as usize] {
            return false;
        }
        let on_edge: Vec<u32> = self
            .edge_faces(u, v)
            .map(|f| self.faces[f as usize].into_iter().find(|&w| w != u && w != v).unwrap_or(u))
            .collect();
        if on_edge.is_empty() {
            return false;
        }
        if self.boundary[u as usize] && !(on_edge.len() == 1 && self.is_boundary_edge(u, v)) {
            return false;
        }
        let held = |x: u32| self.boundary[x as usize] || self.protected[x as usize];
        if self.no_chords && held(v) && nu.iter().any(|&w| w != v && held(w) && !on_edge.contains(&w)) {
            return false;
        }
        // Link condition.
        let common = nu.iter().filter(|w| nv.contains(w)).count();
        if common != on_edge.len() || nu.iter().filter(|w| on_edge.contains(w)).count() != on_edge.len() {
            return false;
        }
        // Two valence-3 vertices on an edge: a tetrahedral component, whose collapse would leave
        // two coincident faces.
        if nu.len() == 3 && nv.len() == 3 {
            return false;
        }
        for &f in &self.vf[u as usize] {
            let t = self.faces[f as usize];
            if t.contains(&v) {
                continue;
            }
            let before = self.normal(t);
            let after = self.normal(t.map(|w| if w == u { v } else { w }));
            let (lb, la) = (before.norm(), after.norm());
            if la <= 1e-12 * lb.max(f64::MIN_POSITIVE) || before.dot(&after) < self.min_cos * lb * la {
                return false;
            }
        }
        true
    }

    fn best(&self, u: u32, nu: &mut Vec<u32>, nv: &mut Vec<u32>) -> Option<Candidate> {
        self.neighbors(u, nu);
        let cand: Vec<u32> = nu.clone();
        let mut best: Option<Candidate> = None;
        for v in cand {
            let cost = self.q[u as usize].eval(&self.q[v as usize], self.pos[v as usize]);
            if best.as_ref().is_some_and(|b| b.cost <= cost) {
                continue;
            }
            self.neighbors(v, nv);
            if self.legal(u, v, nu, nv) {
                best = Some(Candidate { cost, from: u, to: v, stamp: self.stamp[u as usize] });
            }
        }
        best
    }

    /// Collapses `u` into `v`; returns the deleted and the rewritten faces.
    fn collapse(&mut self, u: u32, v: u32) -> (Vec<u32>, Vec<u32>) {
        let fu = std::mem::take(&mut self.vf[u as usize]);
        let (mut deleted, mut rewritten) = (Vec::with_capacity(2), Vec::with_capacity(fu.len()));
        for f in fu {
            let t = &mut self.faces[f as usize];
            if t.contains(&v) {
                self.alive[f as usize] = false;
                deleted.push(f);
                for w in *t {
                    if w != u {
                        self.vf[w as usize].retain(|&g| g != f);
                    }
                }
            } else {
                for w in t.iter_mut() {
                    if *w == u {
                        *w = v;
                    }
                }
                self.vf[v as usize].push(f);
                rewritten.push(f);
            }
        }
        let qu = self.q[u as usize];
        self.q[v as usize].add(&qu);
        (deleted, rewritten)
    }
}

/// Simplifies `mesh` by quadric-error half-edge collapses down to `opts.target_vertices`.
///
/// # Errors
/// `InputError::OutOfRange` for a protected vertex outside the mesh; `Internal` if the result
/// fails validation (a bug: collapses preserve manifoldness).
pub fn decimate(mesh: &Mesh, opts: &DecimateOptions) -> Result<DecimateResult> {
    let nv = mesh.n_vertices();
    let mut protected = vec![false; nv];
    for &p in &opts.protected {
        if p.idx() >= nv {
            return Err(InputError::OutOfRange { what: "protected vertex", index: p.idx(), count: nv }.into());
        }
        protected[p.idx()] = true;
    }
    let faces = mesh.face_indices();
    let mut vf = vec![Vec::with_capacity(6); nv];
    for (f, t) in faces.iter().enumerate() {
        for &v in t {
            vf[v as usize].push(f as u32);
        }
    }
    let pos = mesh.positions();
    let mut q = vec![Quadric::default(); nv];
    for t in &faces {
        let [a, b, c] = t.map(|i| pos[i as usize]);
        let n = (b - a).cross(&(c - a));
        let area2 = n.norm();
        if area2 <= 0.0 {
            continue;
        }
        let plane = Quadric::plane(n / area2, a, area2 / 2.0);
        for &v in t {
            q[v as usize].add(&plane);
        }
    }
    let boundary: Vec<bool> = (0..nv).map(|v| mesh.is_boundary_vertex(VertexId::from_idx(v))).collect();
    for h in (0..mesh.n_halfedges()).map(crate::HalfedgeId::from_idx) {
        if !mesh.is_boundary_halfedge(h) {
            continue;
        }
        let (a, b) = (mesh.tail(h), mesh.head(h));
        let fnorm = mesh.face_normal_raw(h.face());
        let e = mesh.position(b) - mesh.position(a);
        let n = e.cross(&fnorm);
        let l = n.norm();
        if l <= 0.0 {
            continue;
        }
        let plane = Quadric::plane(n / l, mesh.position(a), opts.boundary_weight * e.norm_squared());
        q[a.idx()].add(&plane);
        q[b.idx()].add(&plane);
    }
    let mut w = Work {
        pos,
        alive: vec![true; faces.len()],
        faces,
        vf,
        boundary,
        protected,
        q,
        stamp: vec![0; nv],
        min_cos: opts.min_normal_cos,
        no_chords: opts.no_chords,
    };
    let (mut nu, mut nvb, mut ring) = (Vec::new(), Vec::new(), Vec::new());
    let mut heap = BinaryHeap::with_capacity(nv);
    for u in 0..nv as u32 {
        if let Some(c) = w.best(u, &mut nu, &mut nvb) {
            heap.push(c);
        }
    }
    let mut remaining = nv;
    let mut collapses = Vec::new();
    let (mut deleted, mut rewritten) = (Vec::new(), Vec::new());
    let mut removed = vec![false; nv];
    while remaining > opts.target_vertices.max(4) {
        let Some(c) = heap.pop() else { break };
        if removed[c.from as usize] || c.stamp != w.stamp[c.from as usize] {
            continue;
        }
        if removed[c.to as usize] || {
            w.neighbors(c.from, &mut nu);
            w.neighbors(c.to, &mut nvb);
            !w.legal(c.from, c.to, &nu, &nvb)
        } {
            if let Some(n) = w.best(c.from, &mut nu, &mut nvb) {
                heap.push(n);
            }
            continue;
        }
        let (del, rew) = w.collapse(c.from, c.to);
        deleted.push(del);
        rewritten.push(rew);
        removed[c.from as usize] = true;
        remaining -= 1;
        collapses.push(Collapse { from: VertexId::from_idx(c.from as usize), to: VertexId::from_idx(c.to as usize) });
        w.neighbors(c.to, &mut ring);
        ring.push(c.to);
        for &x in &ring {
            w.stamp[x as usize] += 1;
        }
        for &x in &ring {
            if let Some(n) = w.best(x, &mut nu, &mut nvb) {
                heap.push(n);
            }
        }
    }
    let mut new_id = vec![u32::MAX; nv];
    let kept: Vec<VertexId> = (0..nv).filter(|&v| !removed[v]).map(VertexId::from_idx).collect();
    for (i, v) in kept.iter().enumerate() {
        new_id[v.idx()] = i as u32;
    }
    let tris: Vec<[u32; 3]> =
        w.faces.iter().zip(&w.alive).filter(|(_, a)| **a).map(|(t, _)| t.map(|v| new_id[v as usize])).collect();
    let out = Mesh::from_triangles(kept.iter().map(|&v| pos[v.idx()]).collect(), &tris)
        .map_err(|e| Error::Internal(format!("decimation broke the mesh: {e}")))?;
    let history = CollapseHistory { faces: w.faces, alive: w.alive, deleted, rewritten };
    Ok(DecimateResult { mesh: out, kept, collapses, history })
}
