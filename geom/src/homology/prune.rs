//! Pruning the meta-mesh to the edges it needs (Carner et al. section 4: the merged tessellation
//! "can be simplified"): a vertex whose every edge is flat — dihedral angle at most the
//! threshold — on both surfaces is removed by a half-edge collapse into its nearest neighbour,
//! applied to both embeddings at once so that they keep one face list. A collapse is refused
//! when it would break the link condition (the mesh stays a manifold of the same genus), fold
//! or flatten a face, or tilt one by more than the threshold, on either surface. Crossing
//! vertices (edge–edge intersections) go first, then the rest, shortest edges first.

use super::overlay::MetaMeshResult;
use crate::error::Result;
use crate::mesh::{P3, V3};

/// Options for [`prune_meta_mesh`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PruneOptions {
    /// Edges whose dihedral angle exceeds this (degrees) on either surface are kept.
    pub dihedral_threshold_deg: f64,
}

/// The pruned meta-mesh and how much went.
#[derive(Debug, Clone)]
pub struct PruneResult {
    pub mesh: MetaMeshResult,
    pub removed_vertices: usize,
}

fn normal(p: &[P3], f: [u32; 3]) -> V3 {
    let [a, b, c] = f.map(|v| p[v as usize]);
    (b - a).cross(&(c - a))
}

fn angle(a: &V3, b: &V3) -> f64 {
    let d = a.norm() * b.norm();
    if d <= 0.0 { std::f64::consts::PI } else { (a.dot(b) / d).clamp(-1.0, 1.0).acos() }
}

/// Collapses flat vertices of the meta-mesh (both embeddings alike).
///
/// # Errors
/// `Numerical` if the result is not a valid mesh (it is checked).
pub fn prune_meta_mesh(m: &MetaMeshResult, opts: &PruneOptions) -> Result<PruneResult> {
    let crossing = &m.crossing;
    let theta = opts.dihedral_threshold_deg.to_radians();
    let n = m.on_source.len();
    let emb = [&m.on_source, &m.on_target];
    let mut faces: Vec<Option<[u32; 3]>> = m.faces.iter().copied().map(Some).collect();
    let mut star: Vec<Vec<u32>> = vec![Vec::new(); n];
    for (f, t) in m.faces.iter().enumerate() {
        for &v in t {
            star[v as usize].push(f as u32);
        }
    }
    let mut alive = vec![true; n];
    let mut order: Vec<u32> = (0..n as u32).collect();
    order.sort_by_key(|&v| !crossing.get(v as usize).copied().unwrap_or(false));
    let mut removed = 0;
    // Passes until nothing more collapses: a refused collapse may become possible once a
    // neighbour has gone.
    for _ in 0..PASSES {
        let before = removed;
        prune_pass(&order, &mut faces, &mut star, &mut alive, &mut removed, &emb, theta);
        if removed == before {
            break;
        }
    }
    let mut id = vec![u32::MAX; n];
    let (mut on_source, mut on_target) = (Vec::new(), Vec::new());
    for v in (0..n).filter(|&v| alive[v]) {
        id[v] = on_source.len() as u32;
        on_source.push(m.on_source[v]);
        on_target.push(m.on_target[v]);
    }
    let faces: Vec<[u32; 3]> = faces.into_iter().flatten().map(|t| t.map(|x| id[x as usize])).collect();
    let crossing: Vec<bool> = (0..n).filter(|&v| alive[v]).map(|v| crossing.get(v).copied().unwrap_or(false)).collect();
    let crossings = crossing.iter().filter(|x| **x).count();
    let mesh = MetaMeshResult { faces, on_source, on_target, crossings, crossing };
    mesh.meshes()?;
    Ok(PruneResult { mesh, removed_vertices: removed })
}

/// Passes of [`prune_meta_mesh`] at most.
const PASSES: usize = 8;

/// One pass over the vertices in `order`.
fn prune_pass(
    order: &[u32],
    faces: &mut [Option<[u32; 3]>],
    star: &mut [Vec<u32>],
    alive: &mut [bool],
    removed: &mut usize,
    emb: &[&Vec<P3>; 2],
    theta: f64,
) {
    for &u in order {
        let us = u as usize;
        let fs: Vec<[u32; 3]> = star[us].iter().filter_map(|&f| faces[f as usize]).collect();
        if !alive[us] || fs.is_empty() || !flat_star(&fs, emb, theta) {
            continue;
        }
        let mut nbrs: Vec<u32> = fs.iter().flatten().copied().filter(|&w| w != u).collect();
        nbrs.sort_unstable();
        nbrs.dedup();
        nbrs.sort_by(|&a, &b| {
            let d = |w: u32| (emb[0][w as usize] - emb[0][us]).norm();
            d(a).total_cmp(&d(b))
        });
        let Some(v) = nbrs.iter().copied().find(|&v| collapsible(u, v, &fs, star, faces, emb, theta)) else {
            continue;
        };
        for &f in &star[us].clone() {
            let Some(t) = faces[f as usize] else { continue };
            if t.contains(&v) {
                faces[f as usize] = None;
            } else {
                faces[f as usize] = Some(t.map(|x| if x == u { v } else { x }));
                star[v as usize].push(f);
            }
        }
        star[us].clear();
        alive[us] = false;
        *removed += 1;
    }
}

/// Every edge at the vertex is flat on both surfaces: each face's normal is within `theta` of
/// its neighbours' around the star (a star's faces are consecutive around it).
fn flat_star(fs: &[[u32; 3]], emb: &[&Vec<P3>; 2], theta: f64) -> bool {
    emb.iter().all(|p| {
        let ns: Vec<V3> = fs.iter().map(|&f| normal(p, f)).collect();
        (0..ns.len())
            .all(|i| (0..ns.len()).all(|j| i == j || !share_edge(fs[i], fs[j]) || angle(&ns[i], &ns[j]) <= theta))
    })
}

fn share_edge(a: [u32; 3], b: [u32; 3]) -> bool {
    a.iter().filter(|x| b.contains(x)).count() == 2
}

/// Whether collapsing `u` (not on the boundary) into `v` keeps a manifold and keeps every moved
/// face within `theta` of where it was, unfolded and not flat, on both surfaces.
fn collapsible(
    u: u32,
    v: u32,
    fs: &[[u32; 3]],
    star: &[Vec<u32>],
    faces: &[Option<[u32; 3]>],
    emb: &[&Vec<P3>; 2],
    theta: f64,
) -> bool {
    // Link condition: the neighbours common to u and v are exactly the two across uv.
    let ring = |x: u32| -> Vec<u32> {
        let mut r: Vec<u32> =
            star[x as usize].iter().filter_map(|&f| faces[f as usize]).flatten().filter(|&w| w != x).collect();
        r.sort_unstable();
        r.dedup();
        r
    };
    let (ru, rv) = (ring(u), ring(v));
    // A vertex on the boundary (an open fan: one more neighbour than faces) stays: collapsing it
    // along an interior edge would pinch the surface, and the boundary keeps its shape.
    if ru.len() != fs.len() {
        return false;
    }
    let common = ru.iter().filter(|w| rv.binary_search(w).is_ok()).count();
    let across = fs.iter().filter(|t| t.contains(&v)).count();
    if across != 2 || common != 2 || ru.len() <= 3 || rv.len() <= 3 {
        return false;
    }
    fs.iter().filter(|t| !t.contains(&v)).all(|&t| {
        let moved = t.map(|x| if x == u { v } else { x });
        emb.iter().all(|p| {
            let (a, b) = (normal(p, t), normal(p, moved));
            b.norm() > 1e-12 * a.norm().max(f64::MIN_POSITIVE) && angle(&a, &b) <= theta
        })
    })
}
