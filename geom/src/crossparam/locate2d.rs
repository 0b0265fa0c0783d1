//! Point location in a planar triangulation through a uniform grid of triangle bounding boxes.
//! Among the triangles of the query's cell the one with the largest smallest barycentric
//! coordinate wins, so points on shared edges or on the domain's boundary (where rounding
//! leaves coordinates of -1e-17) are still found.

use crate::param::Uv;

/// A grid over the triangles of a planar mesh.
pub struct Grid {
    lo: Uv,
    cell: f64,
    nx: usize,
    ny: usize,
    cells: Vec<Vec<u32>>,
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
        Grid { lo, cell, nx, ny, cells }
    }

    /// The triangle containing `p` (or nearest to containing it) and its barycentric
    /// coordinates, clamped to be non-negative and to sum to 1.
    pub fn locate(&self, uv: &[Uv], tris: &[[u32; 3]], p: Uv) -> (u32, [f64; 3]) {
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
