//! Injective projected Newton on a 2D map: minimizes the summed symmetric Dirichlet energy of
//! a triangulation's images, some vertices fixed, and never lets a triangle invert.
//!
//! Each iteration assembles the gradient and the per-triangle PSD-projected Hessians
//! ([`super::sym_dirichlet`]) into one sparse system with a pattern fixed for the whole run
//! ([`super::block_system`]: symbolic factorization once, numeric per iteration), solves for
//! the Newton direction, and searches along it (Smith & Schaefer 2015, as SLIM does): the step
//! starts at `step_fraction` of the first inversion time over all triangles
//! ([`super::max_step`]) or 1, whichever is smaller, and halves until the energy decreases
//! enough (Armijo) **and** every triangle is positively oriented under Shewchuk's exact
//! `orient2d`. A step that fails either test is never taken, so the map stays injective
//! through every accepted iteration when it starts injective.
//!
//! Where the images live is a [`MapDomain`]: the plane ([`Plane`]), or a surface of charts
//! (the common base domain of a layout) whose vertices each sit in a chart of their own, with
//! a metric factor per triangle (the target surface's metric, frozen for one step).

use super::block_system::BlockSystem;
pub use super::domain::{MapDomain, Plane};
use super::line_search::{Stars, backtrack, held_search, inverted, positive};
use super::max_step::first_inversion;
use super::sym_dirichlet::{Mat2, RestTriangle};
use crate::error::{Error, InputError, Result};
use crate::param::Uv;
use crate::progress::Progress;
use rayon::prelude::*;
use serde::Serialize;

/// Triangles whose derivatives are computed in parallel before they are added to the system.
const ASSEMBLY_CHUNK: usize = 8192;

/// Options for [`InjectiveNewton::minimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InjectiveNewtonOptions {
    /// Iterations at most.
    pub max_iterations: usize,
    /// Stop when an iteration lowers the energy by less than this fraction.
    pub tolerance: f64,
    /// The first trial step as a fraction of the first inversion time.
    pub step_fraction: f64,
    /// Rounds per trial step in which the vertices of triangles the trial would invert are
    /// held back (their step zeroed) before the step is halved; 0 halves at once. Where the
    /// linear step bound cannot see an inversion (images retracted onto a curved surface), one
    /// triangle would otherwise shorten every vertex's step.
    pub hold_rounds: usize,
}

impl Default for InjectiveNewtonOptions {
    fn default() -> Self {
        Self { max_iterations: 100, tolerance: 1e-6, step_fraction: 0.8, hold_rounds: 0 }
    }
}

/// What [`InjectiveNewton::minimize`] did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct InjectiveNewtonResult {
    pub iterations: usize,
    pub energy_before: f64,
    pub energy_after: f64,
    /// Trial steps refused (energy not lower or a triangle not positively oriented).
    pub backtracks: usize,
    /// Whether it stopped on the tolerance (not on the iteration limit or a zero step).
    pub converged: bool,
}

/// A triangulation with rest shapes and fixed vertices, ready to optimize images of.
pub struct InjectiveNewton {
    triangles: Vec<[u32; 3]>,
    rest: Vec<RestTriangle>,
    fixed: Vec<bool>,
    system: BlockSystem,
    /// The triangles at each vertex, for the held line search.
    stars: Stars,
}

impl InjectiveNewton {
    /// Prepares `triangles` (over `n_vertices`) with their rest shapes; `fixed` vertices never
    /// move. The symbolic factorization happens here, once.
    ///
    /// # Errors
    /// `Invalid` for mismatched lengths or an out-of-range vertex; as [`BlockSystem::new`].
    pub fn new(n_vertices: usize, triangles: Vec<[u32; 3]>, rest: Vec<RestTriangle>, fixed: &[u32]) -> Result<Self> {
        if rest.len() != triangles.len() {
            return Err(InputError::Invalid("triangles and rest shapes do not match".into()).into());
        }
        let (system, is_fixed) = BlockSystem::for_vertices(n_vertices, &triangles, fixed)?;
        let stars = Stars::new(n_vertices, &triangles);
        Ok(Self { triangles, rest, fixed: is_fixed, system, stars })
    }

    /// Total energy with the domain's current metrics; `None` if any triangle is degenerate or
    /// inverted.
    pub fn energy<D: MapDomain>(&self, d: &D, s: &D::State) -> Option<f64> {
        let metrics: Vec<Mat2> = self.triangles.par_iter().map(|&tri| d.metric(s, tri)).collect();
        self.energy_with(d, s, &metrics)
    }

    fn energy_with<D: MapDomain>(&self, d: &D, s: &D::State, metrics: &[Mat2]) -> Option<f64> {
        self.energy_eps(d, s, metrics, None)
    }

    /// The energy, or with `Some(ε)` the untangling energy (finite on inverted triangles).
    fn energy_eps<D: MapDomain>(&self, d: &D, s: &D::State, metrics: &[Mat2], eps: Option<f64>) -> Option<f64> {
        let each: Vec<Option<f64>> = (0..self.triangles.len())
            .into_par_iter()
            .map(|t| {
                let x = d.element(s, self.triangles[t]).0;
                match eps {
                    None => self.rest[t].energy_in(x, &metrics[t]),
                    Some(e) => self.rest[t].energy_eps(x, &metrics[t], e),
                }
            })
            .collect();
        each.into_iter().sum()
    }

    /// `det(L J)` of every triangle (rest-normalized: 1 for an isometry).
    fn dets<D: MapDomain>(&self, d: &D, s: &D::State, metrics: &[Mat2]) -> Vec<f64> {
        (0..self.triangles.len())
            .map(|t| {
                let x = d.element(s, self.triangles[t]).0;
                let l = &metrics[t];
                let a2 = crate::planar::area2(x[0], x[1], x[2]);
                (l[0][0] * l[1][1] - l[0][1] * l[1][0]) * 0.5 * a2 / self.rest[t].area()
            })
            .collect()
    }

    /// Triangles not positively oriented under the exact predicate.
    pub fn folded<D: MapDomain>(&self, d: &D, s: &D::State) -> usize {
        inverted(d, s, &self.triangles).len()
    }

    /// Untangles a start with inverted triangles by the method of Garanzha, Kaporin, Kudryavtseva,
    /// Protais, Ray & Sokolov 2021 ("Foldover-free maps in 50 lines of code"): Newton steps on
    /// the energy with `det J` replaced by `χ(D, ε)`, `ε` shrinking as the smallest determinant
    /// grows, until every triangle is positive. Returns the triangles still folded.
    ///
    /// # Errors
    /// `Numerical` when a Newton system cannot be solved; `Cancelled`.
    pub fn untangle<D: MapDomain>(
        &self,
        d: &D,
        s: &mut D::State,
        max_iterations: usize,
        progress: &dyn Progress,
    ) -> Result<usize> {
        let metrics: Vec<Mat2> = self.triangles.par_iter().map(|&tri| d.metric(s, tri)).collect();
        let min_det = |s: &D::State| self.dets(d, s, &metrics).into_iter().fold(f64::INFINITY, f64::min);
        let mut m = min_det(s);
        let mut eps = (1e-8 + 0.04 * m.min(0.0).powi(2)).sqrt();
        for _ in 0..max_iterations {
            if self.folded(d, s) == 0 {
                return Ok(0);
            }
            progress.check()?;
            let Some(before) = self.energy_eps(d, s, &metrics, Some(eps)) else { break };
            let dir = self.direction_eps(d, s, &metrics, Some(eps))?;
            if let Some((next, after)) = self.descend(d, s, &dir, &metrics, before, Some(eps)) {
                *s = next;
                let sigma = (1.0 - after / before).max(0.1);
                m = min_det(s);
                let chi = 0.5 * (m + (eps * eps + m * m).sqrt());
                let mu = (1.0 - sigma) * chi;
                eps = if m < mu { 2.0 * (mu * (mu - m)).sqrt() } else { 1e-10 };
            } else {
                eps *= 0.5;
            }
        }
        Ok(self.folded(d, s))
    }

    /// Armijo backtracking along `dir` on the untangling energy (no orientation test).
    fn descend<D: MapDomain>(
        &self,
        d: &D,
        s: &D::State,
        (dir, slope): &(Vec<Uv>, f64),
        metrics: &[Mat2],
        energy: f64,
        eps: Option<f64>,
    ) -> Option<(D::State, f64)> {
        if *slope >= 0.0 {
            return None;
        }
        // No vertex moves farther than a typical edge in one step: a long jump across chart
        // sides can land a vertex on another sheet around a cone, a fold no step undoes.
        let longest = dir.iter().map(|q| q[0].hypot(q[1])).fold(0.0, f64::max);
        let t = if longest > 0.0 { (self.typical_edge(d, s) / longest).min(1.0) } else { 1.0 };
        backtrack(d, s, dir, t, |trial, t| {
            self.energy_eps(d, trial, metrics, eps).filter(|&e| e <= energy + 1e-4 * t * slope)
        })
        .map(|(trial, e, _)| (trial, e))
    }

    /// The median edge length of the triangles in their charts.
    fn typical_edge<D: MapDomain>(&self, d: &D, s: &D::State) -> f64 {
        let mut l: Vec<f64> = self
            .triangles
            .iter()
            .map(|&tri| {
                let x = d.element(s, tri).0;
                (x[1][0] - x[0][0]).hypot(x[1][1] - x[0][1])
            })
            .collect();
        if l.is_empty() {
            return 0.0;
        }
        let mid = l.len() / 2;
        *l.select_nth_unstable_by(mid, f64::total_cmp).1
    }

    /// Whether every triangle is positively oriented in its chart under the exact predicate.
    pub fn is_injective<D: MapDomain>(&self, d: &D, s: &D::State) -> bool {
        self.triangles.par_iter().all(|&tri| positive(d.element(s, tri).0))
    }

    /// Minimizes the energy from the injective start `s`, in place; every accepted step keeps
    /// every triangle positively oriented. Checks for cancellation every iteration.
    ///
    /// # Errors
    /// `Invalid` when `s` does not start injective; `Numerical` when a Newton system cannot
    /// be solved; `Cancelled`.
    pub fn minimize<D: MapDomain>(
        &self,
        d: &D,
        s: &mut D::State,
        opts: &InjectiveNewtonOptions,
        progress: &dyn Progress,
    ) -> Result<InjectiveNewtonResult> {
        let start = match self.energy(d, s) {
            Some(e) if self.is_injective(d, s) => e,
            _ => return Err(InputError::Invalid("the start map is not injective".into()).into()),
        };
        let mut r = InjectiveNewtonResult {
            iterations: 0,
            energy_before: start,
            energy_after: start,
            backtracks: 0,
            converged: false,
        };
        for _ in 0..opts.max_iterations {
            progress.check()?;
            // The metrics are frozen for the step: the energy it lowers is this one.
            let metrics: Vec<Mat2> = self.triangles.par_iter().map(|&tri| d.metric(s, tri)).collect();
            let energy = self
                .energy_with(d, s, &metrics)
                .ok_or_else(|| Error::Internal("an inverted triangle inside the optimization".into()))?;
            let dir = self.direction(d, s, &metrics)?;
            let Some((next, e, backtracks)) = self.line_search(d, s, &dir, &metrics, energy, opts) else {
                tracing::debug!(iteration = r.iterations, energy, slope = dir.1, "no step lowers the energy");
                r.converged = true;
                break;
            };
            tracing::debug!(iteration = r.iterations, energy, e, backtracks, "newton step");
            r.iterations += 1;
            r.backtracks += backtracks;
            *s = next;
            r.energy_after = e;
            if (energy - e) / energy.abs().max(f64::MIN_POSITIVE) < opts.tolerance {
                r.converged = true;
                break;
            }
        }
        if let Some(e) = self.energy(d, s) {
            r.energy_after = e;
        }
        Ok(r)
    }

    /// The Newton direction per vertex in its own chart (zero on fixed vertices), with the
    /// gradient dotted into it.
    fn direction<D: MapDomain>(&self, d: &D, s: &D::State, metrics: &[Mat2]) -> Result<(Vec<Uv>, f64)> {
        self.direction_eps(d, s, metrics, None)
    }

    fn direction_eps<D: MapDomain>(
        &self,
        d: &D,
        s: &D::State,
        metrics: &[Mat2],
        eps: Option<f64>,
    ) -> Result<(Vec<Uv>, f64)> {
        let n = self.system.len();
        let mut grad = vec![0.0; n];
        let mut values = self.system.zero_values();
        // Per-triangle derivatives in parallel, a chunk at a time (bounded memory), added into
        // the system in triangle order.
        let n_tri = self.triangles.len();
        for start in (0..n_tri).step_by(ASSEMBLY_CHUNK) {
            let chunk = start..(start + ASSEMBLY_CHUNK).min(n_tri);
            let parts: Vec<_> = chunk
                .clone()
                .into_par_iter()
                .map(|t| {
                    let (x, m) = d.element(s, self.triangles[t]);
                    match eps {
                        None => self.rest[t].derivatives_in(x, &metrics[t], &m),
                        Some(e) => self.rest[t].derivatives_eps(x, &metrics[t], &m, e),
                    }
                })
                .collect();
            for (t, derivatives) in chunk.zip(parts) {
                let (_, g, h) = derivatives
                    .ok_or_else(|| Error::Internal("an inverted triangle inside the optimization".into()))?;
                for (k, &i) in self.system.dofs(t).iter().enumerate() {
                    if i != usize::MAX {
                        grad[i] += g[k];
                    }
                }
                self.system.add_block(&mut values, t, &h);
            }
        }
        let rhs: Vec<f64> = grad.iter().map(|g| -g).collect();
        // The projected Hessian is PSD; a tiny shift makes it definite, grown if needed.
        let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs())).max(f64::MIN_POSITIVE);
        let step = self.system.solve_shifted(&values, &rhs, 1e-10 * scale, 1e-2 * scale)?;
        let slope: f64 = step.iter().zip(&grad).map(|(a, g)| a * g).sum();
        let mut dir = vec![[0.0; 2]; self.fixed.len()];
        let mut k = 0;
        for (v, out) in dir.iter_mut().enumerate() {
            if !self.fixed[v] {
                *out = [step[k], step[k + 1]];
                k += 2;
            }
        }
        Ok((dir, slope))
    }

    /// The first time any triangle inverts along `dir` (each corner's move carried into the
    /// triangle's chart).
    fn first_inversion<D: MapDomain>(&self, d: &D, s: &D::State, dir: &[Uv]) -> f64 {
        self.triangles
            .par_iter()
            .map(|&tri| {
                let (x, m) = d.element(s, tri);
                let mut k = 0;
                let moves = tri.map(|v| {
                    let (q, mi) = (dir[v as usize], m[k]);
                    k += 1;
                    [mi[0][0] * q[0] + mi[0][1] * q[1], mi[1][0] * q[0] + mi[1][1] * q[1]]
                });
                first_inversion(x, moves)
            })
            .reduce(|| f64::INFINITY, f64::min)
    }

    /// The accepted state, its energy and the refused trials; `None` when no step along the
    /// direction lowers the energy.
    fn line_search<D: MapDomain>(
        &self,
        d: &D,
        s: &D::State,
        (dir, slope): &(Vec<Uv>, f64),
        metrics: &[Mat2],
        energy: f64,
        opts: &InjectiveNewtonOptions,
    ) -> Option<(D::State, f64, usize)> {
        if *slope >= 0.0 {
            return None;
        }
        let t = (opts.step_fraction * self.first_inversion(d, s, dir)).min(1.0);
        if opts.hold_rounds > 0 {
            let accept = |trial: &D::State| self.energy(d, trial).filter(|&e| e < energy);
            return held_search(d, s, (dir, t), (&self.triangles, &self.stars), opts.hold_rounds, accept);
        }
        // The frozen metrics give the direction and the Armijo test; the step must also lower
        // the energy under the metrics where the trial lands (a long step crosses many target
        // faces, and the frozen energy alone let it wander uphill).
        backtrack(d, s, dir, t, |trial, t| {
            if !self.energy_with(d, trial, metrics).is_some_and(|e| e <= energy + 1e-4 * t * slope) {
                return None;
            }
            self.energy(d, trial).filter(|&e| e < energy && self.is_injective(d, trial))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::optim::sym_dirichlet::IDENTITY;
    use crate::progress::NoProgress;

    /// The flat `n` × `n` grid as its own rest shape, boundary fixed; and its rest positions.
    fn grid_problem(n: usize) -> (InjectiveNewton, Vec<Uv>) {
        let m = shapes::grid(n);
        let rest_pos: Vec<Uv> = m.positions().iter().map(|p| [p.x, p.y]).collect();
        let tris: Vec<[u32; 3]> = m.faces().iter().map(|f| f.map(|v| v.0)).collect();
        let rest: Vec<RestTriangle> =
            tris.iter().map(|t| RestTriangle::new(t.map(|v| rest_pos[v as usize])).unwrap()).collect();
        let boundary: Vec<u32> =
            (0..m.n_vertices() as u32).filter(|&v| m.is_boundary_vertex(crate::VertexId(v))).collect();
        let opt = InjectiveNewton::new(m.n_vertices(), tris, rest, &boundary).unwrap();
        (opt, rest_pos)
    }

    /// A grid with a fold (two interior vertices pushed across their neighbours) is untangled,
    /// then relaxed without an inverted step.
    #[test]
    fn a_folded_grid_is_untangled_then_relaxed() {
        let (opt, rest_pos) = grid_problem(6);
        let mut x = rest_pos.clone();
        // Vertex (2, 2) pushed past (4, 2), and (3, 3) past (1, 3).
        x[2 * 7 + 2] = [0.75, 2.0 / 6.0];
        x[3 * 7 + 3] = [0.1, 0.5];
        assert!(opt.folded(&Plane, &x) > 0);
        let left = opt.untangle(&Plane, &mut x, 200, &NoProgress).unwrap();
        assert_eq!(left, 0);
        assert!(opt.is_injective(&Plane, &x));
        let opts = InjectiveNewtonOptions { max_iterations: 500, ..Default::default() };
        let r = opt.minimize(&Plane, &mut x, &opts, &NoProgress).unwrap();
        assert!(opt.is_injective(&Plane, &x));
        let ideal = 4.0 * opt.rest.iter().map(|r| r.area()).sum::<f64>();
        assert!((r.energy_after - ideal) / ideal < 1e-3, "{r:?} vs {ideal}");
    }

    /// A square grid whose interior is pushed sideways (`x + 0.3 sin(πx) sin(πy)`, the boundary
    /// held): injective but far from the rest shape. The optimization brings the energy to its
    /// minimum (the identity's, four times the area) and every accepted step stays injective.
    #[test]
    fn a_pushed_grid_relaxes_without_ever_inverting() {
        let (opt, rest_pos) = grid_problem(8);
        let pi = std::f64::consts::PI;
        let mut x: Vec<Uv> =
            rest_pos.iter().map(|p| [p[0] + 0.3 * (pi * p[0]).sin() * (pi * p[1]).sin(), p[1]]).collect();
        assert!(opt.is_injective(&Plane, &x));
        let opts = InjectiveNewtonOptions { max_iterations: 1, ..Default::default() };
        let mut last = opt.energy(&Plane, &x).unwrap();
        let start = last;
        for _ in 0..60 {
            let r = opt.minimize(&Plane, &mut x, &opts, &NoProgress).unwrap();
            assert!(opt.is_injective(&Plane, &x), "an accepted step inverted a triangle");
            assert!(r.energy_after <= last, "{} > {last}", r.energy_after);
            last = r.energy_after;
        }
        let ideal = 4.0 * opt.rest.iter().map(|r| r.area()).sum::<f64>();
        assert!(last < start && (last - ideal) / ideal < 1e-3, "start {start}, end {last}, ideal {ideal}");
    }

    /// A plane whose moves shear (every other vertex also rises, the rest sink, by twice its
    /// step's length): the linear step bound cannot see the inversions that adds, so the line
    /// search holds vertices. `restore`
    /// says whether holding one restores it in place.
    struct Bent {
        restore: bool,
    }

    impl MapDomain for Bent {
        type State = Vec<Uv>;
        fn element(&self, s: &Vec<Uv>, tri: [u32; 3]) -> ([Uv; 3], [Mat2; 3]) {
            Plane.element(s, tri)
        }
        fn moved(&self, s: &Vec<Uv>, d: &[Uv]) -> Option<Vec<Uv>> {
            let shear = |v: usize, q: &Uv| if v.is_multiple_of(2) { 2.0 } else { -2.0 } * q[0].hypot(q[1]);
            Some(s.iter().zip(d).enumerate().map(|(v, (p, q))| [p[0] + q[0], p[1] + q[1] + shear(v, q)]).collect())
        }
        fn restore(&self, trial: &mut Vec<Uv>, from: &Vec<Uv>, v: usize) -> bool {
            if self.restore {
                trial[v] = from[v];
            }
            self.restore
        }
    }

    /// Holding a vertex in place (restoring it and re-testing its star) takes the same steps
    /// as moving the whole state anew; every accepted step stays injective.
    #[test]
    fn held_vertices_restored_in_place_take_the_same_steps() {
        let (opt, rest_pos) = grid_problem(8);
        let pi = std::f64::consts::PI;
        let start: Vec<Uv> =
            rest_pos.iter().map(|p| [p[0] + 0.3 * (pi * p[0]).sin() * (pi * p[1]).sin(), p[1]]).collect();
        let opts = InjectiveNewtonOptions { max_iterations: 1, hold_rounds: 30, ..Default::default() };
        let (mut a, mut b) = (start.clone(), start);
        let mut backtracks = 0;
        for _ in 0..20 {
            let ra = opt.minimize(&Bent { restore: true }, &mut a, &opts, &NoProgress).unwrap();
            let rb = opt.minimize(&Bent { restore: false }, &mut b, &opts, &NoProgress).unwrap();
            assert_eq!(a, b);
            assert_eq!((ra.iterations, ra.backtracks), (rb.iterations, rb.backtracks));
            assert!(opt.is_injective(&Plane, &a), "an accepted step inverted a triangle");
            backtracks += ra.backtracks;
        }
        assert!(backtracks > 0, "the shear never held a vertex: the test tests nothing");
    }

    /// A step toward inversion: a descent direction that would carry the centre vertex of a
    /// fan through the opposite edge is cut short of the first inversion, and the step taken
    /// keeps every triangle positively oriented and lowers the energy. Then the whole
    /// optimization converges to the rest shape.
    #[test]
    fn a_step_toward_inversion_is_cut_before_it() {
        // A square split into four triangles around a centre vertex 4; the corners are fixed.
        let rest_pos: Vec<Uv> = vec![[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [0.5, 0.5]];
        let tris = vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]];
        let rest =
            tris.iter().map(|t: &[u32; 3]| RestTriangle::new(t.map(|v| rest_pos[v as usize])).unwrap()).collect();
        let opt = InjectiveNewton::new(5, tris, rest, &[0, 1, 2, 3]).unwrap();
        let mut x = rest_pos.clone();
        x[4] = [0.5, 0.9];
        // Downward (a descent direction from near the top edge), ten times too far: it would
        // reach the bottom edge at t = 0.09.
        let dir: Vec<Uv> = (0..5).map(|v| if v == 4 { [0.0, -10.0] } else { [0.0, 0.0] }).collect();
        let along = |t: f64| {
            let y: Vec<Uv> = x.iter().zip(&dir).map(|(p, d)| [p[0] + t * d[0], p[1] + t * d[1]]).collect();
            opt.energy(&Plane, &y)
        };
        let h = 1e-7;
        let slope = (along(h).unwrap() - along(-h).unwrap()) / (2.0 * h);
        assert!(slope < 0.0);
        let max = opt.first_inversion(&Plane, &x, &dir);
        assert!((max - 0.09).abs() < 1e-12, "first inversion at {max}");
        assert!(along(1.0).is_none(), "the full step inverts");
        let e0 = opt.energy(&Plane, &x).unwrap();
        let metrics = [IDENTITY; 4];
        let (y, e, _) =
            opt.line_search(&Plane, &x, &(dir, slope), &metrics, e0, &InjectiveNewtonOptions::default()).unwrap();
        assert!(opt.is_injective(&Plane, &y) && e < e0);
        assert!(y[4][1] > 0.0 && y[4][1] < 0.9, "{:?}", y[4]);
        let r = opt.minimize(&Plane, &mut x, &InjectiveNewtonOptions::default(), &NoProgress).unwrap();
        assert!(opt.is_injective(&Plane, &x) && r.converged);
        assert!((x[4][0] - 0.5).abs() < 1e-6 && (x[4][1] - 0.5).abs() < 1e-6, "{:?}", x[4]);
        // An inverted start is refused.
        x[4] = [0.5, -0.1];
        assert_eq!(
            opt.minimize(&Plane, &mut x, &Default::default(), &NoProgress).unwrap_err().code(),
            "invalid_argument"
        );
    }
}
