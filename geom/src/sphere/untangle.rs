//! Turning over image triangles that face away from the surface, on the sphere, without ever
//! leaving the bijective spherical triangulations.
//!
//! The method of Garanzha, Kaporin, Kudryavtseva, Protais, Ray & Sokolov 2021 ("Foldover-free
//! maps in 50 lines of code"), carried to images on a surface: each image chord is projected
//! on the plane normal to its corners' smooth normals ([`Measure::Untangle`]), where a
//! turned-over image has a negative Jacobian determinant `D`; the symmetric Dirichlet energy
//! with `D` replaced by `χ(D, ε) = (D + √(ε² + D²)) / 2` is finite there and its minimizers turn
//! it back. `ε` follows their schedule: it shrinks as the smallest determinant grows, so the
//! energy tends to the distortion itself once every image is upright. The steps are the same
//! injective Newton steps as [`SphereNewton::minimize`]: the spherical triangulation stays
//! bijective throughout; only the images on the surface are untangled.

use super::measure::{Measure, SphereImage};
use super::newton::{SphereNewton, SphereNewtonOptions};
use crate::error::Result;
use crate::mesh::P3;
use crate::progress::Progress;

/// What [`SphereNewton::untangle`] did.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct UntangleResult {
    pub iterations: usize,
    /// Turned-over images before and after.
    pub before: usize,
    pub after: usize,
    /// The smallest projected Jacobian determinant at the end (positive when all upright).
    pub min_det: f64,
}

impl SphereNewton {
    /// Untangles the images of `s` in place, for at most `max_iterations` Newton steps; stops
    /// as soon as every image is upright. Each step measures every image with the untangling
    /// energy, as Garanzha et al. do: `ε` is set by the worst image, so an upright image may
    /// lean while a turned-over one comes back. (Keeping the upright images upright as hard
    /// walls while only the turned-over ones were untangled stalled: cat -> lion left 13 and
    /// 27 images turned over after 25 and 13 steps, where untangling all of them leaves none.)
    /// With `shrink` positive, a shrink barrier referred to the points every ten steps keeps
    /// the model aware of inversions on the sphere.
    ///
    /// # Errors
    /// `Numerical` when a Newton system cannot be solved; `Cancelled`.
    pub fn untangle<I: SphereImage>(
        &mut self,
        image: &I,
        s: &mut Vec<P3>,
        max_iterations: usize,
        shrink: f64,
        opts: &SphereNewtonOptions,
        progress: &dyn Progress,
    ) -> Result<UntangleResult> {
        let before = self.turned_over_list(image, s).unwrap_or_default();
        let mut r = UntangleResult {
            iterations: 0,
            before: before.len(),
            after: before.len(),
            min_det: self.min_det(image, s),
        };
        let mut m = r.min_det;
        let mut eps = (1e-8 + 0.04 * m.min(0.0).powi(2)).sqrt();
        let mut tangled = before;
        while !tangled.is_empty() && r.iterations < max_iterations {
            progress.check()?;
            if shrink > 0.0 && r.iterations.is_multiple_of(10) {
                self.set_reference(s, shrink);
            }
            r.iterations += 1;
            let measure = Measure::Untangle(eps);
            let Some(energy) = self.energy_as(measure, image, s) else { break };
            let (dir, slope) = self.direction(measure, image, s)?;
            let Some((next, after, _)) = self.line_search(measure, image, s, (&dir, slope), energy, opts) else {
                if self.raise_damping() {
                    continue;
                }
                break;
            };
            *s = next;
            let sigma = (1.0 - after / energy).max(0.1);
            m = self.min_det(image, s);
            let chi = 0.5 * (m + (eps * eps + m * m).sqrt());
            let mu = (1.0 - sigma) * chi;
            eps = if m < mu { 2.0 * (mu * (mu - m)).sqrt() } else { 1e-10 };
            tangled = self.turned_over_list(image, s).unwrap_or_default();
            tracing::trace!(
                iteration = r.iterations,
                energy,
                after,
                m,
                eps,
                turned = tangled.len(),
                "sphere untangle step"
            );
        }
        let (w, d) = self.worst(image, s);
        if let Some(tri) = self.triangles().get(w) {
            tracing::debug!(triangle = w, det = d, ?tri, fixed = ?tri.map(|v| self.is_fixed(v)), "worst after untangling");
        }
        self.clear_reference();
        let turned = tangled.len();
        r.after = turned;
        r.min_det = m;
        Ok(r)
    }
}
