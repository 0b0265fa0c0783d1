//! Uniform semi-regular remeshing (Yu & Chuang, section 4): level `n` samples every patch's
//! unit square at `(2^n + 1)²` grid points and splits every grid cell into two triangles.
//! Grid points on a patch side are named by their layout curve and their index along it, and
//! corners by their layout corner, so patches sharing a side share its vertices and the
//! connectivity depends on the layout and the level alone: identical for every model.
//! Positions come from each model's [`QuadSurface`], and each shared point is computed once.

use super::layout::QuadLayout;
use super::surface::QuadSurface;
use crate::error::{Error, InputError, Result};
use crate::mesh::{P3, V3};
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

/// Positions of the remesh vertices of one model.
///
/// # Errors
/// `Internal` when the model's quad count does not match the layout.
pub fn sample_uniform(grid: &RemeshGrid, surf: &dyn QuadSurface) -> Result<Vec<P3>> {
    Ok(sample_with_normals(grid, surf)?.0)
}

/// Positions and unit normals at the remesh vertices.
///
/// # Errors
/// As [`sample_uniform`].
pub fn sample_with_normals(grid: &RemeshGrid, surf: &dyn QuadSurface) -> Result<(Vec<P3>, Vec<V3>)> {
    if surf.n_quads() != grid.node.len() {
        return Err(Error::Internal(format!("{} quads for a layout of {}", surf.n_quads(), grid.node.len())));
    }
    let n = grid.n as f64;
    Ok(grid.owner.iter().map(|&(p, i, j)| surf.sample(p as usize, [f64::from(i) / n, f64::from(j) / n])).unzip())
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
