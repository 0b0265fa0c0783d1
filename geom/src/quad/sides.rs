//! Keeping feature points on the same side of the partition loop on every model. Shortest
//! paths on different shapes can pass a feature on different sides; then the feature would lie
//! in different patches and could not be aligned. Given the side a feature must be on, the
//! curve nearest to it is re-traced around it:
//! - `S1`: shortest path from the feature to the loop inside its current side, meeting curve `c`
//!   at `w` (each curve is tried, nearest first);
//! - `S2`: shortest path from `w` to another curve, inside the other side;
//! - neither runs alongside the rest of the loop (they may not enter its one-ring except for
//!   the last step), so the re-traced curve has room to pass between them and the loop;
//! - `c` is traced again between its corners with `T = S1 + S2` blocked. The rest of the loop
//!   and `T` form a tree, whose complement is a disk, so a new `c` exists (on a fine enough
//!   mesh), and it cannot cross `T`: `T` hangs off the rest of the loop on the wanted side, so
//!   the feature at its tip ends up there.

use crate::error::Result;
use crate::geodesic::{VertexDijkstraOptions, vertex_dijkstra};
use crate::mesh::cut::path_edges;
use crate::mesh::{Mesh, VertexId};

/// The features and their one-rings, which the loop never enters: a feature next to the loop
/// would have patch-boundary neighbours, which stay put while it moves to its aligned (u, v),
/// and could leave no room for its star.
pub fn feature_rings(mesh: &Mesh, features: &[VertexId]) -> Vec<bool> {
    let mut m = vec![false; mesh.n_vertices()];
    for f in features {
        m[f.idx()] = true;
    }
    with_one_ring(mesh, &m)
}

/// The vertices of `m` and their neighbours.
pub fn with_one_ring(mesh: &Mesh, m: &[bool]) -> Vec<bool> {
    let mut out = m.to_vec();
    for v in (0..m.len()).filter(|&v| m[v]) {
        for u in mesh.vertex_neighbors(VertexId::from_idx(v)) {
            out[u.idx()] = true;
        }
    }
    out
}

/// Per face: true on the left of the loop (the side of patch 0).
pub fn left_faces(mesh: &Mesh, curves: &[Vec<VertexId>]) -> Result<Vec<bool>> {
    let on_loop = path_edges(mesh, curves)?;
    let mut label = vec![false; mesh.n_faces()];
    let mut seen = vec![false; mesh.n_faces()];
    let Some(h) = mesh.find_halfedge(curves[0][0], curves[0][1]) else { return Ok(label) };
    let mut stack = vec![h.face()];
    seen[h.face().idx()] = true;
    while let Some(f) = stack.pop() {
        label[f.idx()] = true;
        for k in 0..3 {
            let h = crate::HalfedgeId::of(f, k);
            if on_loop[mesh.edge(h).idx()] {
                continue;
            }
            if let Some(t) = mesh.twin(h)
                && !seen[t.face().idx()]
            {
                seen[t.face().idx()] = true;
                stack.push(t.face());
            }
        }
    }
    Ok(label)
}

/// Whether vertex `v` (off the loop) lies left of the loop.
pub fn vertex_left(mesh: &Mesh, left: &[bool], v: VertexId) -> bool {
    mesh.vertex_faces(v).next().is_some_and(|f| left[f.idx()])
}

/// The loop with one curve re-traced so that `feature` changes side, or `None`.
pub fn reroute(
    mesh: &Mesh,
    curves: &[Vec<VertexId>],
    feature: VertexId,
    features: &[VertexId],
) -> Result<Option<Vec<Vec<VertexId>>>> {
    let left = left_faces(mesh, curves)?;
    let side = vertex_left(mesh, &left, feature);
    let n = mesh.n_vertices();
    let mut curve_of = vec![u32::MAX; n];
    let mut corner = vec![false; n];
    for (c, p) in curves.iter().enumerate() {
        corner[p[0].idx()] = true;
        for v in &p[1..p.len() - 1] {
            curve_of[v.idx()] = c as u32;
        }
    }
    let same: Vec<bool> = left.iter().map(|&l| l == side).collect();
    let other: Vec<bool> = left.iter().map(|&l| l != side).collect();
    // S1: to the nearest interior vertex of each curve, inside the feature's side, touching no
    // other loop vertex (else the wall would hang off the loop on both sides).
    let mut blocked = vec![false; n];
    for f in features {
        blocked[f.idx()] = *f != feature;
    }
    let mut order = Vec::new();
    for c in 0..curves.len() {
        let near = near_rest(mesh, curves, &curve_of, &corner, c);
        let mut b1 = blocked.clone();
        for (v, b) in b1.iter_mut().enumerate() {
            *b |=
                corner[v] || (curve_of[v] != u32::MAX && curve_of[v] as usize != c) || (near[v] && v != feature.idx());
        }
        let r1 = vertex_dijkstra(
            mesh,
            &[(feature, 0.0)],
            &VertexDijkstraOptions { faces: Some(&same), blocked: Some(&b1), ..Default::default() },
        )?;
        let best = (0..n)
            .filter(|&v| curve_of[v] as usize == c && r1.dist[v].is_finite())
            .min_by(|&a, &b| r1.dist[a].total_cmp(&r1.dist[b]));
        if let Some(w) = best {
            order.push((r1.dist[w], c, w, r1, near));
        }
    }
    order.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, c, w, r1, near) in &order {
        if let Some(out) = around(mesh, curves, r1, &blocked, &curve_of, &corner, &other, near, features, *c, *w)? {
            return Ok(Some(out));
        }
    }
    Ok(None)
}

/// Whether `v` is on the loop but not on curve `c`: on another curve, or a corner not `c`'s.
fn rest_of_loop(curves: &[Vec<VertexId>], curve_of: &[u32], corner: &[bool], c: usize, v: usize) -> bool {
    (curve_of[v] != u32::MAX && curve_of[v] as usize != c) || (corner[v] && !curves[c].contains(&VertexId::from_idx(v)))
}

/// Vertices off the loop next to the loop's other curves or its corners other than `c`'s.
fn near_rest(mesh: &Mesh, curves: &[Vec<VertexId>], curve_of: &[u32], corner: &[bool], c: usize) -> Vec<bool> {
    let n = mesh.n_vertices();
    let rest = |v: usize| rest_of_loop(curves, curve_of, corner, c, v);
    let on_loop = |v: usize| curve_of[v] != u32::MAX || corner[v];
    (0..n).map(|v| !on_loop(v) && mesh.vertex_neighbors(VertexId::from_idx(v)).any(|u| rest(u.idx()))).collect()
}

/// Re-traces curve `c` with the wall from the feature through `w` (on `c`) to another curve.
#[allow(clippy::too_many_arguments)]
fn around(
    mesh: &Mesh,
    curves: &[Vec<VertexId>],
    r1: &crate::geodesic::VertexDijkstraResult,
    blocked: &[bool],
    curve_of: &[u32],
    corner: &[bool],
    other: &[bool],
    near: &[bool],
    features: &[VertexId],
    c: usize,
    w: usize,
) -> Result<Option<Vec<Vec<VertexId>>>> {
    let n = mesh.n_vertices();
    let Some(s1) = r1.path_to(VertexId::from_idx(w)) else { return Ok(None) };
    // S2: from w across to another curve (or a corner not on c), inside the other side.
    let mut blocked2 = blocked.to_vec();
    for v in &curves[c] {
        blocked2[v.idx()] = v.idx() != w;
    }
    for v in &s1 {
        blocked2[v.idx()] |= v.idx() != w;
    }
    let r2 = vertex_dijkstra(
        mesh,
        &[(VertexId::from_idx(w), 0.0)],
        &VertexDijkstraOptions { faces: Some(other), blocked: Some(&blocked2), ..Default::default() },
    )?;
    let ends = |v: usize| rest_of_loop(curves, curve_of, corner, c, v);
    // The first vertex next to the rest of the loop, then one step onto it: the wall never runs
    // alongside the loop, which would leave no room to pass between them.
    let Some(y) = (0..n)
        .filter(|&v| (near[v] || ends(v)) && r2.dist[v].is_finite())
        .min_by(|&a, &b| r2.dist[a].total_cmp(&r2.dist[b]))
    else {
        return Ok(None);
    };
    let Some(mut s2) = r2.path_to(VertexId::from_idx(y)) else { return Ok(None) };
    if !ends(y) {
        let Some(z) = mesh.vertex_neighbors(VertexId::from_idx(y)).find(|u| ends(u.idx())) else { return Ok(None) };
        s2.push(z);
    }
    // Re-trace c with everything else blocked.
    let mut wall = vec![false; n];
    for (w, r) in wall.iter_mut().zip(feature_rings(mesh, features)) {
        *w |= r;
    }
    for (k, p) in curves.iter().enumerate() {
        for v in p {
            wall[v.idx()] |= k != c;
        }
    }
    for v in s1.iter().chain(&s2) {
        wall[v.idx()] = true;
    }
    let (a, b) = (curves[c][0], curves[c][curves[c].len() - 1]);
    wall[a.idx()] = false;
    let r = vertex_dijkstra(
        mesh,
        &[(a, 0.0)],
        &VertexDijkstraOptions { target: Some(b), blocked: Some(&wall), ..Default::default() },
    )?;
    let Some(path) = r.path_to(b) else { return Ok(None) };
    let mut out = curves.to_vec();
    out[c] = path;
    Ok(Some(out))
}
