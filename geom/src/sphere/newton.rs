//! Injective projected Newton for vertices on the unit sphere.
//!
//! The unknowns are a tangent step per free vertex in a frame of its own; a vertex at `p` moves
//! to `normalize(p + t₁ b₁ + t₂ b₂)` (the retraction of Schmidt, Pieper & Kobbelt 2023). Each
//! vertex's sphere point has an *image* in space ([`SphereImage`]): the point itself for a
//! sphere embedding, the point carried onto a target surface for a map between surfaces. The
//! energy is the area-weighted symmetric Dirichlet energy of every triangle's image (its chord
//! triangle, laid out in its own plane) against the triangle's rest shape
//! ([`crate::optim::sym_dirichlet`]); it grows without bound as an image degenerates. A
//! triangle too large for its chord to see its inversion also pays [`super::barrier`].
//!
//! Each iteration assembles the gradient and the per-triangle PSD-projected Hessians into one
//! sparse system whose pattern never changes ([`crate::optim::block_system`]: symbolic
//! factorization once, numeric per iteration) and solves for the Newton direction. The line
//! search starts at `step_fraction` of the first inversion on the sphere along the direction
//! ([`super::max_step`], exact for the retraction) and halves until the energy drops enough
//! (Armijo) **and** every triangle is positive under the exact predicate. So a start that is a
//! bijective spherical triangulation stays one through every accepted step: no triangle changes
//! sign on the continuous path, so the covering's degree stays 1.

use super::barrier::{barrier, shrink_barrier};
use super::max_step::first_inversion;
use super::measure::{Image, Measure, SphereImage, projected_layout, smooth_up, upright};
use super::orient::{all_positive, det};
use crate::error::{Error, InputError, Result};
use crate::mesh::{P3, V3};
use crate::optim::RestTriangle;
use crate::optim::block_system::BlockSystem;
use crate::optim::sym_dirichlet::Mat2;
use crate::progress::Progress;
use rayon::prelude::*;
use serde::Serialize;
use std::sync::atomic::{AtomicU64, Ordering};

/// A triangle's gradient and projected Hessian in its corners' tangent steps.
type Block = ([f64; 6], [[f64; 6]; 6]);

/// Options for [`SphereNewton::minimize`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereNewtonOptions {
    /// Iterations at most.
    pub max_iterations: usize,
    /// Stop when the Newton decrement (the drop a full step would give on the quadratic model)
    /// is below this fraction of the energy.
    pub tolerance: f64,
    /// The first trial step as a fraction of the first inversion on the sphere.
    pub step_fraction: f64,
    /// No vertex moves farther than this (radians of tangent step) in one trial.
    pub max_move: f64,
}

impl Default for SphereNewtonOptions {
    fn default() -> Self {
        Self { max_iterations: 200, tolerance: 1e-4, step_fraction: 0.8, max_move: 0.5 }
    }
}

/// What [`SphereNewton::minimize`] did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SphereNewtonResult {
    pub iterations: usize,
    pub energy_before: f64,
    pub energy_after: f64,
    /// Trial steps refused (energy not lower enough or a triangle not positive).
    pub backtracks: usize,
    /// Whether it stopped on the tolerance or a zero step (not on the iteration limit).
    pub converged: bool,
}

/// Triangles with rest shapes and fixed vertices, ready to optimize on the sphere. The
/// symbolic factorization happens once, in [`SphereNewton::new`].
pub struct SphereNewton {
    triangles: Vec<[u32; 3]>,
    rest: Vec<RestTriangle>,
    fixed: Vec<bool>,
    system: BlockSystem,
    pull: Pull,
    /// Per triangle, the reference `det` of the shrink barrier (empty: no shrink barrier).
    reference: Vec<f64>,
    /// Marquardt's damping λ of the Newton systems (`H + λ diag(H)`: each vertex damped on the
    /// scale of its own curvature, which differs by orders of magnitude between a thin part's
    /// crowded points and the rest), as `f64` bits: raised when the line search cuts a step short, lowered when a full
    /// step is taken.
    damping: AtomicU64,
}

/// The damping's range.
const DAMPING: (f64, f64) = (1e-8, 1e2);

/// Soft goals: `weight / 2 · |p − goal|²` per pulled vertex, its 2×2 Hessian `weight · I`
/// added into the block of one triangle around it.
#[derive(Default)]
struct Pull {
    weight: f64,
    /// (vertex, goal, triangle, corner).
    goals: Vec<(u32, P3, usize, usize)>,
}

/// A unit tangent frame at `p` (right-handed with the outward normal).
pub fn tangent_frame(p: &P3) -> [V3; 2] {
    let n = p.coords;
    let helper = if n.x.abs() < 0.6 { V3::x() } else { V3::y() };
    let b1 = (helper - n * n.dot(&helper)).normalize();
    [b1, n.cross(&b1)]
}

impl SphereNewton {
    /// Prepares `triangles` over `n_vertices` with their rest shapes; `fixed` vertices never move.
    ///
    /// # Errors
    /// `Invalid` for mismatched lengths or an out-of-range vertex; as [`BlockSystem::new`].
    pub fn new(n_vertices: usize, triangles: Vec<[u32; 3]>, rest: Vec<RestTriangle>, fixed: &[u32]) -> Result<Self> {
        if rest.len() != triangles.len() {
            return Err(InputError::Invalid("triangles and rest shapes do not match".into()).into());
        }
        let (system, is_fixed) = BlockSystem::for_vertices(n_vertices, &triangles, fixed)?;
        Ok(Self {
            triangles,
            rest,
            fixed: is_fixed,
            system,
            pull: Pull::default(),
            reference: Vec::new(),
            damping: AtomicU64::new(DAMPING.0.to_bits()),
        })
    }

    /// Makes every triangle resist shrinking on the sphere below `fraction` of its size at
    /// `s` ([`shrink_barrier`]).
    pub fn set_reference(&mut self, s: &[P3], fraction: f64) {
        self.reference = self
            .triangles
            .iter()
            .map(|t| fraction * det(&s[t[0] as usize], &s[t[1] as usize], &s[t[2] as usize]))
            .collect();
    }

    /// Removes the shrink barrier.
    pub fn clear_reference(&mut self) {
        self.reference.clear();
    }

    /// Pulls free vertices toward goals with `weight / 2 · |p − goal|²` each (the soft landmark
    /// phase); replaces any earlier pull.
    ///
    /// # Errors
    /// `Invalid` for a vertex outside the mesh, fixed, or in no triangle.
    pub fn set_pull(&mut self, goals: &[(u32, P3)], weight: f64) -> Result<()> {
        // One triangle and corner per vertex, found in one pass (not a scan per goal).
        let mut slot_of = vec![None; self.fixed.len()];
        for (t, tri) in self.triangles.iter().enumerate() {
            for (k, &x) in tri.iter().enumerate() {
                if let Some(slot @ None) = slot_of.get_mut(x as usize) {
                    *slot = Some((t, k));
                }
            }
        }
        let mut out = Vec::with_capacity(goals.len());
        for &(v, g) in goals {
            let slot = slot_of
                .get(v as usize)
                .copied()
                .flatten()
                .filter(|_| !self.fixed.get(v as usize).copied().unwrap_or(true))
                .ok_or_else(|| InputError::Invalid(format!("vertex {v} cannot be pulled")))?;
            out.push((v, g, slot.0, slot.1));
        }
        self.pull = Pull { weight, goals: out };
        Ok(())
    }

    pub fn is_fixed(&self, v: u32) -> bool {
        self.fixed.get(v as usize).copied().unwrap_or(false)
    }

    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// The energy at sphere points `s`; `None` when a triangle is not positive (in floating
    /// point), or an image is degenerate or turned over.
    pub fn energy<I: SphereImage>(&self, image: &I, s: &[P3]) -> Option<f64> {
        self.energy_as(Measure::Upright, image, s)
    }

    /// The vertices' images at `s` with the tangent frames they were taken in.
    fn images<I: SphereImage>(image: &I, s: &[P3]) -> Option<(Vec<[V3; 2]>, Vec<Image>)> {
        let frames: Vec<[V3; 2]> = s.par_iter().map(tangent_frame).collect();
        let images =
            s.par_iter().enumerate().map(|(v, p)| image.image(v as u32, p, &frames[v])).collect::<Option<_>>()?;
        Some((frames, images))
    }

    /// The energy under `measure`; `None` when a triangle is not positive on the sphere or the
    /// measure refuses an image.
    pub fn energy_as<I: SphereImage>(&self, measure: Measure, image: &I, s: &[P3]) -> Option<f64> {
        self.energy_with(measure, image, s, None)
    }

    /// Per triangle, the normal [`Measure::Untangle`] projects its image on at `s`.
    fn projection_normals<I: SphereImage>(&self, image: &I, s: &[P3]) -> Option<Vec<V3>> {
        let (_, images) = Self::images(image, s)?;
        Some(self.triangles.par_iter().map(|tri| smooth_up(tri.map(|v| &images[v as usize]))).collect())
    }

    /// [`SphereNewton::energy_as`] with the projections on `frozen` normals when given.
    fn energy_with<I: SphereImage>(&self, measure: Measure, image: &I, s: &[P3], frozen: Option<&[V3]>) -> Option<f64> {
        let (_, images) = Self::images(image, s)?;
        let e: f64 = (0..self.triangles.len())
            .into_par_iter()
            .map(|t| {
                let tri = self.triangles[t];
                let [a, b, c] = tri.map(|v| &s[v as usize]);
                if det(a, b, c) <= 0.0 {
                    return f64::INFINITY;
                }
                let mut guard = barrier(self.rest[t].area(), [a, b, c]).map_or(f64::INFINITY, |g| g.0);
                if let Some(&d0) = self.reference.get(t) {
                    guard += shrink_barrier(self.rest[t].area(), d0, [a, b, c]).map_or(f64::INFINITY, |g| g.0);
                }
                let im = tri.map(|v| &images[v as usize]);
                let e = measure
                    .layout(im, || upright(image, s, tri, im), frozen.map(|f| &f[t]))
                    .and_then(|(x, _)| measure.energy(&self.rest[t], x));
                e.map_or(f64::INFINITY, |e| e + guard)
            })
            .sum();
        let pull: f64 =
            self.pull.goals.iter().map(|(v, g, ..)| 0.5 * self.pull.weight * (s[*v as usize] - g).norm_squared()).sum();
        let e = e + pull;
        e.is_finite().then_some(e)
    }

    /// Image triangles turned over (their normal away from the sum of the surface normals under
    /// their corners).
    pub fn turned_over<I: SphereImage>(&self, image: &I, s: &[P3]) -> Option<usize> {
        Some(self.turned_over_list(image, s)?.len())
    }

    /// The triangles whose images are turned over.
    pub fn turned_over_list<I: SphereImage>(&self, image: &I, s: &[P3]) -> Option<Vec<usize>> {
        let (_, images) = Self::images(image, s)?;
        Some(
            (0..self.triangles.len())
                .into_par_iter()
                .filter(|&t| {
                    let tri = self.triangles[t];
                    !upright(image, s, tri, tri.map(|v| &images[v as usize]))
                })
                .collect(),
        )
    }

    /// The smallest Jacobian determinant of an image projected on the surface under it
    /// (negative for a turned-over image; `-∞` where degenerate).
    pub fn min_det<I: SphereImage>(&self, image: &I, s: &[P3]) -> f64 {
        self.worst(image, s).1
    }

    /// The triangle with the smallest projected Jacobian determinant, and that determinant.
    pub fn worst<I: SphereImage>(&self, image: &I, s: &[P3]) -> (usize, f64) {
        let Some((_, images)) = Self::images(image, s) else { return (usize::MAX, f64::NEG_INFINITY) };
        (0..self.triangles.len())
            .into_par_iter()
            .map(|t| {
                let tri = self.triangles[t];
                let Some((x, _)) =
                    projected_layout(tri.map(|v| images[v as usize].x), &smooth_up(tri.map(|v| &images[v as usize])))
                else {
                    return (t, f64::NEG_INFINITY);
                };
                (t, self.rest[t].jacobian_det(x))
            })
            .reduce(|| (usize::MAX, f64::INFINITY), |a, b| if b.1 < a.1 { b } else { a })
    }

    /// Minimizes the energy from the bijective start `s`, in place; every accepted step keeps
    /// every triangle positive under the exact predicate. Checks for cancellation every
    /// iteration.
    ///
    /// # Errors
    /// `Invalid` when `s` does not start with every triangle positive; `Numerical` when a
    /// Newton system cannot be solved; `Cancelled`.
    pub fn minimize<I: SphereImage>(
        &self,
        image: &I,
        s: &mut Vec<P3>,
        opts: &SphereNewtonOptions,
        progress: &dyn Progress,
    ) -> Result<SphereNewtonResult> {
        self.minimize_as(Measure::Upright, image, s, opts, progress)
    }

    /// [`SphereNewton::minimize`] under `measure`.
    ///
    /// # Errors
    /// As [`SphereNewton::minimize`].
    pub fn minimize_as<I: SphereImage>(
        &self,
        measure: Measure,
        image: &I,
        s: &mut Vec<P3>,
        opts: &SphereNewtonOptions,
        progress: &dyn Progress,
    ) -> Result<SphereNewtonResult> {
        let start = match self.energy_as(measure, image, s) {
            Some(e) if all_positive(s, &self.triangles) => e,
            _ => return Err(InputError::Invalid("the start on the sphere is not injective".into()).into()),
        };
        let mut r = SphereNewtonResult {
            iterations: 0,
            energy_before: start,
            energy_after: start,
            backtracks: 0,
            converged: false,
        };
        let mut energy = start;
        for _ in 0..opts.max_iterations {
            progress.check()?;
            let (dir, slope) = self.direction(measure, image, s)?;
            if -0.5 * slope < opts.tolerance * energy {
                r.converged = true;
                break;
            }
            let Some((next, e, refused)) = self.line_search(measure, image, s, (&dir, slope), energy, opts) else {
                // No step lowers the energy along this direction: damp harder and try again,
                // and stop only when the damped direction (near the gradient's) fails too.
                if self.raise_damping() {
                    continue;
                }
                r.converged = true;
                break;
            };
            tracing::trace!(iteration = r.iterations, energy, e, refused, "sphere newton step");
            r.iterations += 1;
            r.backtracks += refused;
            *s = next;
            energy = e;
        }
        r.energy_after = energy;
        Ok(r)
    }

    /// The Newton direction per vertex as a tangent vector (zero on fixed vertices), with the
    /// gradient dotted into it.
    pub(super) fn direction<I: SphereImage>(&self, measure: Measure, image: &I, s: &[P3]) -> Result<(Vec<V3>, f64)> {
        let (frames, images) = Self::images(image, s)
            .ok_or_else(|| Error::Internal("a vertex without an image inside the optimization".into()))?;
        let blocks: Vec<Option<Block>> = (0..self.triangles.len())
            .into_par_iter()
            .map(|t| {
                let tri = self.triangles[t];
                let im = tri.map(|v| &images[v as usize]);
                let (x, [u, w]) = measure.layout(im, || upright(image, s, tri, im), None)?;
                let m: [Mat2; 3] = tri.map(|v| {
                    let a = &images[v as usize].d;
                    [[u.dot(&a[0]), u.dot(&a[1])], [w.dot(&a[0]), w.dot(&a[1])]]
                });
                let (_, mut g, mut h) = measure.derivatives(&self.rest[t], x, &m)?;
                let corners = tri.map(|v| &s[v as usize]);
                let mut guards = vec![barrier(self.rest[t].area(), corners)?];
                if let Some(&d0) = self.reference.get(t) {
                    guards.push(shrink_barrier(self.rest[t].area(), d0, corners)?);
                }
                for (value, gb, k) in guards {
                    if value <= 0.0 {
                        continue;
                    }
                    let mut q = [0.0; 6];
                    for (i, &v) in tri.iter().enumerate() {
                        for j in 0..2 {
                            q[2 * i + j] = frames[v as usize][j].dot(&gb[i]);
                        }
                    }
                    for i in 0..6 {
                        g[i] += q[i];
                        for j in 0..6 {
                            h[i][j] += k * q[i] * q[j];
                        }
                    }
                }
                Some((g, h))
            })
            .collect();
        let n = self.system.len();
        let mut grad = vec![0.0; n];
        let mut values = self.system.zero_values();
        let mut blocks = blocks;
        for &(v, g, t, k) in &self.pull.goals {
            if let Some((gr, h)) = blocks[t].as_mut() {
                let d = (s[v as usize] - g) * self.pull.weight;
                for j in 0..2 {
                    gr[2 * k + j] += frames[v as usize][j].dot(&d);
                    h[2 * k + j][2 * k + j] += self.pull.weight;
                }
            }
        }
        for (t, b) in blocks.iter().enumerate() {
            let (g, h) =
                b.as_ref().ok_or_else(|| Error::Internal("a degenerate image inside the optimization".into()))?;
            for (k, &i) in self.system.dofs(t).iter().enumerate() {
                if i != usize::MAX {
                    grad[i] += g[k];
                }
            }
            self.system.add_block(&mut values, t, h);
        }
        let rhs: Vec<f64> = grad.iter().map(|g| -g).collect();
        // The projected Hessian is PSD (and singular along the rotations about a held point); a
        // shift tiny against its mean diagonal makes it definite, grown if needed. (Against the
        // largest entry it would swamp every well-shaped triangle while a crowded one's entries
        // are huge.)
        let trace: f64 = blocks
            .iter()
            .enumerate()
            .filter_map(|(t, b)| b.as_ref().map(|(_, h)| (t, h)))
            .map(|(t, h)| (0..6).filter(|&k| self.system.dofs(t)[k] != usize::MAX).map(|k| h[k][k]).sum::<f64>())
            .sum();
        let scale = (trace / n.max(1) as f64).max(f64::MIN_POSITIVE);
        let damping = f64::from_bits(self.damping.load(Ordering::Relaxed));
        self.system.scale_diagonal(&mut values, 1.0 + damping);
        let step = self.system.solve_shifted(&values, &rhs, 1e-8 * scale, scale)?;
        let slope: f64 = step.iter().zip(&grad).map(|(a, g)| a * g).sum();
        let mut dir = vec![V3::zeros(); s.len()];
        let mut k = 0;
        for (v, out) in dir.iter_mut().enumerate() {
            if !self.fixed[v] {
                *out = frames[v][0] * step[k] + frames[v][1] * step[k + 1];
                k += 2;
            }
        }
        Ok((dir, slope))
    }

    /// Multiplies the damping by 100; false when it is already at its largest.
    pub(super) fn raise_damping(&self) -> bool {
        let d = f64::from_bits(self.damping.load(Ordering::Relaxed));
        if d >= DAMPING.1 {
            return false;
        }
        self.damping.store((d * 100.0).min(DAMPING.1).to_bits(), Ordering::Relaxed);
        true
    }

    /// The accepted points, their energy and the refused trials; `None` when no step along the
    /// direction lowers the energy.
    pub(super) fn line_search<I: SphereImage>(
        &self,
        measure: Measure,
        image: &I,
        s: &[P3],
        (dir, slope): (&[V3], f64),
        energy: f64,
        opts: &SphereNewtonOptions,
    ) -> Option<(Vec<P3>, f64, usize)> {
        if slope >= 0.0 {
            return None;
        }
        // The untangling energy searched with the projection normals of the start: the Newton
        // step treats them as constant, and the normals moving under the step made it look
        // like no descent (steps accepted after 40 halvings, plane -> bird).
        let frozen = match measure {
            Measure::Untangle(_) => Some(self.projection_normals(image, s)?),
            Measure::Upright => None,
        };
        let energy = match &frozen {
            Some(f) => self.energy_with(measure, image, s, Some(f))?,
            None => energy,
        };
        let longest = dir.iter().map(|d| d.norm()).fold(0.0, f64::max);
        let mut t = if longest > 0.0 { (opts.max_move / longest).min(1.0) } else { 1.0 };
        let first = (0..self.triangles.len())
            .into_par_iter()
            .map(|k| {
                let tri = self.triangles[k];
                first_inversion(tri.map(|v| &s[v as usize]), tri.map(|v| &dir[v as usize]), t)
            })
            .reduce(|| f64::INFINITY, f64::min);
        if first.is_finite() {
            t = t.min(opts.step_fraction * first);
        }
        let mut refused = 0;
        tracing::trace!(t, first, longest, "sphere line search");
        while t > 1e-14 {
            let trial: Vec<P3> = s.par_iter().zip(dir).map(|(p, d)| P3::from((p.coords + d * t).normalize())).collect();
            if let Some(e) = self.energy_with(measure, image, &trial, frozen.as_deref())
                && e <= energy + 1e-4 * t * slope
                && e < energy
                && all_positive(&trial, &self.triangles)
            {
                // A step cut to a tenth of the Newton step or less: the quadratic model is poor
                // (kinks where images cross the surface's edges, inversions on the sphere it
                // does not see); damp the next systems. A full step: undamp.
                let damping = f64::from_bits(self.damping.load(Ordering::Relaxed));
                let next = if t <= 0.1 {
                    (damping * 10.0).min(DAMPING.1)
                } else if t >= 1.0 {
                    (damping * 0.1).max(DAMPING.0)
                } else {
                    damping
                };
                self.damping.store(next.to_bits(), Ordering::Relaxed);
                return Some((trial, e, refused));
            }
            refused += 1;
            t *= 0.5;
        }
        None
    }
}
