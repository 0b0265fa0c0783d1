//! The cut that opens a genus-0 surface with feature curves into a disk whose boundary carries
//! every feature (Carner et al. section 3.4).
//!
//! The double cover `M'` of `M` along `n` curves has genus `n − 1`, and the deck involution σ
//! (swap the copies) maps it to itself. We cut `M'` along a σ-symmetric graph: every slit, plus
//! a chain of links on each copy, `start(F1) → F1 → end(F1) → start(F2) → … → Fn`. The slits
//! separate the copies, so the fundamental domain of `M'` is two mirror disks, copy 1's and σ of
//! it; a harmonic map with σ-symmetric boundary data is the mirror image on the second (the
//! solution is unique), so only copy 1 is solved and "dropping the copy" is exact. Copy 1's
//! disk is `M` cut along the chain, and its boundary reads `F1 L2 F2 … Fn Fn⁻¹ … L2⁻¹ F1⁻¹`
//! (with boundary arcs in place of `F ⋯ F⁻¹` for boundary loops).
//!
//! Why a chain and not a star of links from one base vertex: links meet curves only at curve
//! endpoints (or, on a boundary loop, at two points splitting it by arc length), where there is
//! a single way around, so the boundary word depends on the curves' order alone — two meshes
//! always produce the same word, with no cyclic order to reconcile at a branch point.

use super::features::{Curve, CurveKind, doubled_genus};
use super::search;
use crate::error::{Error, InputError, Result};
use crate::mesh::cut::{CutMesh, cut_along, path_edges};
use crate::mesh::{Mesh, VertexId};
use crate::topology;
use std::collections::HashMap;

/// What one side of the disk's boundary runs along.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case", tag = "kind", content = "index")]
pub enum SideKind {
    /// Link `i` of the chain (link 0 joins the first anchor to a boundary loop, when it must).
    Link(usize),
    /// Curve `i` (open feature or boundary arc).
    Curve(usize),
    /// Side `i` of the canonical 4g-gon, counted from the corner the chain arrives at (surfaces
    /// with handles, [`super::feature_handles`]).
    Basis(usize),
}

/// One side: `walk[start..=start + edges]` (cyclically).
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct Side {
    pub start: usize,
    pub edges: usize,
    pub kind: SideKind,
    /// Length in space.
    pub length: f64,
}

/// The cut disk and how its boundary is made up.
#[derive(Debug, Clone)]
pub struct FeatureCutResult {
    /// The curves in chain order (open ones possibly reversed), then an unlisted boundary loop
    /// (at most one).
    pub curves: Vec<Curve>,
    /// The chain's links, each a vertex path.
    pub links: Vec<Vec<VertexId>>,
    /// The chain's first vertex.
    pub base: VertexId,
    pub disk: CutMesh,
    /// The disk's boundary (vertices of `disk.mesh`), interior on the left, from the base.
    pub walk: Vec<VertexId>,
    pub sides: Vec<Side>,
    /// Genus of the double cover.
    pub doubled_genus: usize,
}

/// Cuts a genus-0 `mesh` along its `curves` and the chain that links them, visiting the curves
/// in `order` (index, entered at its last vertex; see [`chain_order`]). An unlisted boundary
/// loop is appended as the last curve, starting at `loop_start` when that lies on it (a
/// boundary anchor); otherwise the chain arrives at it by a shortest path, from the last open
/// curve or, with none, from `anchor`.
///
/// # Errors
/// `InputError::TopologyMismatch` for genus > 0 or unlisted boundary loops that cannot be told
/// apart; `InputError::Features` when no link can avoid the other curves.
pub fn feature_cut(
    mesh: &Mesh,
    curves: &[Curve],
    order: &[(usize, bool)],
    anchor: Option<VertexId>,
    loop_start: Option<VertexId>,
) -> Result<FeatureCutResult> {
    let genus = topology::summary(mesh).genus;
    if genus != 0 {
        return Err(InputError::TopologyMismatch(format!(
            "the feature cut opens genus-0 surfaces (a surface with handles is cut through its canonical basis first); this one has genus {genus}"
        ))
        .into());
    }
    match cut_with(mesh, curves, order, anchor, loop_start, false) {
        Err(Error::Input(InputError::Features(_))) => cut_with(mesh, curves, order, anchor, loop_start, true),
        r => r,
    }
}

/// [`feature_cut`] with shortest links, or with links that keep clear of used vertices
/// (`clear`, see [`link_path`]).
fn cut_with(
    mesh: &Mesh,
    curves: &[Curve],
    order: &[(usize, bool)],
    anchor: Option<VertexId>,
    loop_start: Option<VertexId>,
    clear: bool,
) -> Result<FeatureCutResult> {
    if order.len() != curves.len() {
        return Err(Error::Internal(format!("chain order of {} for {} curves", order.len(), curves.len())));
    }
    let mut curves: Vec<Curve> = order
        .iter()
        .map(|&(i, rev)| {
            let mut c = curves[i].clone();
            if rev {
                c.vertices.reverse();
            }
            c
        })
        .collect();
    let listed: Vec<VertexId> =
        curves.iter().filter(|c| c.kind == CurveKind::Boundary).map(|c| c.vertices[0]).collect();
    let loops = topology::boundary_loops(mesh);
    let unlisted: Vec<_> = loops.iter().filter(|l| !l.iter().any(|&h| listed.contains(&mesh.tail(h)))).collect();
    if unlisted.len() > 1 {
        return Err(InputError::TopologyMismatch(format!(
            "{} boundary loops are not listed as features; list each one (a closed vertex list) so that they correspond",
            unlisted.len()
        ))
        .into());
    }
    // Boundary curves go last, so that only interior chain points split a loop.
    curves.sort_by_key(|c| c.kind == CurveKind::Boundary);
    let mut auto_loop: Option<Vec<VertexId>> = unlisted.first().map(|l| l.iter().map(|&h| mesh.tail(h)).collect());
    // A boundary anchor on the unlisted loop fixes where it starts: the chain arrives there.
    let pinned = match (&mut auto_loop, loop_start) {
        (Some(ring), Some(s)) if ring.contains(&s) => {
            let k = ring.iter().position(|&x| x == s).unwrap_or(0);
            ring.rotate_left(k);
            true
        }
        _ => false,
    };
    if curves.is_empty() && auto_loop.is_none() {
        return Err(InputError::TopologyMismatch(
            "a closed genus-0 surface has no handle to cut: give at least one feature curve".into(),
        )
        .into());
    }
    let mut used = vec![false; mesh.n_vertices()];
    for v in curves.iter().flat_map(|c| &c.vertices) {
        used[v.idx()] = true;
    }
    for l in &loops {
        for &h in l {
            used[mesh.tail(h).idx()] = true;
        }
    }
    let mut links = Vec::new();
    let mut prev: Option<VertexId> = None;
    let mut base = None;
    let total = curves.len() + usize::from(auto_loop.is_some());
    for i in 0..total {
        let entry_targets: Vec<VertexId> = match (curves.get(i), &auto_loop) {
            (Some(c), _) => vec![c.vertices[0]],
            (None, Some(ring)) if pinned => vec![ring[0]],
            (None, ring) => ring.clone().unwrap_or_default(),
        };
        if prev.is_none() && curves.get(i).is_none() && !pinned {
            let a = anchor.ok_or_else(|| {
                InputError::Anchors(
                    "a disk without feature curves needs an anchor: a pair of boundary vertices fixes where the boundary starts"
                        .into(),
                )
            })?;
            if used[a.idx()] {
                return Err(InputError::Anchors(format!("anchor vertex {} lies on the boundary", a.0)).into());
            }
            prev = Some(a);
        }
        if base.is_none() {
            base = Some(prev.unwrap_or(entry_targets[0]));
        }
        let entry = match prev {
            None => entry_targets[0],
            Some(p) => {
                let link = link_path(mesh, &used, p, &entry_targets, clear).ok_or_else(|| {
                    InputError::Features(format!(
                        "no path from vertex {} to curve {i} avoids the other curves; refine the mesh or move the curves apart",
                        p.0
                    ))
                })?;
                for v in &link[1..link.len() - 1] {
                    used[v.idx()] = true;
                }
                used[p.idx()] = true;
                let e = link[link.len() - 1];
                links.push(link);
                e
            }
        };
        if curves.get(i).is_none() {
            let ring = auto_loop.as_deref().unwrap_or_default();
            let s = ring.iter().position(|&x| x == entry).unwrap_or(0);
            curves.push(Curve {
                vertices: (0..ring.len()).map(|k| ring[(s + k) % ring.len()]).collect(),
                kind: CurveKind::Boundary,
            });
        }
        let c = &curves[i];
        prev = Some(match c.kind {
            CurveKind::Open => c.vertices[c.vertices.len() - 1],
            CurveKind::Boundary => half_way(mesh, &c.vertices),
        });
    }
    let base = base.ok_or_else(|| Error::Internal("feature cut: empty chain".into()))?;
    let open: Vec<Vec<VertexId>> =
        curves.iter().filter(|c| c.kind == CurveKind::Open).map(|c| c.vertices.clone()).chain(links.clone()).collect();
    let disk = cut_along(mesh, &path_edges(mesh, &open)?)?;
    let ds = topology::summary(&disk.mesh);
    if ds.components != 1 || ds.boundary_loops != 1 || topology::euler_characteristic(&disk.mesh) != 1 {
        return Err(Error::Internal(format!(
            "feature cut: not a disk ({} components, {} boundary loops, χ = {})",
            ds.components,
            ds.boundary_loops,
            topology::euler_characteristic(&disk.mesh)
        )));
    }
    let (walk, sides) = sides_of(mesh, &disk, &curves, &links, base)?;
    let doubled = doubled_genus(0, curves.len());
    Ok(FeatureCutResult { curves, links, base, disk, walk, sides, doubled_genus: doubled })
}

/// The order in which the chain visits the open curves, and whether it enters each at its
/// last vertex: greedy nearest-neighbour from curve 0's end, with endpoint distances relative
/// to each mesh's bounding-box diagonal summed over both meshes, so that both get one order and
/// the links (cuts that are not features) stay short.
pub fn chain_order(meshes: [&Mesh; 2], curves: [&[Curve]; 2]) -> Vec<(usize, bool)> {
    let open: Vec<usize> = (0..curves[0].len()).filter(|&i| curves[0][i].kind == CurveKind::Open).collect();
    let end = |k: usize, i: usize, last: bool| {
        let v = &curves[k][i].vertices;
        meshes[k].position(if last { v[v.len() - 1] } else { v[0] })
    };
    let dist = |(i, il): (usize, bool), (j, jl): (usize, bool)| -> f64 {
        (0..2).map(|k| (end(k, i, il) - end(k, j, jl)).norm() / meshes[k].bbox_diagonal().max(f64::MIN_POSITIVE)).sum()
    };
    let mut order = Vec::with_capacity(curves[0].len());
    let mut left: Vec<usize> = open.clone();
    if let Some(first) = left.first().copied() {
        left.remove(0);
        order.push((first, false));
    }
    while !left.is_empty() {
        let &(i, rev) = order.last().unwrap_or(&(0, false));
        let exit = (i, !rev);
        let mut best = (f64::INFINITY, 0, false);
        for (k, &j) in left.iter().enumerate() {
            for r in [false, true] {
                let d = dist(exit, (j, r));
                if d < best.0 {
                    best = (d, k, r);
                }
            }
        }
        order.push((left.remove(best.1), best.2));
    }
    order.extend((0..curves[0].len()).filter(|i| !open.contains(i)).map(|i| (i, false)));
    order
}

/// The chain's order on surfaces with handles, where the chain ends at the base (at a corner of
/// the 4g-gon): greedy nearest-neighbour outward from `base` on each mesh (distances as in
/// [`chain_order`]), then walked backwards, so that the last curve is the one nearest the base
/// and is left at its nearer end. The link to the base is then short and direct; a long one
/// that has to pass the chain of curves on one side or the other can take different sides on
/// two deformed copies (the whole chain then turns once around the base).
pub fn chain_order_to_base(meshes: [&Mesh; 2], curves: [&[Curve]; 2], base: [VertexId; 2]) -> Vec<(usize, bool)> {
    let end = |k: usize, i: usize, last: bool| {
        let v = &curves[k][i].vertices;
        meshes[k].position(if last { v[v.len() - 1] } else { v[0] })
    };
    let scale = |k: usize| meshes[k].bbox_diagonal().max(f64::MIN_POSITIVE);
    let mut left: Vec<usize> = (0..curves[0].len()).collect();
    let mut out: Vec<(usize, bool)> = Vec::with_capacity(left.len());
    while !left.is_empty() {
        // From the base, then from the far end of the curve taken last.
        let from = |k: usize| match out.last() {
            None => meshes[k].position(base[k]),
            Some(&(i, entered_at_last)) => end(k, i, !entered_at_last),
        };
        let mut best = (f64::INFINITY, 0, false);
        for (j, &c) in left.iter().enumerate() {
            for r in [false, true] {
                let d: f64 = (0..2).map(|k| (from(k) - end(k, c, r)).norm() / scale(k)).sum();
                if d < best.0 {
                    best = (d, j, r);
                }
            }
        }
        out.push((left.remove(best.1), best.2));
    }
    out.into_iter().rev().map(|(c, r)| (c, !r)).collect()
}

/// Shortest path from `from` to one of `to` through unused vertices only. With `clear`, the
/// path first keeps a vertex of clearance from every used vertex (away from its own two ends):
/// a link that comes next to used vertices twice pens the vertices between in a pocket that
/// later links cannot enter (vertex walls block passage wherever two of them share an edge);
/// when that finds nothing, steps next to used vertices only cost more.
fn link_path(mesh: &Mesh, used: &[bool], from: VertexId, to: &[VertexId], clear: bool) -> Option<Vec<VertexId>> {
    let is_target = |v: VertexId| to.contains(&v);
    let allowed = |v: VertexId| is_target(v) || !used[v.idx()];
    if !clear {
        let (tree, hit) = search::dijkstra(mesh, &[from], &allowed, &|_| true, &is_target, &|_| 1.0);
        return Some(search::path_to(&tree, hit?));
    }
    let at_end = |v: VertexId| v == from || is_target(v);
    let near = |v: VertexId| !at_end(v) && mesh.vertex_neighbors(v).any(|w| used[w.idx()] && !at_end(w));
    let end_ring = |v: VertexId| mesh.vertex_neighbors(v).any(at_end);
    let strict = |v: VertexId| is_target(v) || (!used[v.idx()] && (!near(v) || end_ring(v)));
    let (tree, hit) = search::dijkstra(mesh, &[from], &strict, &|_| true, &is_target, &|_| 1.0);
    if let Some(h) = hit {
        return Some(search::path_to(&tree, h));
    }
    let weight = |v: VertexId| if near(v) { LINK_CLEARANCE } else { 1.0 };
    let (tree, hit) = search::dijkstra(mesh, &[from], &allowed, &|_| true, &is_target, &weight);
    Some(search::path_to(&tree, hit?))
}

/// Cost factor of a link step onto a vertex next to a used one (when no path keeps clear).
const LINK_CLEARANCE: f64 = 3.0;

/// The vertex of a boundary loop halfway round from its start, by arc length.
fn half_way(mesh: &Mesh, ring: &[VertexId]) -> VertexId {
    let n = ring.len();
    let len: Vec<f64> = (0..n).map(|i| (mesh.position(ring[(i + 1) % n]) - mesh.position(ring[i])).norm()).collect();
    let total: f64 = len.iter().sum();
    let mut acc = 0.0;
    for (i, l) in len.iter().enumerate() {
        if acc + 0.5 * l >= 0.5 * total {
            return ring[i.clamp(1, n - 1)];
        }
        acc += l;
    }
    ring[n / 2]
}

/// The disk's boundary walk from the base and its sides, split at the chain's junctions.
fn sides_of(
    mesh: &Mesh,
    disk: &CutMesh,
    curves: &[Curve],
    links: &[Vec<VertexId>],
    base: VertexId,
) -> Result<(Vec<VertexId>, Vec<Side>)> {
    let loops = topology::boundary_loops(&disk.mesh);
    let ring: Vec<VertexId> = loops[0].iter().map(|&h| disk.mesh.tail(h)).collect();
    let s = ring
        .iter()
        .position(|&v| disk.orig[v.idx()] == base)
        .ok_or_else(|| Error::Internal("feature cut: the base is not on the disk's boundary".into()))?;
    let walk: Vec<VertexId> = (0..ring.len()).map(|k| ring[(s + k) % ring.len()]).collect();
    let key = |a: VertexId, b: VertexId| (a.0.min(b.0), a.0.max(b.0));
    let mut kind: HashMap<(u32, u32), SideKind> = HashMap::new();
    let mut junction = vec![false; mesh.n_vertices()];
    junction[base.idx()] = true;
    for (i, l) in links.iter().enumerate() {
        for w in l.windows(2) {
            kind.insert(key(w[0], w[1]), SideKind::Link(i));
        }
        junction[l[0].idx()] = true;
        junction[l[l.len() - 1].idx()] = true;
    }
    for (i, c) in curves.iter().enumerate() {
        let v = &c.vertices;
        let n = v.len();
        let steps = if c.kind == CurveKind::Boundary { n } else { n - 1 };
        for k in 0..steps {
            kind.insert(key(v[k], v[(k + 1) % n]), SideKind::Curve(i));
        }
        junction[v[0].idx()] = true;
        junction[v[n - 1].idx()] |= c.kind == CurveKind::Open;
    }
    let orig = |k: usize| disk.orig[walk[k % walk.len()].idx()];
    let breaks: Vec<usize> = (0..walk.len()).filter(|&k| junction[orig(k).idx()]).collect();
    let mut sides = Vec::with_capacity(breaks.len());
    for (j, &b) in breaks.iter().enumerate() {
        let e = if j + 1 < breaks.len() { breaks[j + 1] } else { walk.len() };
        let k = kind.get(&key(orig(b), orig(b + 1))).copied().ok_or_else(|| {
            Error::Internal(format!("feature cut: boundary edge {}-{} is on no cut", orig(b).0, orig(b + 1).0))
        })?;
        let length = (b..e).map(|i| (mesh.position(orig(i + 1)) - mesh.position(orig(i))).norm()).sum();
        sides.push(Side { start: b, edges: e - b, kind: k, length });
    }
    Ok((walk, sides))
}
