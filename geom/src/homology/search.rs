//! The two searches of the canonical basis: the shortest simple non-separating loop through a
//! corner of the current cut surface, and the shortest path that joins two sides of a cut loop.
//! Both stay off the surface's boundary (the loops already cut) except at the corner, so the
//! loops they produce meet only at the base vertex.

use super::cocycle::z2_cohomology;
use crate::error::Result;
use crate::mesh::cut::{CutMesh, cut_along, edge_between, path_edges};
use crate::mesh::{EdgeId, Mesh, VertexId};
use crate::topology::boundary_loops;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

#[derive(PartialEq)]
struct Item(f64, u32);
impl Eq for Item {}
impl PartialOrd for Item {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Item {
    fn cmp(&self, o: &Self) -> Ordering {
        o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
    }
}

/// Cost factor for stepping onto a vertex next to the boundary (other than the corner): paths
/// keep a vertex of clearance from the loops already cut where they can, which leaves room for
/// the paths that must cross or follow them later.
const CLEARANCE: f64 = 3.0;

/// Classes tried beyond the number of loops asked for.
const MAX_EXTRA_CLASSES: usize = 3;

/// Whether paths must keep off `v`: a boundary vertex, or one `blocked` lists (per vertex of
/// `mesh`; feature curves the basis must not touch, see [`super::basis::canonical_basis_avoiding`]).
/// An empty `blocked` blocks nothing.
pub(super) fn wall(mesh: &Mesh, blocked: &[bool], v: VertexId) -> bool {
    mesh.is_boundary_vertex(v) || blocked.get(v.idx()).copied().unwrap_or(false)
}

/// Free vertices with a wall neighbour other than `except`.
fn near_boundary(mesh: &Mesh, blocked: &[bool], except: &[VertexId]) -> Vec<bool> {
    (0..mesh.n_vertices())
        .map(|v| {
            let v = VertexId::from_idx(v);
            !wall(mesh, blocked, v) && mesh.vertex_neighbors(v).any(|w| wall(mesh, blocked, w) && !except.contains(&w))
        })
        .collect()
}

/// Shortest-path tree over the vertices `allowed` admits, from `sources`.
pub(super) struct Tree {
    dist: Vec<f64>,
    pred: Vec<u32>,
}

/// `first` filters the steps out of the sources.
pub(super) fn dijkstra(
    mesh: &Mesh,
    sources: &[VertexId],
    allowed: &dyn Fn(VertexId) -> bool,
    first: &dyn Fn(VertexId) -> bool,
    stop: &dyn Fn(VertexId) -> bool,
    weight: &dyn Fn(VertexId) -> f64,
) -> (Tree, Option<VertexId>) {
    let n = mesh.n_vertices();
    let mut dist = vec![f64::INFINITY; n];
    let mut pred = vec![u32::MAX; n];
    let mut done = vec![false; n];
    let mut heap = BinaryHeap::new();
    for &s in sources {
        dist[s.idx()] = 0.0;
        heap.push(Item(0.0, s.0));
    }
    while let Some(Item(d, v)) = heap.pop() {
        let v = VertexId(v);
        if done[v.idx()] {
            continue;
        }
        done[v.idx()] = true;
        if stop(v) {
            return (Tree { dist, pred }, Some(v));
        }
        // Do not pass through a stop vertex or leave one (only sources may be left).
        let pv = mesh.position(v);
        let from_source = pred[v.idx()] == u32::MAX;
        for w in mesh.vertex_neighbors(v) {
            if done[w.idx()] || !allowed(w) || (from_source && !first(w)) {
                continue;
            }
            let nd = d + (mesh.position(w) - pv).norm() * weight(w);
            if nd < dist[w.idx()] {
                dist[w.idx()] = nd;
                pred[w.idx()] = v.0;
                heap.push(Item(nd, w.0));
            }
        }
    }
    (Tree { dist, pred }, None)
}

pub(super) fn path_to(t: &Tree, v: VertexId) -> Vec<VertexId> {
    let mut p = vec![v];
    let mut c = v;
    while t.pred[c.idx()] != u32::MAX {
        c = VertexId(t.pred[c.idx()]);
        p.push(c);
    }
    p.reverse();
    p
}

/// Simple non-separating loops through `corner` (a vertex of `mesh`, interior or on its one
/// boundary loop) avoiding the boundary elsewhere, one per Z2 homology class, classes ordered
/// by their shortest (tree) loop, at most `count`. Each is a vertex list from `corner` back to
/// `corner`. Vertices `blocked` lists (per vertex of `mesh`) are walls like the boundary.
///
/// A shortest loop through a vertex far from its handle is a lasso: a stem walked out and back
/// plus a cycle. Such a loop cannot be cut as an edge path, so the stem is slit open first and
/// the loop is searched on the slit surface, where its two halves run along the two sides of
/// the slit (the covering-space paths of the paper, kept apart).
///
/// # Errors
/// `Internal` from the cohomology construction.
pub fn nonseparating_loops(
    mesh: &Mesh,
    blocked: &[bool],
    corner: VertexId,
    count: usize,
) -> Result<Vec<Vec<VertexId>>> {
    let mut out = Vec::new();
    each_nonseparating_loop(mesh, blocked, corner, count, &mut |lp| {
        out.push(lp);
        Ok(false)
    })?;
    Ok(out)
}

/// [`nonseparating_loops`] handed to `take` one at a time, in order, until it returns `true`:
/// a caller that accepts the first loop does not pay for the later ones (each may cost a slit
/// surface and a two-branch search). Returns how many were handed over.
///
/// # Errors
/// As [`nonseparating_loops`], and whatever `take` returns.
pub fn each_nonseparating_loop(
    mesh: &Mesh,
    blocked: &[bool],
    corner: VertexId,
    count: usize,
    take: &mut dyn FnMut(Vec<VertexId>) -> Result<bool>,
) -> Result<usize> {
    let allowed = |v: VertexId| v == corner || !wall(mesh, blocked, v);
    // At a boundary corner, keep the neighbours next to the boundary edges free of first
    // steps, so that the crossing path has a side to arrive on.
    let fan: Vec<VertexId> = mesh.vertex_neighbors(corner).collect();
    let hugging: Vec<VertexId> =
        if mesh.is_boundary_vertex(corner) && fan.len() >= 4 { vec![fan[1], fan[fan.len() - 2]] } else { Vec::new() };
    let first_ok = |w: VertexId| !hugging.contains(&w);
    let near = near_boundary(mesh, blocked, &[corner]);
    // At a boundary corner, leaving near the middle of its fan keeps the outer sectors wide:
    // they become the corners of the next handles.
    let mut fan_cost = vec![1.0; mesh.n_vertices()];
    if mesh.is_boundary_vertex(corner) && fan.len() >= 3 {
        let half = (fan.len() - 1) as f64 / 2.0;
        for (i, w) in fan.iter().enumerate() {
            let q = (i.min(fan.len() - 1 - i) as f64 / half).min(1.0);
            fan_cost[w.idx()] = 1.0 + 4.0 * (1.0 - q) * (1.0 - q);
        }
    }
    let weight = |w: VertexId| if near[w.idx()] { CLEARANCE * fan_cost[w.idx()] } else { 1.0 };
    let (tree, _) = dijkstra(mesh, &[corner], &allowed, &first_ok, &|_| false, &weight);
    let n = mesh.n_vertices();
    let mut tree_edges: Vec<EdgeId> = Vec::with_capacity(n + 16);
    let mut is_tree = vec![false; mesh.n_edges()];
    for v in 0..n {
        if tree.pred[v] != u32::MAX
            && let Some(e) = edge_between(mesh, VertexId(tree.pred[v]), VertexId::from_idx(v))
        {
            tree_edges.push(e);
            is_tree[e.idx()] = true;
        }
    }
    // The boundary loop, as a path from the corner (all but its closing edge).
    for lp in boundary_loops(mesh) {
        if let Some(i) = lp.iter().position(|&h| mesh.tail(h) == corner) {
            let m = lp.len();
            for k in 0..m - 1 {
                tree_edges.push(mesh.edge(lp[(i + k) % m]));
            }
        }
    }
    let coh = z2_cohomology(mesh, &tree_edges)?;
    // Classes by their shortest tree loop (possibly a lasso).
    let mut lassos: Vec<(f64, EdgeId)> = Vec::new();
    for e in 0..mesh.n_edges() {
        let e = EdgeId::from_idx(e);
        let [x, y] = mesh.edge_vertices(e);
        if coh.mask[e.idx()] == 0 || is_tree[e.idx()] || !allowed(x) || !allowed(y) {
            continue;
        }
        let (dx, dy) = (tree.dist[x.idx()], tree.dist[y.idx()]);
        if dx.is_finite() && dy.is_finite() {
            lassos.push((dx + dy + mesh.edge_length(e), e));
        }
    }
    lassos.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let mut seen = std::collections::HashSet::new();
    let mut out = 0;
    for (_, e) in lassos {
        // Classes beyond the shortest few are long detours; trying them all costs a slit and a
        // search each on a failing corner.
        if out >= count || seen.len() >= count + MAX_EXTRA_CLASSES {
            break;
        }
        let want = coh.mask[e.idx()];
        if !seen.insert(want) {
            continue;
        }
        let [x, y] = mesh.edge_vertices(e);
        let (px, py) = (path_to(&tree, x), path_to(&tree, y));
        let stem_len = px.iter().zip(&py).take_while(|(a, b)| a == b).count();
        if stem_len < 2 {
            // Tree paths from different first edges: already a simple loop.
            let mut lp = px.clone();
            lp.extend(py.iter().rev());
            if room_at_corner(mesh, blocked, corner, &lp) {
                out += 1;
                if take(lp)? {
                    return Ok(out);
                }
                continue;
            }
        }
        if stem_len >= 2 {
            let rb = return_beside(mesh, blocked, corner, &px, y, &coh.mask, want, &weight);
            if let Some(lp) = rb
                && room_at_corner(mesh, blocked, corner, &lp)
            {
                out += 1;
                if take(lp)? {
                    return Ok(out);
                }
                continue;
            }
        }
        let slit = if stem_len >= 2 {
            cut_along(mesh, &path_edges(mesh, &[px[..stem_len].to_vec()])?)?
        } else {
            CutMesh { mesh: mesh.clone(), orig: (0..n).map(VertexId::from_idx).collect() }
        };
        // Cutting keeps faces and corners, so half-edge h of the slit mesh is half-edge h here.
        let mut emask = vec![0u64; slit.mesh.n_edges()];
        for h in 0..slit.mesh.n_halfedges() {
            let h = crate::mesh::HalfedgeId::from_idx(h);
            emask[slit.mesh.edge(h).idx()] = coh.mask[mesh.edge(h).idx()];
        }
        let corners: Vec<VertexId> =
            (0..slit.mesh.n_vertices()).map(VertexId::from_idx).filter(|v| slit.orig[v.idx()] == corner).collect();
        let room = |lp: &[VertexId]| room_at_corner(mesh, blocked, corner, lp);
        let weight_slit = |w: VertexId| weight(slit.orig[w.idx()]);
        let blocked_slit: Vec<bool> =
            if blocked.is_empty() { Vec::new() } else { slit.orig.iter().map(|o| blocked[o.idx()]).collect() };
        let found =
            shortest_simple_loop(&slit, &blocked_slit, &corners, &emask, want, stem_len >= 2, &weight_slit, &room);
        if let Some(lp) = found {
            out += 1;
            if take(lp)? {
                return Ok(out);
            }
        }
    }
    Ok(out)
}

/// A lasso's loop made simple: out along `out` (corner to `x`), across to `y`, and back to the
/// corner by the shortest path that avoids `out` (keeping a vertex of clearance from it where it
/// can), in class `want`.
#[allow(clippy::too_many_arguments)]
fn return_beside(
    mesh: &Mesh,
    blocked: &[bool],
    corner: VertexId,
    out: &[VertexId],
    y: VertexId,
    mask: &[u64],
    want: u64,
    weight: &dyn Fn(VertexId) -> f64,
) -> Option<Vec<VertexId>> {
    let n = mesh.n_vertices();
    let mut on_out = vec![false; n];
    for v in &out[1..] {
        on_out[v.idx()] = true;
    }
    if on_out[y.idx()] || wall(mesh, blocked, y) {
        return None;
    }
    let mut beside = vec![false; n];
    for v in &out[1..] {
        for w in mesh.vertex_neighbors(*v) {
            beside[w.idx()] = true;
        }
    }
    let allowed = |v: VertexId| v == corner || (!on_out[v.idx()] && !wall(mesh, blocked, v));
    let w8 = |v: VertexId| if beside[v.idx()] && v != corner { CLEARANCE * weight(v) } else { weight(v) };
    let (tree, hit) = dijkstra(mesh, &[y], &allowed, &|_| true, &|v| v == corner, &w8);
    hit?;
    // From the source `y` to the corner.
    let back = path_to(&tree, corner);
    let mut lp = out.to_vec();
    lp.extend(back);
    let class = lp.windows(2).try_fold(0u64, |acc, w| edge_between(mesh, w[0], w[1]).map(|e| acc ^ mask[e.idx()]))?;
    (class == want).then_some(lp)
}

/// The shortest loop in class `want` on `slit` from a corner copy back to a corner copy, with
/// halves that share no vertex; returned in the uncut mesh's vertex ids.
#[allow(clippy::too_many_arguments)]
fn shortest_simple_loop(
    slit: &CutMesh,
    blocked: &[bool],
    corners: &[VertexId],
    mask: &[u64],
    want: u64,
    by_side: bool,
    weight: &dyn Fn(VertexId) -> f64,
    room: &dyn Fn(&[VertexId]) -> bool,
) -> Option<Vec<VertexId>> {
    let mesh = &slit.mesh;
    let two = two_branch_dijkstra(mesh, blocked, corners, mask, by_side, weight);
    let mut cands: Vec<(f64, u32, u32)> = Vec::new();
    for e in 0..mesh.n_edges() {
        let e = EdgeId::from_idx(e);
        let [x, y] = mesh.edge_vertices(e);
        let me = mask[e.idx()];
        for &lx in &two.of[x.idx()] {
            for &ly in &two.of[y.idx()] {
                let (a, b) = (&two.labels[lx as usize], &two.labels[ly as usize]);
                if a.branch != b.branch && a.mask ^ b.mask ^ me == want {
                    cands.push((a.dist + b.dist + mesh.edge_length(e), lx, ly));
                }
            }
        }
    }
    cands.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
    let mut mark = vec![false; mesh.n_vertices()];
    let dbg = tracing::enabled!(tracing::Level::DEBUG);
    let (mut n_touch, mut n_room) = (0, 0);
    let nc = cands.len();
    for (_, lx, ly) in cands {
        let (ha, hb) = (two.path(lx), two.path(ly));
        for v in &ha {
            mark[v.idx()] = true;
        }
        let touches = hb.iter().any(|v| mark[v.idx()]);
        for v in &ha {
            mark[v.idx()] = false;
        }
        if touches {
            n_touch += 1;
            continue;
        }
        let mut lp: Vec<VertexId> = Vec::with_capacity(ha.len() + hb.len() + 2);
        lp.push(slit.orig[two.root(lx).idx()]);
        lp.extend(ha.iter().map(|v| slit.orig[v.idx()]));
        lp.extend(hb.iter().rev().map(|v| slit.orig[v.idx()]));
        lp.push(slit.orig[two.root(ly).idx()]);
        if room(&lp) {
            return Some(lp);
        }
        n_room += 1;
    }
    if dbg {
        let both = two.of.iter().filter(|o| o.len() == 2).count();
        tracing::debug!(
            "homology basis: {nc} loop candidates, {n_touch} touching, {n_room} without room, {both} labelled twice"
        );
    }
    None
}

/// The loop's two ends at the corner leave a free neighbour (not on the loop, not on the
/// boundary) between them and, at a boundary corner, outside them on at least one side, so
/// the path that crosses the loop there can start and end.
fn room_at_corner(mesh: &Mesh, blocked: &[bool], corner: VertexId, lp: &[VertexId]) -> bool {
    let fan: Vec<VertexId> = mesh.vertex_neighbors(corner).collect();
    let l = lp.len();
    if l < 4 {
        return false;
    }
    let (Some(p), Some(q)) = (fan.iter().position(|&v| v == lp[1]), fan.iter().position(|&v| v == lp[l - 2])) else {
        return false;
    };
    let on_loop: std::collections::HashSet<VertexId> = lp.iter().copied().collect();
    let free = |i: usize| !on_loop.contains(&fan[i]) && !wall(mesh, blocked, fan[i]);
    let d = fan.len();
    if mesh.is_boundary_vertex(corner) {
        let (i, j) = (p.min(q), p.max(q));
        let s2 = (i + 1..j).any(free);
        let s13 = (0..i).any(free) || (j + 1..d).any(free);
        s2 && s13
    } else {
        let (mut a, mut b) = (false, false);
        for k in 1..d {
            let i = (p + k) % d;
            if i == q {
                break;
            }
            a |= free(i);
        }
        for k in 1..d {
            let i = (q + k) % d;
            if i == p {
                break;
            }
            b |= free(i);
        }
        a && b
    }
}

/// One label of the two-branch search: a path from a neighbour of the corner.
struct Label {
    vertex: VertexId,
    dist: f64,
    branch: u32,
    mask: u64,
    pred: u32,
}

/// Dijkstra from every neighbour of a corner at once, keeping at each vertex the best label of
/// up to two different first edges ("branches"), so that loops leaving the corner one way and
/// returning another are found even when all shortest paths start the same way.
struct TwoBranch {
    labels: Vec<Label>,
    of: Vec<Vec<u32>>,
    /// Per source label (in order): its first vertex and the corner copy it leaves.
    roots: Vec<(VertexId, VertexId)>,
}

impl TwoBranch {
    /// The corner copy a label's path leaves from.
    fn root(&self, l: u32) -> VertexId {
        let mut c = l;
        while self.labels[c as usize].pred != u32::MAX {
            c = self.labels[c as usize].pred;
        }
        self.roots[c as usize].1
    }

    /// Vertices from the corner's neighbour to the label's vertex.
    fn path(&self, l: u32) -> Vec<VertexId> {
        let mut p = Vec::new();
        let mut c = l;
        loop {
            let lab = &self.labels[c as usize];
            p.push(lab.vertex);
            if lab.pred == u32::MAX {
                break;
            }
            c = lab.pred;
        }
        p.reverse();
        p
    }
}

fn neighbors_with_edges(mesh: &Mesh, v: VertexId) -> Vec<(VertexId, EdgeId)> {
    let mut out: Vec<(VertexId, EdgeId)> = Vec::new();
    for h in mesh.outgoing(v) {
        for (w, e) in [(mesh.head(h), mesh.edge(h)), (mesh.tail(h.prev()), mesh.edge(h.prev()))] {
            if !out.iter().any(|x| x.1 == e) {
                out.push((w, e));
            }
        }
    }
    out
}

/// With `by_side`, branches are the two sides of a slit ending at the corner: the corner's two
/// copies, or the two halves of its one fan; otherwise each first edge is its own branch.
fn two_branch_dijkstra(
    mesh: &Mesh,
    blocked: &[bool],
    corners: &[VertexId],
    mask: &[u64],
    by_side: bool,
    weight: &dyn Fn(VertexId) -> f64,
) -> TwoBranch {
    let n = mesh.n_vertices();
    let allowed = |v: VertexId| !corners.contains(&v) && !wall(mesh, blocked, v);
    let mut labels: Vec<Label> = Vec::new();
    let mut of: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut heap = BinaryHeap::new();
    // Tentative labels live in `labels` too; a label is final once popped.
    let mut best: Vec<Vec<u32>> = vec![Vec::new(); n];
    let mut roots = Vec::new();
    for (ci, &corner) in corners.iter().enumerate() {
        let fan: Vec<VertexId> = mesh.vertex_neighbors(corner).collect();
        for (w, e) in neighbors_with_edges(mesh, corner) {
            if !allowed(w) {
                continue;
            }
            let d = mesh.edge_length(e);
            roots.push((w, corner));
            let branch = if !by_side {
                (roots.len() - 1) as u32
            } else if corners.len() >= 2 {
                ci as u32
            } else {
                u32::from(fan.iter().position(|&x| x == w).unwrap_or(0) >= fan.len() / 2)
            };
            labels.push(Label { vertex: w, dist: d, branch, mask: mask[e.idx()], pred: u32::MAX });
            let id = (labels.len() - 1) as u32;
            best[w.idx()].push(id);
            heap.push(Item(d, id));
        }
    }
    while let Some(Item(_, id)) = heap.pop() {
        let v = labels[id as usize].vertex;
        // Superseded by a shorter label of the same branch.
        if !best[v.idx()].contains(&id) {
            continue;
        }
        let (v, d, br, mk) = {
            let l = &labels[id as usize];
            (l.vertex, l.dist, l.branch, l.mask)
        };
        if of[v.idx()].len() >= 2 || of[v.idx()].iter().any(|&o| labels[o as usize].branch == br) {
            continue;
        }
        of[v.idx()].push(id);
        for (w, e) in neighbors_with_edges(mesh, v) {
            if !allowed(w) || of[w.idx()].len() >= 2 || of[w.idx()].iter().any(|&o| labels[o as usize].branch == br) {
                continue;
            }
            let nd = d + mesh.edge_length(e) * weight(w);
            // Keep a tentative label only if it beats the one of the same branch.
            if let Some(&t) = best[w.idx()].iter().find(|&&t| labels[t as usize].branch == br)
                && labels[t as usize].dist <= nd
            {
                continue;
            }
            labels.push(Label { vertex: w, dist: nd, branch: br, mask: mk ^ mask[e.idx()], pred: id });
            let nid = (labels.len() - 1) as u32;
            let bw = &mut best[w.idx()];
            if let Some(slot) = bw.iter_mut().find(|t| labels[**t as usize].branch == br) {
                *slot = nid;
            } else {
                bw.push(nid);
            }
            heap.push(Item(nd, nid));
        }
    }
    TwoBranch { labels, of, roots }
}

/// The shortest path from `from` to any of `to` through interior vertices only (`blocked`
/// ones excepted, as in [`nonseparating_loops`]).
///
/// `on_new(w)` tells the boundary vertices of the loop just cut: a target corner's fan runs from
/// that loop to older boundary, and arriving near the older boundary would leave a thin wedge
/// there, which later becomes the corner of the next handle; those steps cost more.
pub fn interior_path(
    mesh: &Mesh,
    blocked: &[bool],
    from: VertexId,
    to: &[VertexId],
    on_new: &dyn Fn(VertexId) -> bool,
) -> Option<Vec<VertexId>> {
    let is_target = |v: VertexId| to.contains(&v);
    let allowed = |v: VertexId| is_target(v) || !wall(mesh, blocked, v);
    let mut ends = to.to_vec();
    ends.push(from);
    let near = near_boundary(mesh, blocked, &ends);
    let mut fan_cost = vec![1.0; mesh.n_vertices()];
    for &c in to {
        let fan: Vec<VertexId> = mesh.vertex_neighbors(c).collect();
        let d = fan.len();
        if d < 3 {
            continue;
        }
        // Which end of the fan is the new loop; the other end is older boundary.
        let (first_new, last_new) = (on_new(fan[0]), on_new(fan[d - 1]));
        if first_new == last_new {
            continue;
        }
        for (i, w) in fan.iter().enumerate() {
            let from_old = if first_new { d - 1 - i } else { i } as f64 / (d - 1) as f64;
            fan_cost[w.idx()] = 1.0 + 4.0 * (1.0 - from_old) * (1.0 - from_old);
        }
    }
    let weight = |w: VertexId| if near[w.idx()] { CLEARANCE * fan_cost[w.idx()] } else { 1.0 };
    let (tree, hit) = dijkstra(mesh, &[from], &allowed, &|_| true, &is_target, &weight);
    let hit = hit?;
    let p = path_to(&tree, hit);
    // A direct edge between two boundary copies would run along no interior: refuse.
    (p.len() >= 3).then_some(p)
}
