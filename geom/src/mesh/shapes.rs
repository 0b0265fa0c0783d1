//! Meshes built in code, for tests and benchmarks: tetrahedron, icosphere (also with holes), torus, grid disk,
//! Loop-free midpoint subdivision (each triangle into four) of any mesh, and the vertex farthest
//! along a direction (tests pick landmarks with it).

use super::{Mesh, P3, VertexId};
use std::collections::HashMap;

fn build(pos: Vec<P3>, tris: &[[u32; 3]]) -> Mesh {
    // Shapes are valid by construction; a failure here is a bug in this file.
    match Mesh::from_triangles(pos, tris) {
        Ok(m) => m,
        Err(e) => panic!("shape construction failed: {e}"),
    }
}

/// An icosphere (`k` subdivisions) with the faces around each vertex of `around` removed: one
/// boundary loop per vertex (they must lie at least two rings apart). Open-mesh tests use it.
pub fn icosphere_with_holes(k: usize, around: &[u32]) -> Mesh {
    let s = icosphere(k);
    let keep: Vec<[u32; 3]> =
        s.faces().iter().filter(|f| !f.iter().any(|v| around.contains(&v.0))).map(|f| f.map(|v| v.0)).collect();
    build(s.positions().to_vec(), &keep)
}

/// A regular tetrahedron (genus 0, 4 vertices).
pub fn tetrahedron() -> Mesh {
    let p = vec![P3::new(1., 1., 1.), P3::new(1., -1., -1.), P3::new(-1., 1., -1.), P3::new(-1., -1., 1.)];
    build(p, &[[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
}

/// An icosphere: the icosahedron subdivided `k` times and projected to the unit sphere.
pub fn icosphere(k: usize) -> Mesh {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut pos: Vec<P3> = [
        [-1., t, 0.],
        [1., t, 0.],
        [-1., -t, 0.],
        [1., -t, 0.],
        [0., -1., t],
        [0., 1., t],
        [0., -1., -t],
        [0., 1., -t],
        [t, 0., -1.],
        [t, 0., 1.],
        [-t, 0., -1.],
        [-t, 0., 1.],
    ]
    .iter()
    .map(|p| P3::from(nalgebra::Vector3::new(p[0], p[1], p[2]).normalize()))
    .collect();
    let mut tris: Vec<[u32; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..k {
        (pos, tris) = midpoint_subdivide(&pos, &tris);
        for p in &mut pos {
            *p = P3::from(p.coords.normalize());
        }
    }
    build(pos, &tris)
}

/// An icosphere stretched, squashed and twisted about its axis (the same connectivity as
/// [`icosphere`]`(k)`): a smooth genus-0 deformation to map a sphere onto.
pub fn twisted_icosphere(k: usize) -> Mesh {
    let m = icosphere(k);
    let pos: Vec<P3> = m
        .positions()
        .iter()
        .map(|p| {
            let a = 0.8 * p.z;
            let (x, y) = (p.x * a.cos() - p.y * a.sin(), p.x * a.sin() + p.y * a.cos());
            P3::new(1.6 * x, 0.9 * y, 0.7 * p.z)
        })
        .collect();
    build(pos, &m.face_indices())
}

/// A torus with `n` segments around the big circle and `m` around the tube.
pub fn torus(n: usize, m: usize, big_r: f64, small_r: f64) -> Mesh {
    let mut pos = Vec::with_capacity(n * m);
    for i in 0..n {
        let u = i as f64 / n as f64 * std::f64::consts::TAU;
        for j in 0..m {
            let v = j as f64 / m as f64 * std::f64::consts::TAU;
            let r = big_r + small_r * v.cos();
            pos.push(P3::new(r * u.cos(), r * u.sin(), small_r * v.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let mut tris = Vec::with_capacity(2 * n * m);
    for i in 0..n {
        for j in 0..m {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    build(pos, &tris)
}

/// A flat `n` x `n` grid of squares over [0,1]^2, each split into two triangles (a disk).
pub fn grid(n: usize) -> Mesh {
    let mut pos = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            pos.push(P3::new(i as f64 / n as f64, j as f64 / n as f64, 0.0));
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let mut tris = Vec::with_capacity(2 * n * n);
    for j in 0..n {
        for i in 0..n {
            tris.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            tris.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    build(pos, &tris)
}

/// Splits every triangle into four at edge midpoints (positions only; no smoothing).
pub fn midpoint_subdivide(pos: &[P3], tris: &[[u32; 3]]) -> (Vec<P3>, Vec<[u32; 3]>) {
    let mut pos = pos.to_vec();
    let mut mid: HashMap<(u32, u32), u32> = HashMap::with_capacity(tris.len() * 3 / 2);
    let mut out = Vec::with_capacity(tris.len() * 4);
    let mut midpoint = |a: u32, b: u32, pos: &mut Vec<P3>| -> u32 {
        let key = (a.min(b), a.max(b));
        *mid.entry(key).or_insert_with(|| {
            pos.push(P3::from((pos[a as usize].coords + pos[b as usize].coords) * 0.5));
            (pos.len() - 1) as u32
        })
    };
    for &[a, b, c] in tris {
        let ab = midpoint(a, b, &mut pos);
        let bc = midpoint(b, c, &mut pos);
        let ca = midpoint(c, a, &mut pos);
        out.extend_from_slice(&[[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
    }
    (pos, out)
}

/// Subdivides a mesh `k` times by [`midpoint_subdivide`] (for tests and benchmarks).
pub fn subdivide(mesh: &Mesh, k: usize) -> Mesh {
    match try_subdivide(mesh, k) {
        Ok(m) => m,
        Err(e) => panic!("subdivision of a valid mesh failed: {e}"),
    }
}

/// Subdivides a mesh `k` times by [`midpoint_subdivide`], as a fallible call for user input.
///
/// # Errors
/// `InputError::TooLarge` when the result would exceed the default face limit; any
/// construction error (none is expected for a valid input mesh).
pub fn try_subdivide(mesh: &Mesh, k: usize) -> crate::Result<Mesh> {
    let faces = (mesh.n_faces() as u64).saturating_mul(4u64.saturating_pow(k.min(32) as u32));
    let limit = super::MeshLimits::default().max_faces;
    if faces > limit {
        return Err(crate::InputError::TooLarge { what: "faces after subdivision", count: faces, limit }.into());
    }
    let mut pos = mesh.positions().to_vec();
    let mut tris = mesh.face_indices();
    for _ in 0..k {
        (pos, tris) = midpoint_subdivide(&pos, &tris);
    }
    Mesh::from_triangles(pos, &tris)
}

/// The vertex farthest along `dir` (the first of ties); vertex 0 for an empty mesh.
pub fn extreme_vertex(m: &Mesh, dir: [f64; 3]) -> VertexId {
    let d = nalgebra::Vector3::from(dir);
    let i = (0..m.n_vertices())
        .max_by(|&a, &b| m.positions()[a].coords.dot(&d).total_cmp(&m.positions()[b].coords.dot(&d)));
    VertexId::from_idx(i.unwrap_or(0))
}
