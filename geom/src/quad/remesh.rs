//! Uniform semi-regular remeshing (Yu & Chuang, section 4): level `n` samples every patch's
//! unit square at `(2^n + 1)²` grid points and splits every grid cell into two triangles.
//! Grid points on a patch side are named by their layout curve and their index along it, and
//! corners by their layout corner, so patches sharing a side share its vertices and the
//! connectivity depends on the layout and the level alone: identical for every model.
//! Positions come from point location in each patch's parameterization (a uniform grid over the
//! parameter triangles), and each shared point is computed once.

use super::layout::QuadLayout;
use super::partition::PatchMesh;
use crate::crossparam::locate2d::Grid;
use crate::error::{Error, InputError, Result};
use crate::mesh::{P3, V3};
use crate::param::Uv;
use std::collections::HashMap;

/// Highest remeshing level accepted (level 0 would glue two faces onto two) (`2 · 4^10` triangles per patch).
pub const MAX_LEVEL: u32 = 10;

/// Connectivity of a uniform remesh.
#[derive(Debug, Clone)]
pub struct RemeshGrid {
    pub level: u32,
    /// Grid cells per side, `2^level`.
    pub n: usize,
    /// Per patch, the remesh vertex of grid point `(i, j)` at `j * (n + 1) + i`.
    pub node: Vec<Vec<u32>>,
    /// Per remesh vertex, the first `(patch, i, j)` that names it.
    pub owner: Vec<(u32, u32, u32)>,
    pub faces: Vec<[u32; 3]>,
}

/// Name of a lattice point shared by every patch that holds it.
#[derive(Debug, Clone, Copy, Hash, PartialEq, Eq)]
pub enum Key {
    Corner(u32),
    Curve(u32, u32),
    Inner(u32, u32, u32),
}

/// The connectivity of level `level` over `layout`.
///
/// # Errors
/// `InputError::Invalid` for a level above [`MAX_LEVEL`].
pub fn uniform_grid(layout: &QuadLayout, level: u32) -> Result<RemeshGrid> {
    if !(1..=MAX_LEVEL).contains(&level) {
        return Err(InputError::Invalid(format!("remesh level {level} is outside 1..={MAX_LEVEL}")).into());
    }
    let n = 1usize << level;
    let m = n + 1;
    let mut ids: HashMap<Key, u32> = HashMap::with_capacity(layout.patches.len() * m * m);
    let mut owner = Vec::with_capacity(layout.patches.len() * m * m);
    let mut node = Vec::with_capacity(layout.patches.len());
    for (p, pl) in layout.patches.iter().enumerate() {
        let mut nd = Vec::with_capacity(m * m);
        for j in 0..m {
            for i in 0..m {
                let key = grid_key(pl, p as u32, i, j, n);
                let next = owner.len() as u32;
                let id = *ids.entry(key).or_insert(next);
                if id == next {
                    owner.push((p as u32, i as u32, j as u32));
                }
                nd.push(id);
            }
        }
        node.push(nd);
    }
    let mut faces = Vec::with_capacity(layout.patches.len() * 2 * n * n);
    for nd in &node {
        for j in 0..n {
            for i in 0..n {
                let (a, b, c, d) = (nd[j * m + i], nd[j * m + i + 1], nd[(j + 1) * m + i + 1], nd[(j + 1) * m + i]);
                // Diagonals point at the nearest square corner, so a corner cell is split
                // through its corner: otherwise both patches at a corner would hold a triangle
                // on the same three boundary points.
                if (i < n / 2) == (j < n / 2) {
                    faces.push([a, b, c]);
                    faces.push([a, c, d]);
                } else {
                    faces.push([a, b, d]);
                    faces.push([b, c, d]);
                }
            }
        }
    }
    Ok(RemeshGrid { level, n, node, owner, faces })
}

/// Which side (and position along it, in grid steps from the side's start) grid point `(i, j)`
/// lies on; corners first.
pub fn grid_key(pl: &super::layout::QuadPatchLayout, p: u32, i: usize, j: usize, n: usize) -> Key {
    let corner = match (i, j) {
        (0, 0) => Some(0),
        (x, 0) if x == n => Some(1),
        (x, y) if x == n && y == n => Some(2),
        (0, y) if y == n => Some(3),
        _ => None,
    };
    if let Some(k) = corner {
        return Key::Corner(pl.corners[k]);
    }
    let side = if j == 0 {
        Some((0, i))
    } else if i == n {
        Some((1, j))
    } else if j == n {
        Some((2, n - i))
    } else if i == 0 {
        Some((3, n - j))
    } else {
        None
    };
    match side {
        Some((k, s)) => {
            let sd = pl.sides[k];
            Key::Curve(sd.curve, if sd.reversed { (n - s) as u32 } else { s as u32 })
        }
        None => Key::Inner(p, i as u32, j as u32),
    }
}

/// Positions of the remesh vertices of one model, from its patches and their parameterizations.
///
/// # Errors
/// `Internal` when the patch count does not match the layout.
pub fn sample_uniform(grid: &RemeshGrid, patches: &[PatchMesh], uvs: &[Vec<Uv>]) -> Result<Vec<P3>> {
    Ok(sample(grid, patches, uvs, false)?.0)
}

/// Positions and unit normals (area-weighted vertex normals of the original surface,
/// interpolated) at the remesh vertices.
///
/// # Errors
/// As [`sample_uniform`].
pub fn sample_with_normals(grid: &RemeshGrid, patches: &[PatchMesh], uvs: &[Vec<Uv>]) -> Result<(Vec<P3>, Vec<V3>)> {
    sample(grid, patches, uvs, true)
}

fn vertex_normals(m: &crate::Mesh) -> Vec<V3> {
    let mut n = vec![V3::zeros(); m.n_vertices()];
    for (f, t) in m.faces().iter().enumerate() {
        let w = m.face_normal_raw(crate::FaceId::from_idx(f));
        for v in t {
            n[v.idx()] += w;
        }
    }
    n.iter().map(|x| x.try_normalize(0.0).unwrap_or_else(V3::z)).collect()
}

fn sample(grid: &RemeshGrid, patches: &[PatchMesh], uvs: &[Vec<Uv>], normals: bool) -> Result<(Vec<P3>, Vec<V3>)> {
    if patches.len() != grid.node.len() || uvs.len() != patches.len() {
        return Err(Error::Internal(format!("{} patches for a layout of {}", patches.len(), grid.node.len())));
    }
    let tris: Vec<Vec<[u32; 3]>> = patches.iter().map(|p| p.mesh.face_indices()).collect();
    let locators: Vec<Grid> = uvs.iter().zip(&tris).map(|(uv, t)| Grid::new(uv, t)).collect();
    let vn: Vec<Vec<V3>> = if normals { patches.iter().map(|p| vertex_normals(&p.mesh)).collect() } else { Vec::new() };
    let n = grid.n as f64;
    let mut pos = Vec::with_capacity(grid.owner.len());
    let mut nor = Vec::with_capacity(if normals { grid.owner.len() } else { 0 });
    for &(p, i, j) in &grid.owner {
        let p = p as usize;
        let q = [f64::from(i) / n, f64::from(j) / n];
        let (f, b) = locators[p].locate(&uvs[p], &tris[p], q);
        let t = tris[p][f as usize];
        let x = t.map(|v| patches[p].mesh.positions()[v as usize]);
        pos.push(P3::from(x[0].coords * b[0] + x[1].coords * b[1] + x[2].coords * b[2]));
        if normals {
            let m = t.map(|v| vn[p][v as usize]);
            nor.push((m[0] * b[0] + m[1] * b[1] + m[2] * b[2]).try_normalize(0.0).unwrap_or_else(V3::z));
        }
    }
    Ok((pos, nor))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn genus0_grid_is_a_closed_sphere_with_the_expected_counts() {
        for level in 1..6 {
            let g = uniform_grid(&QuadLayout::genus0(), level).unwrap();
            let n = 1usize << level;
            // Two squares glued along their boundary: 2 (n+1)^2 - 4n vertices, 4 n^2 triangles.
            assert_eq!(g.owner.len(), 2 * (n + 1) * (n + 1) - 4 * n);
            assert_eq!(g.faces.len(), 4 * n * n);
            {
                let pos = (0..g.owner.len()).map(|i| P3::new(i as f64, (i * i) as f64, 1.0)).collect();
                let m = crate::Mesh::from_triangles(pos, &g.faces).expect("manifold");
                let s = crate::topology::summary(&m);
                assert_eq!((s.genus, s.boundary_loops, s.components), (0, 0, 1));
            }
        }
        assert!(uniform_grid(&QuadLayout::genus0(), MAX_LEVEL + 1).is_err());
        assert!(uniform_grid(&QuadLayout::genus0(), 0).is_err());
    }
}
