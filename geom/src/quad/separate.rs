//! A partition loop that separates the features by construction, for when re-tracing one curve
//! at a time ([`super::sides`]) cannot bring every feature to its side.
//!
//! - The features of each side are joined into a tree of shortest paths, `TL` (patch 0, left of
//!   the loop) and `TR` (patch 1), kept a one-ring apart from each other and from the partition
//!   points. A side without features gets one stand-in vertex, the one farthest from the rest.
//! - A seam `γ` runs from `TL` to `TR` through face interiors (a shortest dual path).
//! - The loop p0 -> p1 -> p2 -> p3 -> p0 is traced around both trees and off the features'
//!   one-rings, with exactly one net crossing of `γ`, carried by one of its four curves; the
//!   others do not touch the seam. A closed curve that misses both trees and crosses an arc
//!   joining them an odd number of times separates them (Jordan), and the crossing's sign says
//!   which tree is on its left.
//! - With a guide (the shortest loop, which puts some feature on its wrong side) the trees pay
//!   to cross it and the loop is drawn to it, so the result departs from it only where a
//!   feature has to change sides.
//! - The crossing count is the layer of a two-layer lift of the vertex graph (the covering-space
//!   construction of homotopy-constrained shortest paths, as in Erickson & Whittlesey's
//!   "Greedy optimal homotopy and homology generators" and the `voronoi` corridors).
//!
//! Every (crossing curve, sign, traced first or last) choice is tried; the shortest loop that
//! puts each feature on its side wins.

use super::sides::{feature_rings, left_faces, vertex_left, with_one_ring as ring};
use crate::error::Result;
use crate::geodesic::{MinHeap, vertex_dijkstra};
use crate::mesh::{FaceId, HalfedgeId, Mesh, VertexId};

/// Per edge, the seam's crossing: `Some((tail, head))` of the crossed edge's half-edge on the
/// `TL` side of `γ` (traversing the edge tail -> head counts +1).
type Seam = Vec<Option<(VertexId, VertexId)>>;

/// The loop with every feature `features[k]` in patch `want[k]`, or `None` on this mesh.
/// `guide`, the shortest loop (which puts some features on the wrong side), shapes the result:
/// the trees pay to cross it, so they cross it only to reach a feature on its wrong side, and
/// the new loop is drawn to it, so it departs from it only to go around such a crossing.
///
/// # Errors
/// Only mask-size errors of the shortest-path searches (internal).
pub fn separating_loop(
    mesh: &Mesh,
    points: [VertexId; 4],
    features: &[VertexId],
    want: &[usize],
    guide: Option<&[Vec<VertexId>]>,
) -> Result<Option<Vec<Vec<VertexId>>>> {
    let n = mesh.n_vertices();
    let mut sides: [Vec<VertexId>; 2] = [Vec::new(), Vec::new()];
    for (&f, &w) in features.iter().zip(want) {
        sides[w.min(1)].push(f);
    }
    let mut taken = vec![false; n];
    for v in points.iter().chain(features) {
        taken[v.idx()] = true;
    }
    for side in sides.iter_mut().filter(|s| s.is_empty()) {
        let Some(v) = stand_in(mesh, &taken)? else { return Ok(None) };
        taken[v.idx()] = true;
        side.push(v);
    }
    // With the guide first; without it when its trees wall a partition point off.
    let mut guides = vec![guide];
    if guide.is_some() {
        guides.push(None);
    }
    for g in guides {
        let costs = Costs::new(mesh, g)?;
        if let Some(curves) = attempt(mesh, points, &sides, &taken, &costs, features, want)? {
            return Ok(Some(curves));
        }
    }
    Ok(None)
}

/// The trees, the seam and the shortest loop around them under one set of costs.
fn attempt(
    mesh: &Mesh,
    points: [VertexId; 4],
    sides: &[Vec<VertexId>; 2],
    taken: &[bool],
    costs: &Costs,
    features: &[VertexId],
    want: &[usize],
) -> Result<Option<Vec<Vec<VertexId>>>> {
    let n = mesh.n_vertices();
    // TL avoids the points and TR's terminals with a one-ring margin; TR avoids TL likewise.
    let points_mask = mask(n, &points);
    let mut blocked = ring(mesh, &or(&points_mask, &mask(n, &sides[1])));
    unblock(&mut blocked, &sides[0]);
    let Some(tl) = tree(mesh, &sides[0], &blocked, &costs.tree)? else { return Ok(None) };
    let mut blocked = ring(mesh, &or(&points_mask, &tl));
    unblock(&mut blocked, &sides[1]);
    let Some(tr) = tree(mesh, &sides[1], &blocked, &costs.tree)? else { return Ok(None) };
    let Some(seam) = seam(mesh, &tl, &tr) else { return Ok(None) };
    // The loop may not touch the trees, the features or the stand-ins.
    let walls = or(&or(&tl, &tr), &or(&or(&points_mask, taken), &feature_rings(mesh, features)));
    let mut best: Option<(f64, Vec<Vec<VertexId>>)> = None;
    for k in 0..4 {
        for sigma in [1i8, -1] {
            for first in [true, false] {
                let Some(curves) = trace(mesh, points, &walls, &seam, &costs.near, k, sigma, first) else { continue };
                let left = left_faces(mesh, &curves)?;
                if features.iter().zip(want).any(|(&f, &w)| vertex_left(mesh, &left, f) != (w == 0)) {
                    continue;
                }
                let len = length(mesh, &curves);
                if best.as_ref().is_none_or(|b| len < b.0) {
                    best = Some((len, curves));
                }
            }
        }
    }
    tracing::debug!("separating loop: {}", if best.is_some() { "found" } else { "none" });
    Ok(best.map(|b| b.1))
}

fn mask(n: usize, vs: &[VertexId]) -> Vec<bool> {
    let mut m = vec![false; n];
    for v in vs {
        m[v.idx()] = true;
    }
    m
}

fn or(a: &[bool], b: &[bool]) -> Vec<bool> {
    a.iter().zip(b).map(|(x, y)| *x || *y).collect()
}

fn unblock(m: &mut [bool], vs: &[VertexId]) {
    for v in vs {
        m[v.idx()] = false;
    }
}

/// The vertex farthest (along edges) from every taken one.
fn stand_in(mesh: &Mesh, taken: &[bool]) -> Result<Option<VertexId>> {
    let sources: Vec<(VertexId, f64)> =
        (0..taken.len()).filter(|&v| taken[v]).map(|v| (VertexId::from_idx(v), 0.0)).collect();
    let r = vertex_dijkstra(mesh, &sources, &Default::default())?;
    Ok((0..taken.len())
        .filter(|&v| r.dist[v].is_finite() && !taken[v])
        .max_by(|&a, &b| r.dist[a].total_cmp(&r.dist[b]))
        .map(VertexId::from_idx))
}

/// A tree of shortest paths joining `terminals` (Prim's heuristic for the Steiner tree: the
/// nearest terminal joins the tree so far), or `None` when one is walled off.
fn tree(mesh: &Mesh, terminals: &[VertexId], blocked: &[bool], cost: &[f64]) -> Result<Option<Vec<bool>>> {
    let mut inside = mask(mesh.n_vertices(), &terminals[..1]);
    let mut rest = terminals[1..].to_vec();
    while !rest.is_empty() {
        let sources: Vec<VertexId> = (0..inside.len()).filter(|&v| inside[v]).map(VertexId::from_idx).collect();
        let (dist, pred) = weighted_dijkstra(mesh, &sources, blocked, cost);
        let Some(i) = (0..rest.len()).min_by(|&a, &b| dist[rest[a].idx()].total_cmp(&dist[rest[b].idx()])) else {
            break;
        };
        if !dist[rest[i].idx()].is_finite() {
            return Ok(None);
        }
        let mut v = rest[i].idx();
        while !inside[v] {
            inside[v] = true;
            v = pred[v] as usize;
        }
        rest.swap_remove(i);
    }
    Ok(Some(inside))
}

/// Multi-source Dijkstra with per-vertex cost factors (an edge costs its length times the mean
/// of its ends' factors); distances and predecessors (`u32::MAX` at sources and unreached).
fn weighted_dijkstra(mesh: &Mesh, sources: &[VertexId], blocked: &[bool], cost: &[f64]) -> (Vec<f64>, Vec<u32>) {
    let n = mesh.n_vertices();
    let mut dist = vec![f64::INFINITY; n];
    let mut pred = vec![u32::MAX; n];
    let mut heap = MinHeap::with_capacity(1024);
    for s in sources {
        dist[s.idx()] = 0.0;
        heap.push(0.0, s.0);
    }
    while let Some((d, u)) = heap.pop() {
        let u = VertexId(u);
        if d > dist[u.idx()] {
            continue;
        }
        for v in mesh.vertex_neighbors(u) {
            if blocked[v.idx()] {
                continue;
            }
            let nd = d + edge_cost(mesh, cost, u, v);
            if nd < dist[v.idx()] {
                dist[v.idx()] = nd;
                pred[v.idx()] = u.0;
                heap.push(nd, v.0);
            }
        }
    }
    (dist, pred)
}

fn edge_cost(mesh: &Mesh, cost: &[f64], u: VertexId, v: VertexId) -> f64 {
    (mesh.position(v) - mesh.position(u)).norm() * 0.5 * (cost[u.idx()] + cost[v.idx()])
}

/// A shortest dual path from a face at `TL` to a face at `TR`, as the edges it crosses.
fn seam(mesh: &Mesh, tl: &[bool], tr: &[bool]) -> Option<Seam> {
    let nf = mesh.n_faces();
    let touches = |f: usize, m: &[bool]| mesh.face(FaceId::from_idx(f)).iter().any(|v| m[v.idx()]);
    let centroid = |f: usize| {
        let [a, b, c] = mesh.face_points(FaceId::from_idx(f));
        (a.coords + b.coords + c.coords) / 3.0
    };
    let mut dist = vec![f64::INFINITY; nf];
    let mut via: Vec<Option<HalfedgeId>> = vec![None; nf];
    let mut heap = MinHeap::with_capacity(1024);
    for f in (0..nf).filter(|&f| touches(f, tl)) {
        dist[f] = 0.0;
        heap.push(0.0, f as u32);
    }
    let end = loop {
        let (d, f) = heap.pop()?;
        let f = f as usize;
        if d > dist[f] {
            continue;
        }
        if touches(f, tr) {
            break f;
        }
        for k in 0..3 {
            let h = HalfedgeId::of(FaceId::from_idx(f), k);
            let Some(t) = mesh.twin(h) else { continue };
            let g = t.face().idx();
            let nd = d + (centroid(g) - centroid(f)).norm();
            if nd < dist[g] {
                dist[g] = nd;
                via[g] = Some(h);
                heap.push(nd, g as u32);
            }
        }
    };
    let mut out: Seam = vec![None; mesh.n_edges()];
    let mut f = end;
    while let Some(h) = via[f] {
        out[mesh.edge(h).idx()] = Some((mesh.tail(h), mesh.head(h)));
        f = h.face().idx();
    }
    Some(out)
}

/// The four curves, curve `k` with one net crossing of sign `sigma`, traced first or last;
/// each later curve is kept off the earlier ones, and the other three off the seam; `None` if
/// one cannot be traced.
#[allow(clippy::too_many_arguments)]
fn trace(
    mesh: &Mesh,
    points: [VertexId; 4],
    walls: &[bool],
    seam: &Seam,
    cost: &[f64],
    k: usize,
    sigma: i8,
    first: bool,
) -> Option<Vec<Vec<VertexId>>> {
    let mut blocked = walls.to_vec();
    let mut curves = vec![Vec::new(); 4];
    let start = if first { k } else { k + 1 };
    for j in 0..4 {
        let c = (start + j) % 4;
        let path = lifted_path(mesh, points[c], points[(c + 1) % 4], &blocked, seam, cost, (c == k).then_some(sigma))?;
        for v in &path {
            blocked[v.idx()] = true;
        }
        curves[c] = path;
    }
    Some(curves)
}

/// Shortest vertex path `a` -> `b` through unblocked vertices. With `sigma`, it crosses the
/// seam once net in that direction (layer 0 -> 1); without, it does not touch the seam.
/// `None` if there is none, or if the shortest one visits a vertex twice (once per layer).
fn lifted_path(
    mesh: &Mesh,
    a: VertexId,
    b: VertexId,
    blocked: &[bool],
    seam: &Seam,
    cost: &[f64],
    sigma: Option<i8>,
) -> Option<Vec<VertexId>> {
    let n = mesh.n_vertices();
    let goal = b.idx() + if sigma.is_some() { n } else { 0 };
    let mut dist = vec![f64::INFINITY; 2 * n];
    let mut pred = vec![u32::MAX; 2 * n];
    let mut heap = MinHeap::with_capacity(1024);
    dist[a.idx()] = 0.0;
    heap.push(0.0, a.0);
    while let Some((d, s)) = heap.pop() {
        let s = s as usize;
        if d > dist[s] {
            continue;
        }
        if s == goal {
            break;
        }
        let (u, layer) = (VertexId::from_idx(s % n), s / n);
        if u == b {
            continue;
        }
        for h in mesh.outgoing(u) {
            let v = mesh.head(h);
            if blocked[v.idx()] && v != b {
                continue;
            }
            let next = match (seam[mesh.edge(h).idx()], sigma) {
                (None, _) => layer,
                (Some(_), None) => continue,
                (Some((t, _)), Some(sg)) => {
                    let sign = if t == u { 1 } else { -1 };
                    match (layer, sign == sg) {
                        (0, true) => 1,
                        (1, false) => 0,
                        _ => continue,
                    }
                }
            };
            let t = v.idx() + next * n;
            let nd = d + edge_cost(mesh, cost, u, v);
            if nd < dist[t] {
                dist[t] = nd;
                pred[t] = s as u32;
                heap.push(nd, t as u32);
            }
        }
    }
    if !dist[goal].is_finite() {
        return None;
    }
    let mut path = vec![b];
    let mut seen = vec![false; n];
    seen[b.idx()] = true;
    let mut s = goal;
    while pred[s] != u32::MAX {
        s = pred[s] as usize;
        let v = VertexId::from_idx(s % n);
        if std::mem::replace(&mut seen[v.idx()], true) {
            return None;
        }
        path.push(v);
    }
    path.reverse();
    Some(path)
}

/// Per-vertex cost factors from the guide loop: `tree` is `CROSS` on the guide and its
/// one-ring (1 elsewhere); `near` grows from 1 on the guide to `1 + DRAW` at `REACH` of the
/// bounding-box diagonal from it. Without a guide both are 1.
struct Costs {
    tree: Vec<f64>,
    near: Vec<f64>,
}

const CROSS: f64 = 20.0;
const DRAW: f64 = 3.0;
const REACH: f64 = 0.05;

impl Costs {
    fn new(mesh: &Mesh, guide: Option<&[Vec<VertexId>]>) -> Result<Self> {
        let n = mesh.n_vertices();
        let Some(guide) = guide else { return Ok(Self { tree: vec![1.0; n], near: vec![1.0; n] }) };
        let on: Vec<VertexId> = guide.iter().flatten().copied().collect();
        let tree = ring(mesh, &mask(n, &on)).iter().map(|&b| if b { CROSS } else { 1.0 }).collect();
        let sources: Vec<(VertexId, f64)> = on.iter().map(|&v| (v, 0.0)).collect();
        let d = vertex_dijkstra(mesh, &sources, &Default::default())?;
        let reach = REACH * mesh.bbox_diagonal();
        let near = d.dist.iter().map(|&x| 1.0 + DRAW * (x / reach).min(1.0)).collect();
        Ok(Self { tree, near })
    }
}

fn length(mesh: &Mesh, curves: &[Vec<VertexId>]) -> f64 {
    curves.iter().flat_map(|c| c.windows(2)).map(|w| (mesh.position(w[1]) - mesh.position(w[0])).norm()).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    use crate::mesh::shapes::extreme_vertex as extreme;

    /// The curves join p0 -> p1 -> p2 -> p3 -> p0 along mesh edges, and no vertex is on two
    /// curves except the corners they share.
    fn assert_simple_loop(m: &Mesh, pts: [VertexId; 4], curves: &[Vec<VertexId>]) {
        let mut seen = vec![0; m.n_vertices()];
        for (c, path) in curves.iter().enumerate() {
            assert_eq!((path[0], path[path.len() - 1]), (pts[c], pts[(c + 1) % 4]));
            for w in path.windows(2) {
                assert!(m.find_halfedge(w[0], w[1]).is_some(), "consecutive vertices share an edge");
            }
            for v in &path[1..] {
                seen[v.idx()] += 1;
            }
        }
        assert!(seen.iter().all(|&k| k <= 1), "the loop never touches itself");
    }

    #[test]
    fn features_on_both_poles_end_on_the_wanted_sides() {
        let m = shapes::icosphere(4);
        let pts = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]].map(|d| extreme(&m, d));
        let feats = [[0.3, 0.2, 1.0], [-0.2, 0.3, -1.0], [0.5, 0.5, 0.6]].map(|d| extreme(&m, d));
        // The equator separates the poles; every assignment, including both poles on one side
        // (which the shortest loop cannot give), is reached.
        for want in [[0, 1, 0], [0, 0, 0], [1, 1, 0], [1, 0, 1]] {
            let curves = separating_loop(&m, pts, &feats, &want, None).unwrap().expect("a separating loop");
            assert_simple_loop(&m, pts, &curves);
            let left = left_faces(&m, &curves).unwrap();
            for (f, w) in feats.iter().zip(want) {
                assert_eq!(vertex_left(&m, &left, *f), w == 0, "feature {} wanted in patch {w}", f.0);
            }
        }
    }

    #[test]
    fn the_guide_keeps_the_loop_where_it_was_away_from_the_moved_feature() {
        let m = shapes::icosphere(4);
        let pts = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]].map(|d| extreme(&m, d));
        // One feature just north of the equator, wanted south.
        let feats = [extreme(&m, [0.7, 0.7, 0.25]), extreme(&m, [0.0, 0.0, 1.0]), extreme(&m, [0.0, 0.0, -1.0])];
        let r = super::super::partition::partition_genus0(&m, pts, &feats, &Default::default()).unwrap();
        let north = r.patches.iter().position(|p| p.features.iter().any(|&(k, _)| k == 1)).unwrap();
        let want = [1 - north, north, 1 - north];
        let curves = separating_loop(&m, pts, &feats, &want, Some(&r.curves)).unwrap().expect("a separating loop");
        assert_simple_loop(&m, pts, &curves);
        let left = left_faces(&m, &curves).unwrap();
        for (f, w) in feats.iter().zip(want) {
            assert_eq!(vertex_left(&m, &left, *f), w == 0);
        }
        // The curves away from the moved feature (p2 -> p3 runs on the far side) stay put.
        assert_eq!(curves[2], r.curves[2], "the far curve is the guide's");
    }
}
