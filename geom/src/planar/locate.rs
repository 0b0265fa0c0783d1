//! Point location in a planar triangulation. A query starts at the triangle whose centroid is
//! nearest (k-d tree, `kiddo`) and walks towards the point across the edge opposite its most
//! negative barycentric coordinate (a visibility walk, Devillers–Pion–Teillaud 2002), which
//! ends in a few steps however unevenly the triangles are spread (a harmonic disk map squeezes
//! protrusions by orders of magnitude, so a uniform grid's cells there hold thousands). When the
//! walk leaves the domain, revisits a triangle or runs long, a uniform grid of triangle bounding
//! boxes answers instead: among the triangles of the query's cell the one with the largest
//! smallest barycentric coordinate wins, so points on shared edges or on the domain's boundary
//! (where rounding leaves coordinates of -1e-17) are still found.

use crate::param::Uv;
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use std::collections::HashMap;

/// Walk steps before the grid takes over.
const MAX_WALK: usize = 256;

/// A point locator over the triangles of a planar mesh.
pub struct Grid {
    lo: Uv,
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
    /// Per triangle, the triangle across the edge opposite corner `k` (`u32::MAX`: none).
    adj: Vec<[u32; 3]>,
    /// Triangle centroids (`None` without triangles).
    tree: Option<ImmutableKdTree<f64, 2>>,
}

/// Barycentric coordinates of `p` in triangle `t`.
pub fn barycentric(t: [Uv; 3], p: Uv) -> [f64; 3] {
    let [a, b, c] = t;
    let d = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
    if d == 0.0 {
        return [f64::NEG_INFINITY; 3];
    }
    let l1 = ((p[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (p[1] - a[1])) / d;
    let l2 = ((b[0] - a[0]) * (p[1] - a[1]) - (p[0] - a[0]) * (b[1] - a[1])) / d;
    [1.0 - l1 - l2, l1, l2]
}

impl Grid {
    /// Indexes triangles `tris` over positions `uv`.
    pub fn new(uv: &[Uv], tris: &[[u32; 3]]) -> Grid {
        let mut lo = [f64::INFINITY; 2];
        let mut hi = [f64::NEG_INFINITY; 2];
        for p in uv {
            for k in 0..2 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let w = (hi[0] - lo[0]).max(1e-300);
        let h = (hi[1] - lo[1]).max(1e-300);
        let n = (tris.len() as f64).sqrt().ceil().max(1.0);
        let cell = (w.max(h) / n).max(1e-300);
        let nx = ((w / cell).ceil() as usize).clamp(1, 4096);
        let ny = ((h / cell).ceil() as usize).clamp(1, 4096);
        let mut cells = vec![Vec::new(); nx * ny];
        let idx = |x: f64, n: usize| (x.max(0.0) as usize).min(n - 1);
        for (f, t) in tris.iter().enumerate() {
            let ps = t.map(|v| uv[v as usize]);
            let (mut a, mut b) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
            for p in ps {
                for k in 0..2 {
                    a[k] = a[k].min(p[k]);
                    b[k] = b[k].max(p[k]);
                }
            }
            let (x0, x1) = (idx((a[0] - lo[0]) / cell, nx), idx((b[0] - lo[0]) / cell, nx));
            let (y0, y1) = (idx((a[1] - lo[1]) / cell, ny), idx((b[1] - lo[1]) / cell, ny));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    cells[y * nx + x].push(f as u32);
                }
            }
        }
        let mut adj = vec![[u32::MAX; 3]; tris.len()];
        let mut open: HashMap<(u32, u32), (u32, usize)> = HashMap::with_capacity(tris.len() * 2);
        for (f, t) in tris.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (t[(k + 1) % 3], t[(k + 2) % 3]);
                match open.remove(&(b, a)) {
                    Some((g, j)) => {
                        adj[f][k] = g;
                        adj[g as usize][j] = f as u32;
                    }
                    None => {
                        open.insert((a, b), (f as u32, k));
                    }
                }
            }
        }
        let cents: Vec<[f64; 2]> = tris
            .iter()
            .map(|t| {
                let p = t.map(|v| uv[v as usize]);
                [(p[0][0] + p[1][0] + p[2][0]) / 3.0, (p[0][1] + p[1][1] + p[2][1]) / 3.0]
            })
            .collect();
        let tree = ImmutableKdTree::new_from_slice(&cents).ok();
        Grid { lo, cell, nx, ny, cells, adj, tree }
    }

    /// The containing triangle reached by walking from the nearest centroid, if the walk finds
    /// one within [`MAX_WALK`] steps without leaving the domain.
    fn walk(&self, uv: &[Uv], tris: &[[u32; 3]], p: Uv, slab: bool) -> Option<(u32, [f64; 3])> {
        let tree = self.tree.as_ref()?;
        let mut f = tree.query(&p).nearest_one::<SquaredEuclidean<f64>>().execute().item as usize;
        let mut prev = u32::MAX;
        for _ in 0..MAX_WALK {
            let t = tris.get(f)?;
            let b = barycentric(t.map(|v| uv[v as usize]), p);
            let k = (0..3).min_by(|&i, &j| b[i].total_cmp(&b[j]))?;
            if b[k] >= 0.0 {
                return Some((f as u32, b));
            }
            let g = self.adj[f][k];
            if g == u32::MAX {
                // Beyond a boundary edge and within its slab (a point on the domain's boundary
                // curve just outside the chord, or rounding): the clamped point on the edge.
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                if b[i] < 0.0 || b[j] < 0.0 || !b[k].is_finite() || (!slab && b[k] < -1e-12) {
                    return None;
                }
                let mut c = [0.0; 3];
                (c[i], c[j]) = (b[i] / (b[i] + b[j]), b[j] / (b[i] + b[j]));
                return Some((f as u32, c));
            }
            if g == prev || !b[k].is_finite() {
                return None;
            }
            prev = f as u32;
            f = g as usize;
        }
        None
    }

    /// The triangle containing `p` when a walk reaches it: `None` for a point outside the
    /// domain (and, rarely, for one the walk cannot reach across a concave boundary).
    pub fn locate_inside(&self, uv: &[Uv], tris: &[[u32; 3]], p: Uv) -> Option<(u32, [f64; 3])> {
        self.walk(uv, tris, p, false)
    }

    /// The triangle containing `p` (or nearest to containing it) and its barycentric
    /// coordinates, clamped to be non-negative and to sum to 1.
    pub fn locate(&self, uv: &[Uv], tris: &[[u32; 3]], p: Uv) -> (u32, [f64; 3]) {
        if let Some(hit) = self.walk(uv, tris, p, true) {
            return hit;
        }
        let cx = (((p[0] - self.lo[0]) / self.cell).max(0.0) as usize).min(self.nx - 1);
        let cy = (((p[1] - self.lo[1]) / self.cell).max(0.0) as usize).min(self.ny - 1);
        let mut best = (f64::NEG_INFINITY, 0u32, [1.0, 0.0, 0.0]);
        let scan = |r: usize, best: &mut (f64, u32, [f64; 3])| {
            let (x0, x1) = (cx.saturating_sub(r), (cx + r).min(self.nx - 1));
            let (y0, y1) = (cy.saturating_sub(r), (cy + r).min(self.ny - 1));
            for y in y0..=y1 {
                for x in x0..=x1 {
                    for &f in &self.cells[y * self.nx + x] {
                        let b = barycentric(tris[f as usize].map(|v| uv[v as usize]), p);
                        let m = b[0].min(b[1]).min(b[2]);
                        if m > best.0 {
                            *best = (m, f, b);
                        }
                    }
                }
            }
        };
        let mut r = 0;
        scan(r, &mut best);
        while best.0 < -1e-9 && r < self.nx.max(self.ny) {
            r = (r * 2).max(1);
            scan(r, &mut best);
        }
        let mut b = best.2.map(|x| x.max(0.0));
        let s: f64 = b.iter().sum();
        if s > 0.0 {
            b = b.map(|x| x / s);
        }
        (best.1, b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A polar grid on the unit disk whose rings crowd towards the centre geometrically (as a
    /// harmonic map crowds a protrusion): radii 2^-k.
    fn crowded_disk(rings: usize, sectors: usize) -> (Vec<Uv>, Vec<[u32; 3]>) {
        let mut uv = vec![[0.0, 0.0]];
        for k in 0..rings {
            let r = 0.5f64.powi((rings - 1 - k) as i32);
            for j in 0..sectors {
                let a = std::f64::consts::TAU * j as f64 / sectors as f64;
                uv.push([r * a.cos(), r * a.sin()]);
            }
        }
        let at = |k: usize, j: usize| (1 + k * sectors + j % sectors) as u32;
        let mut tris = Vec::new();
        for j in 0..sectors {
            tris.push([0, at(0, j), at(0, j + 1)]);
        }
        for k in 0..rings - 1 {
            for j in 0..sectors {
                tris.push([at(k, j), at(k + 1, j), at(k + 1, j + 1)]);
                tris.push([at(k, j), at(k + 1, j + 1), at(k, j + 1)]);
            }
        }
        (uv, tris)
    }

    #[test]
    fn located_triangles_contain_their_points_at_every_scale() {
        let (uv, tris) = crowded_disk(24, 32);
        let grid = Grid::new(&uv, &tris);
        let mut n = 0;
        for k in 0..23 {
            for j in 0..7 {
                let r = 0.5f64.powi(k) * 0.93;
                let a = 0.37 + j as f64 * 0.9;
                let p = [r * a.cos(), r * a.sin()];
                let (f, b) = grid.locate(&uv, &tris, p);
                let exact = barycentric(tris[f as usize].map(|v| uv[v as usize]), p);
                assert!(exact.iter().all(|&x| x >= -1e-12), "{p:?} in {f}: {exact:?}");
                assert!((b.iter().sum::<f64>() - 1.0).abs() < 1e-12);
                n += 1;
            }
        }
        assert_eq!(n, 23 * 7);
    }

    #[test]
    fn points_just_outside_a_boundary_chord_land_on_it() {
        let (uv, tris) = crowded_disk(6, 16);
        let grid = Grid::new(&uv, &tris);
        // On the unit circle half-way between two boundary vertices: outside the chord, found on
        // it near its middle (clamped as the grid clamps: negative coordinates dropped).
        let a = std::f64::consts::TAU * 2.5 / 16.0;
        let (f, b) = grid.locate(&uv, &tris, [a.cos(), a.sin()]);
        let t = tris[f as usize];
        let on: Vec<usize> = (0..3).filter(|&k| b[k] > 0.0).collect();
        assert_eq!(on.len(), 2, "{b:?}");
        for k in on {
            assert!((uv[t[k] as usize][0].hypot(uv[t[k] as usize][1]) - 1.0).abs() < 1e-12);
            assert!((b[k] - 0.5).abs() < 0.05, "{b:?}");
        }
    }
}
