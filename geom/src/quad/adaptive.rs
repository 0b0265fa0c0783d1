//! Adaptive remeshing (Yu & Chuang, section 4, eqs. 4–6): a quadtree per patch whose quad `q`
//! splits while `E_N(q) = max_v d(v, g) / B(M)` exceeds ε, where `g` is the least-squares plane
//! (principal axes) of the original vertices inside `q` and `B(M)` the bounding-box diagonal.
//! Over several models a quad splits when the largest of their errors does (`E_C`, eq. 6), so
//! every model gets the same tree. Trees are then balanced to a level difference of at most
//! one between neighbours, across patch sides too (lattice points on a side are named by the
//! layout curve, as in the uniform grid), and each leaf is triangulated without T-vertices: two
//! triangles when no neighbour is finer, otherwise a fan from its centre through the corners and
//! the midpoints that finer neighbours put on its edges.

use super::layout::QuadLayout;
use super::remesh::{Key, grid_key};
use super::surface::QuadSurface;
use crate::error::{InputError, Result};
use crate::mesh::{Mesh, P3};
use crate::param::Uv;
use nalgebra::Matrix3;
use std::collections::{HashMap, HashSet};

/// Adaptive remeshes of all models with one connectivity.
#[derive(Debug, Clone)]
pub struct AdaptiveRemesh {
    pub faces: Vec<[u32; 3]>,
    /// Quadtree leaves (the quads of the remesh).
    pub quads: usize,
    pub positions: Vec<Vec<P3>>,
}

/// A leaf: patch, lower-left lattice corner and size (lattice units at the finest level).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
struct Quad {
    p: u32,
    i: u32,
    j: u32,
    s: u32,
}

/// Largest distance of `pts` from their least-squares plane.
fn plane_error(pts: &[P3]) -> f64 {
    if pts.len() < 4 {
        return 0.0;
    }
    let c = pts.iter().fold(nalgebra::Vector3::zeros(), |a, p| a + p.coords) / pts.len() as f64;
    let mut m = Matrix3::zeros();
    for p in pts {
        let d = p.coords - c;
        m += d * d.transpose();
    }
    let e = m.symmetric_eigen();
    let k = e.eigenvalues.imin();
    let n = e.eigenvectors.column(k).into_owned();
    pts.iter().map(|p| (p.coords - c).dot(&n).abs()).fold(0.0, f64::max)
}

/// Builds adaptive remeshes with error bound `epsilon` and at most `max_level` splits; with
/// `only = Some(m)` the tree follows model `m`'s error alone (separate adaptive remeshing).
///
/// # Errors
/// `InputError::Invalid` for a level outside 1..=10.
pub fn adaptive_remesh_with(
    layout: &QuadLayout,
    surfaces: &[&dyn QuadSurface],
    meshes: &[Mesh],
    epsilon: f64,
    max_level: u32,
    only: Option<usize>,
) -> Result<AdaptiveRemesh> {
    if !(1..=super::remesh::MAX_LEVEL).contains(&max_level) {
        return Err(InputError::Invalid(format!("adaptive level {max_level} is outside 1..=10")).into());
    }
    let n = 1u32 << max_level;
    let models: Vec<usize> = match only {
        Some(m) => vec![m],
        None => (0..surfaces.len()).collect(),
    };
    let verts_of: Vec<Vec<Vec<(Uv, P3)>>> = surfaces.iter().map(|s| s.vertices()).collect();
    let diag: Vec<f64> = meshes.iter().map(Mesh::bbox_diagonal).collect();
    // Refine by error, patch by patch, carrying each model's vertices down the tree.
    let mut leaves: Vec<Quad> = Vec::new();
    #[allow(clippy::needless_range_loop)] // p also names the quad in the tree
    for p in 0..layout.patches.len() {
        let all: Vec<Vec<u32>> = models.iter().map(|&m| (0..verts_of[m][p].len() as u32).collect()).collect();
        let mut stack = vec![(Quad { p: p as u32, i: 0, j: 0, s: n }, all)];
        while let Some((q, verts)) = stack.pop() {
            let mut err: f64 = 0.0;
            for (k, &m) in models.iter().enumerate() {
                let pts: Vec<P3> = verts[k].iter().map(|&v| verts_of[m][p][v as usize].1).collect();
                err = err.max(plane_error(&pts) / diag[m]);
            }
            if err <= epsilon || q.s == 1 {
                leaves.push(q);
                continue;
            }
            let h = q.s / 2;
            for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let c = Quad { p: q.p, i: q.i + di * h, j: q.j + dj * h, s: h };
                let (lo, hi) = (
                    [f64::from(c.i) / f64::from(n), f64::from(c.j) / f64::from(n)],
                    [f64::from(c.i + h) / f64::from(n), f64::from(c.j + h) / f64::from(n)],
                );
                let sub: Vec<Vec<u32>> = models
                    .iter()
                    .enumerate()
                    .map(|(k, &m)| {
                        verts[k]
                            .iter()
                            .copied()
                            .filter(|&v| {
                                let t = verts_of[m][p][v as usize].0;
                                t[0] >= lo[0] && t[0] <= hi[0] && t[1] >= lo[1] && t[1] <= hi[1]
                            })
                            .collect()
                    })
                    .collect();
                stack.push((c, sub));
            }
        }
    }
    let leaves = balance(layout, leaves, n);
    triangulate(layout, surfaces, &leaves, n)
}

/// [`adaptive_remesh_with`] over all models (consistent adaptive remeshing, `E_C`).
///
/// # Errors
/// As [`adaptive_remesh_with`].
pub fn adaptive_remesh(
    layout: &QuadLayout,
    surfaces: &[&dyn QuadSurface],
    meshes: &[Mesh],
    epsilon: f64,
    max_level: u32,
) -> Result<AdaptiveRemesh> {
    adaptive_remesh_with(layout, surfaces, meshes, epsilon, max_level, None)
}

fn key(layout: &QuadLayout, p: u32, i: u32, j: u32, n: u32) -> Key {
    grid_key(&layout.patches[p as usize], p, i as usize, j as usize, n as usize)
}

fn corners(q: &Quad) -> [(u32, u32); 4] {
    [(q.i, q.j), (q.i + q.s, q.j), (q.i + q.s, q.j + q.s), (q.i, q.j + q.s)]
}

/// Splits leaves until no leaf edge carries a neighbour's vertex at a quarter point (a level
/// difference of two or more).
fn balance(layout: &QuadLayout, mut leaves: Vec<Quad>, n: u32) -> Vec<Quad> {
    loop {
        let verts: HashSet<Key> =
            leaves.iter().flat_map(|q| corners(q).map(|(i, j)| key(layout, q.p, i, j, n))).collect();
        let mut next = Vec::with_capacity(leaves.len());
        let mut changed = false;
        for q in &leaves {
            let split = q.s >= 4 && {
                let c = corners(q);
                (0..4).any(|e| {
                    let (a, b) = (c[e], c[(e + 1) % 4]);
                    [1, 3].iter().any(|&k| {
                        let (i, j) = ((a.0 * (4 - k) + b.0 * k) / 4, (a.1 * (4 - k) + b.1 * k) / 4);
                        verts.contains(&key(layout, q.p, i, j, n))
                    })
                })
            };
            if split {
                changed = true;
                let h = q.s / 2;
                for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    next.push(Quad { p: q.p, i: q.i + di * h, j: q.j + dj * h, s: h });
                }
            } else {
                next.push(*q);
            }
        }
        leaves = next;
        if !changed {
            return leaves;
        }
    }
}

fn triangulate(layout: &QuadLayout, surfaces: &[&dyn QuadSurface], leaves: &[Quad], n: u32) -> Result<AdaptiveRemesh> {
    let verts: HashSet<Key> = leaves.iter().flat_map(|q| corners(q).map(|(i, j)| key(layout, q.p, i, j, n))).collect();
    let mut ids: HashMap<Key, u32> = HashMap::new();
    let mut owner: Vec<(u32, u32, u32)> = Vec::new();
    let mut id = |p: u32, i: u32, j: u32| -> u32 {
        let k = key(layout, p, i, j, n);
        *ids.entry(k).or_insert_with(|| {
            owner.push((p, i, j));
            (owner.len() - 1) as u32
        })
    };
    let mut faces = Vec::new();
    for q in leaves {
        let c = corners(q);
        let mut ring = Vec::with_capacity(8);
        let mut has_mid = false;
        for e in 0..4 {
            ring.push(c[e]);
            let (a, b) = (c[e], c[(e + 1) % 4]);
            if q.s >= 2 {
                let m = ((a.0 + b.0) / 2, (a.1 + b.1) / 2);
                if verts.contains(&key(layout, q.p, m.0, m.1, n)) {
                    ring.push(m);
                    has_mid = true;
                }
            }
        }
        if has_mid {
            let centre = id(q.p, q.i + q.s / 2, q.j + q.s / 2);
            let r: Vec<u32> = ring.iter().map(|&(i, j)| id(q.p, i, j)).collect();
            for k in 0..r.len() {
                faces.push([centre, r[k], r[(k + 1) % r.len()]]);
            }
        } else {
            let [a, b, cc, d] = c.map(|(i, j)| id(q.p, i, j));
            // Split through the nearest corner of the square (see the uniform grid).
            let h = n / 2;
            if (q.i < h) == (q.j < h) {
                faces.push([a, b, cc]);
                faces.push([a, cc, d]);
            } else {
                faces.push([a, b, d]);
                faces.push([b, cc, d]);
            }
        }
    }
    let positions = surfaces
        .iter()
        .map(|surf| {
            owner
                .iter()
                .map(|&(p, i, j)| surf.sample(p as usize, [f64::from(i) / f64::from(n), f64::from(j) / f64::from(n)]).0)
                .collect()
        })
        .collect();
    Ok(AdaptiveRemesh { faces, quads: leaves.len(), positions })
}
