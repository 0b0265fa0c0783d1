//! Vertex-by-vertex geometric-stretch optimization of a planar embedding (Sander, Snyder,
//! Gortler & Hoppe, "Texture mapping progressive meshes", SIGGRAPH 2001, as Yu & Chuang use it
//! in section 3.3.2). The energy of a vertex is the L2 stretch of its star,
//! `Σ A3(T) (|S_s|² + |S_t|²) / 2` over its triangles; it grows without bound as a triangle's
//! parameter area goes to zero, so no step can fold a triangle. A vertex moves along random
//! directions, each time to the minimum found by Brent's bracketed parabolic search inside the
//! interval where every incident triangle keeps a positive parameter area. Vertices are visited
//! worst first (largest star stretch) in sweeps until the largest move is below a tolerance.
//!
//! The state is a face soup with liveness flags and vertex–face incidence, so the progressive
//! mesh replay (`coarse_to_fine`) can add vertices and faces between optimizations.

use crate::mesh::P3;
use crate::param::{self, Uv};
use rand::Rng;
use rand_pcg::Pcg64Mcg;

/// An embedding being optimized.
pub struct ParamState {
    pub pos: Vec<P3>,
    pub uv: Vec<Uv>,
    pub faces: Vec<[u32; 3]>,
    pub alive: Vec<bool>,
    /// Live faces around each vertex.
    pub vf: Vec<Vec<u32>>,
    /// Vertices that never move (boundary, aligned features).
    pub fixed: Vec<bool>,
    /// Vertices currently in the mesh.
    pub active: Vec<bool>,
    rng: Pcg64Mcg,
}

pub use crate::planar::area2;

/// `(|S_s|², |S_t|², S_s·S_t)` of a positively oriented triangle ([`param::stretch_jacobian`]).
#[inline]
fn jacobian(p: [P3; 3], q: [Uv; 3]) -> Option<(f64, f64, f64)> {
    let (ss, st, a2) = param::stretch_jacobian(p, q)?;
    (a2 > 0.0).then(|| (ss.norm_squared(), st.norm_squared(), ss.dot(&st)))
}

/// L2 and L∞ stretch of one triangle (`None` when folded or flat in the plane).
pub fn triangle_stretch(p: [P3; 3], q: [Uv; 3]) -> Option<(f64, f64)> {
    let (a, c, b) = jacobian(p, q)?;
    let l2 = ((a + c) / 2.0).sqrt();
    let linf = (((a + c) + ((a - c).powi(2) + 4.0 * b * b).sqrt()) / 2.0).sqrt();
    Some((l2, linf))
}

/// Normalized L2 and L∞ stretch of a whole embedding (Sander et al.: parameter area scaled to
/// the surface area, so 1 is an isometry and larger is worse). Triangles with no positive
/// parameter area have no finite stretch and are left out (callers count them separately);
/// `inf` when no triangle is left.
pub fn mesh_stretch(pos: &[P3], uv: &[Uv], faces: impl Iterator<Item = [u32; 3]>) -> (f64, f64) {
    let (mut num, mut area3, mut area_uv, mut linf) = (0.0, 0.0, 0.0, 0.0f64);
    for t in faces {
        let p = t.map(|v| pos[v as usize]);
        let q = t.map(|v| uv[v as usize]);
        let Some((l2, li)) = triangle_stretch(p, q) else { continue };
        let a3 = 0.5 * (p[1] - p[0]).cross(&(p[2] - p[0])).norm();
        num += l2 * l2 * a3;
        area3 += a3;
        area_uv += area2(q[0], q[1], q[2]) / 2.0;
        linf = linf.max(li);
    }
    if area3 <= 0.0 {
        return (f64::INFINITY, f64::INFINITY);
    }
    let scale = (area_uv / area3).sqrt();
    ((num / area3).sqrt() * scale, linf * scale)
}

/// Several patches' maps before and after an optimization, gathered to measure their stretch
/// together ([`mesh_stretch`] over all of them).
#[derive(Debug, Default)]
pub struct PatchSoup {
    pos: Vec<P3>,
    before: Vec<Uv>,
    after: Vec<Uv>,
    tris: Vec<[u32; 3]>,
}

impl PatchSoup {
    pub fn add(&mut self, pos: &[P3], tris: &[[u32; 3]], before: &[Uv], after: &[Uv]) {
        let off = self.pos.len() as u32;
        self.pos.extend_from_slice(pos);
        self.before.extend_from_slice(before);
        self.after.extend_from_slice(after);
        self.tris.extend(tris.iter().map(|t| t.map(|v| v + off)));
    }

    /// Normalized (L2, L∞) stretch before and after.
    pub fn stretch(&self) -> ((f64, f64), (f64, f64)) {
        let s = |uv: &[Uv]| mesh_stretch(&self.pos, uv, self.tris.iter().copied());
        (s(&self.before), s(&self.after))
    }
}

/// Options of [`ParamState::optimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StretchOptOptions {
    /// Stop when no vertex moved farther than this in a sweep (the square is the unit square).
    pub tolerance: f64,
    /// Sweeps at most.
    pub max_sweeps: usize,
    /// Random line-search directions per vertex visit.
    pub directions: usize,
}

impl Default for StretchOptOptions {
    fn default() -> Self {
        Self { tolerance: 1e-3, max_sweeps: 12, directions: 2 }
    }
}

impl ParamState {
    pub fn new(pos: Vec<P3>, uv: Vec<Uv>, faces: Vec<[u32; 3]>, alive: Vec<bool>, fixed: Vec<bool>, seed: u64) -> Self {
        let n = pos.len();
        let mut vf = vec![Vec::new(); n];
        let mut active = vec![false; n];
        for (f, t) in faces.iter().enumerate() {
            if alive[f] {
                for &v in t {
                    vf[v as usize].push(f as u32);
                    active[v as usize] = true;
                }
            }
        }
        ParamState { pos, uv, faces, alive, vf, fixed, active, rng: rand::SeedableRng::seed_from_u64(seed) }
    }

    /// Stretch energy of the star of `u` with `u` placed at `p` (`inf` if a triangle folds).
    pub fn star_energy(&self, u: u32, p: Uv) -> f64 {
        let mut e = 0.0;
        for &f in &self.vf[u as usize] {
            let t = self.faces[f as usize];
            let q = t.map(|w| if w == u { p } else { self.uv[w as usize] });
            let x = t.map(|w| self.pos[w as usize]);
            let a3 = 0.5 * (x[1] - x[0]).cross(&(x[2] - x[0])).norm();
            match jacobian(x, q) {
                Some((a, c, _)) => e += a3 * (a + c) / 2.0,
                None => return f64::INFINITY,
            }
        }
        e
    }

    /// The link of `u`: per live face around it, its other two corners, counter-clockwise.
    pub fn link(&self, u: u32) -> impl Iterator<Item = [u32; 2]> + '_ {
        self.vf[u as usize].iter().map(move |&f| {
            let t = self.faces[f as usize];
            let k = t.iter().position(|&w| w == u).unwrap_or(0);
            [t[(k + 1) % 3], t[(k + 2) % 3]]
        })
    }

    /// The link of `u` in the plane, for [`super::kernel::kernel_centroid`].
    pub fn link_uv(&self, u: u32) -> Vec<(Uv, Uv)> {
        self.link(u).map(|[a, b]| (self.uv[a as usize], self.uv[b as usize])).collect()
    }

    /// Steps `t` along `d` from the current position that keep every star triangle positive.
    fn feasible(&self, u: u32, d: Uv) -> (f64, f64) {
        let p = self.uv[u as usize];
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for [a, b] in self.link(u) {
            let (a, b) = (self.uv[a as usize], self.uv[b as usize]);
            let area = area2(p, a, b);
            // d/dp of area2(p, a, b) = (a_y - b_y, b_x - a_x).
            let slope = (a[1] - b[1]) * d[0] + (b[0] - a[0]) * d[1];
            if slope < 0.0 {
                hi = hi.min(-area / slope);
            } else if slope > 0.0 {
                lo = lo.max(-area / slope);
            }
        }
        (lo, hi)
    }

    /// Moves vertex `u` to lower its star energy; returns how far it moved.
    pub fn optimize_vertex(&mut self, u: u32, directions: usize) -> f64 {
        if self.fixed[u as usize] || !self.active[u as usize] || self.vf[u as usize].is_empty() {
            return 0.0;
        }
        let start = self.uv[u as usize];
        for _ in 0..directions {
            let ang: f64 = self.rng.random::<f64>() * std::f64::consts::TAU;
            let d = [ang.cos(), ang.sin()];
            let (lo, hi) = self.feasible(u, d);
            if !(lo.is_finite() && hi.is_finite()) || hi - lo <= 0.0 {
                continue;
            }
            let p = self.uv[u as usize];
            let (lo, hi) = (lo * 0.999, hi * 0.999);
            let f = |t: f64| self.star_energy(u, [p[0] + t * d[0], p[1] + t * d[1]]);
            let e0 = f(0.0);
            let (t, e) = super::brent::minimize(f, lo, 0.0, hi, 1e-4 * (hi - lo), 40);
            if e < e0 {
                self.uv[u as usize] = [p[0] + t * d[0], p[1] + t * d[1]];
            }
        }
        let q = self.uv[u as usize];
        ((q[0] - start[0]).powi(2) + (q[1] - start[1]).powi(2)).sqrt()
    }

    /// Sweeps over `verts` (worst star first) until the largest move is below the tolerance;
    /// returns the sweeps made.
    pub fn optimize(&mut self, verts: &[u32], opts: &StretchOptOptions) -> usize {
        let mut order: Vec<(f64, u32)> = Vec::with_capacity(verts.len());
        for sweep in 0..opts.max_sweeps {
            order.clear();
            for &v in verts {
                if !self.fixed[v as usize] && self.active[v as usize] {
                    order.push((self.star_energy(v, self.uv[v as usize]), v));
                }
            }
            order.sort_by(|a, b| b.0.total_cmp(&a.0));
            let mut max_move: f64 = 0.0;
            let visit: Vec<u32> = order.iter().map(|o| o.1).collect();
            for v in visit {
                max_move = max_move.max(self.optimize_vertex(v, opts.directions));
            }
            if max_move < opts.tolerance {
                return sweep + 1;
            }
        }
        opts.max_sweeps
    }

    /// Live faces.
    pub fn live_faces(&self) -> impl Iterator<Item = [u32; 3]> + '_ {
        self.faces.iter().zip(&self.alive).filter(|(_, a)| **a).map(|(t, _)| *t)
    }

    /// Live faces with non-positive parameter area.
    pub fn flipped(&self) -> usize {
        self.live_faces()
            .filter(|t| area2(self.uv[t[0] as usize], self.uv[t[1] as usize], self.uv[t[2] as usize]) <= 0.0)
            .count()
    }
}
