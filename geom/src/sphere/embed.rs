//! A bijective, low-distortion embedding of a closed genus-0 mesh on the unit sphere.
//!
//! 1. The mesh is decimated to a base of a few hundred vertices ([`super::multires`]).
//! 2. Tutte's embedding of the base through the gnomonic plane ([`super::tutte`]): bijective
//!    by construction, verified by the exact predicate.
//! 3. Level by level, vertices come back inside their rings' kernels, and injective projected
//!    Newton on the sphere ([`super::newton`]) lowers the symmetric Dirichlet distortion of the
//!    chord triangles against the mesh (scaled to the sphere's area), every accepted step
//!    verified.
//! 3. The result is checked once more ([`super::orient::check`]: every triangle positive, total
//!    area 4π) and refused as a numerical failure otherwise; it is never returned folded.

use super::multires::{self, BASE_VERTICES, Hierarchy, LEVEL_GROWTH, LEVEL_ITERATIONS};
use super::newton::{SphereNewtonOptions, SphereNewtonResult};
use super::orient::check;
use super::tutte::{default_pole, tutte_sphere};
use crate::error::{Error, InputError, Result};
use crate::mesh::{Mesh, P3};
use crate::optim::RestTriangle;
use crate::progress::Progress;
use crate::topology;
use serde::Serialize;

/// Options for [`embed_sphere`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SphereEmbedOptions {
    /// The distortion optimization after Tutte's start.
    pub newton: SphereNewtonOptions,
}

/// A bijective embedding on the unit sphere and how it was reached.
#[derive(Debug, Clone, PartialEq)]
pub struct SphereEmbedding {
    /// One unit vector per mesh vertex; every face positively oriented.
    pub points: Vec<P3>,
    pub report: SphereEmbedReport,
}

/// Figures of an embedding.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SphereEmbedReport {
    /// The vertex Tutte's start sent to the north pole (held through the optimization).
    pub pole: u32,
    pub newton: SphereNewtonResult,
    /// The final energy over its lower bound (4 × area: every triangle an isometry); 1 is ideal.
    pub distortion: f64,
}

/// The rest shapes of `mesh`'s faces, scaled so the total area is the unit sphere's 4π.
///
/// # Errors
/// `Numerical` for a degenerate face.
pub fn rest_on_unit_sphere(mesh: &Mesh) -> Result<Vec<RestTriangle>> {
    multires::rest_on_unit_sphere(mesh.positions(), &mesh.face_indices())
}

/// Embeds the closed genus-0 `mesh` on the unit sphere, bijectively.
///
/// # Errors
/// `Invalid` when the mesh is not one closed genus-0 surface; `Numerical` when a solve fails or
/// the result is not a bijective spherical triangulation; `Cancelled`.
pub fn embed_sphere(mesh: &Mesh, opts: &SphereEmbedOptions, progress: &dyn Progress) -> Result<SphereEmbedding> {
    let s = topology::summary(mesh);
    if s.components != 1 || s.boundary_loops != 0 || s.genus != 0 {
        return Err(InputError::Invalid(format!(
            "a sphere embedding needs one closed genus-0 surface (components {}, boundary loops {}, genus {})",
            s.components, s.boundary_loops, s.genus
        ))
        .into());
    }
    let mut hierarchy = Hierarchy::new(mesh, BASE_VERTICES)?;
    let base = hierarchy.base();
    let base_pole = default_pole(base);
    let tutte = tutte_sphere(base, base_pole)?;
    let start = check(&tutte, &base.face_indices());
    if !start.is_bijective() {
        return Err(Error::Numerical(format!(
            "Tutte's sphere embedding is not bijective ({} triangles not positive, degree {:.6})",
            start.negative.len(),
            start.degree
        )));
    }
    progress.check()?;
    // Points by input vertex; the ones not yet inserted are placed when their split is undone.
    let pole = hierarchy.kept()[base_pole.idx()];
    let mut points = vec![P3::new(0.0, 0.0, 1.0); mesh.n_vertices()];
    for (i, v) in hierarchy.kept().iter().enumerate() {
        points[v.idx()] = tutte[i];
    }
    // The pole is held: the energy is invariant under rotations, and holding one point removes
    // two of their three directions from the Newton systems.
    let held = [pole.0];
    let mut total =
        SphereNewtonResult { iterations: 0, energy_before: 0.0, energy_after: 0.0, backtracks: 0, converged: false };
    loop {
        let level = if hierarchy.is_done() || total.energy_before == 0.0 {
            opts.newton
        } else {
            SphereNewtonOptions { max_iterations: LEVEL_ITERATIONS.min(opts.newton.max_iterations), ..opts.newton }
        };
        let r = hierarchy.optimize(&mut points, &held, &level, progress)?;
        tracing::debug!(vertices = hierarchy.alive_count(), ?r, "sphere level");
        total.iterations += r.iterations;
        total.backtracks += r.backtracks;
        total.energy_after = r.energy_after;
        total.converged = r.converged;
        if total.energy_before == 0.0 {
            total.energy_before = r.energy_before;
        }
        if hierarchy.is_done() {
            break;
        }
        let target = (hierarchy.alive_count() as f64 * LEVEL_GROWTH).ceil() as usize;
        hierarchy.refine_to(target, &mut points)?;
        progress.check()?;
    }
    let tris = mesh.face_indices();
    let end = check(&points, &tris);
    if !end.is_bijective() {
        return Err(Error::Numerical(format!(
            "the sphere embedding lost bijectivity ({} triangles not positive, degree {:.6})",
            end.negative.len(),
            end.degree
        )));
    }
    // Every triangle an isometry: 4 × the rest area, which is the sphere's 4π.
    let bound = 16.0 * std::f64::consts::PI;
    let r = total;
    Ok(SphereEmbedding {
        points,
        report: SphereEmbedReport { pole: pole.0, newton: r, distortion: r.energy_after / bound },
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::progress::NoProgress;

    #[test]
    fn an_icosphere_embeds_as_itself_up_to_rotation() {
        let mesh = shapes::icosphere(3);
        let e = embed_sphere(&mesh, &SphereEmbedOptions::default(), &NoProgress).unwrap();
        assert!(check(&e.points, &mesh.face_indices()).is_bijective());
        // The icosphere's own placement is nearly isometric to its chords: the optimum is close.
        assert!(e.report.distortion < 1.02, "{:?}", e.report);
        assert!(e.report.newton.energy_after < e.report.newton.energy_before);
    }

    #[test]
    fn a_torus_is_refused() {
        let e = embed_sphere(&shapes::torus(8, 6, 2.0, 0.5), &SphereEmbedOptions::default(), &NoProgress).unwrap_err();
        assert_eq!(e.code(), "invalid_argument");
    }
}
