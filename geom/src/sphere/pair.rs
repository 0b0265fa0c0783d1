//! A map from one closed genus-0 surface onto another, bijective at every step (issue 50).
//!
//! The source's vertices live as points on the target's sphere: a bijective spherical
//! triangulation with the source's faces, carried onto the target surface through the target's
//! own embedding ([`OnTarget`]). So the map is a bijection of the sphere composed with two
//! bijections, at every step, and there is nothing to repair.
//!
//! 1. **Start**: the source's embedding turned by the rotation that best carries its anchors
//!    onto their partners' points on the target's sphere ([`fit_rotation`]).
//! 2. **Landmarks** ([`place_anchors`]): each anchor onto its partner's point, soft then hard.
//! 3. **Global**: the distortion of each source triangle's image, projected on the target's
//!    smooth tangent plane, with Garanzha et al.'s `χ(D, ε)` at a fixed `ε` in place of its
//!    signed Jacobian determinant ([`Measure::Untangle`]): close to the symmetric Dirichlet
//!    energy where images are upright, finite but steep where one faces away from the surface
//!    (where a thin part of one surface met a thick part of the other). Optimizing the chord
//!    energy alone here left strips of mirrored images that cost it nothing (cow: 15 and 41
//!    evaluator flips against 1 and 4, cat -> horse 61 and 62 against 3 and 0).
//! 4. **Untangle** ([`SphereNewton::untangle`]): the images still turned over, turned back with
//!    `ε` on Garanzha's schedule, every image measured by it.
//! 5. **Distortion** ([`SphereNewton::minimize`]): projected Newton on the symmetric Dirichlet
//!    energy of each source triangle against its chord on the target (the evaluator's measure),
//!    anchors held, every accepted step bijective on the sphere and every image upright.
//!
//! A map that keeps turned-over images after the untangling is reported with their count, never
//! as a clean map: the caller fails the job as folded.

use super::align::fit_rotation;
use super::landmarks::{LandmarkReport, place_anchors};
use super::locate::{Located, OnTarget, SphereLocator};
use super::measure::Measure;
use super::multires::rest_on_unit_sphere;
use super::newton::{SphereNewton, SphereNewtonOptions, SphereNewtonResult};
use super::orient::check;
use super::untangle::UntangleResult;
use crate::error::{Error, InputError, Result};
use crate::mesh::{Mesh, P3};
use crate::optim::RestTriangle;
use crate::progress::Progress;
use serde::Serialize;

/// Options for [`sphere_pair`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpherePairOptions {
    /// The distortion optimization on the target.
    pub newton: SphereNewtonOptions,
    /// Untangling steps at most.
    pub untangle_iterations: usize,
    /// Steps at most of the global optimization, in which images may turn over.
    pub global_iterations: usize,
}

impl Default for SpherePairOptions {
    fn default() -> Self {
        Self {
            newton: SphereNewtonOptions { max_iterations: 100, ..SphereNewtonOptions::default() },
            untangle_iterations: 100,
            global_iterations: 250,
        }
    }
}

/// The source's vertices on the target.
#[derive(Debug, Clone, PartialEq)]
pub struct SpherePair {
    /// Per source vertex, its point on the target's sphere; with the source's faces, a
    /// bijective spherical triangulation.
    pub points: Vec<P3>,
    /// Per source vertex, where it lands on the target (an anchor exactly on its partner).
    pub located: Vec<Located>,
    pub report: SpherePairReport,
}

/// Figures of a pair map.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct SpherePairReport {
    pub landmarks: LandmarkReport,
    /// The global optimization, in which images may turn over.
    pub global: SphereNewtonResult,
    pub untangle: Option<UntangleResult>,
    pub newton: Option<SphereNewtonResult>,
    /// Source triangles whose images still face away from the target (0 for a clean map).
    pub turned_over: usize,
    /// The final energy over its lower bound (4 × the target's area); 1 is an isometry.
    pub distortion: f64,
}

/// Maps the closed genus-0 `source` onto `target`, each given with its bijective sphere
/// embedding, with `anchors` (source vertex, target vertex) exact.
///
/// # Errors
/// `Invalid` for embeddings of the wrong length or not bijective; `Anchors` for an anchor out of
/// range or a vertex anchored twice; as [`place_anchors`]; `Numerical` when a Newton system
/// cannot be solved; `Cancelled`.
pub fn sphere_pair(
    source: &Mesh,
    source_sphere: &[P3],
    target: &Mesh,
    target_sphere: &[P3],
    anchors: &[(u32, u32)],
    opts: &SpherePairOptions,
    progress: &dyn Progress,
) -> Result<SpherePair> {
    let tris = source.face_indices();
    if source_sphere.len() != source.n_vertices() || target_sphere.len() != target.n_vertices() {
        return Err(InputError::Invalid("a sphere embedding does not match its mesh".into()).into());
    }
    if !check(source_sphere, &tris).is_bijective() || !check(target_sphere, &target.face_indices()).is_bijective() {
        return Err(InputError::Invalid("a sphere embedding is not bijective".into()).into());
    }
    check_anchors(anchors, source.n_vertices(), target.n_vertices())?;
    // 1. Start.
    let goals: Vec<(u32, P3)> = anchors.iter().map(|&(s, t)| (s, target_sphere[t as usize])).collect();
    let from: Vec<P3> = anchors.iter().map(|&(s, _)| source_sphere[s as usize]).collect();
    let to: Vec<P3> = goals.iter().map(|g| g.1).collect();
    let rotation = fit_rotation(&from, &to);
    let mut s: Vec<P3> = source_sphere.iter().map(|p| rotation * p).collect();
    // 2. Landmarks, on the source's own distortion.
    let unit_rest = rest_on_unit_sphere(source.positions(), &tris)?;
    let landmarks = place_anchors(&tris, &unit_rest, &mut s, &goals, progress)?;
    // 3–5. On the target, the source's triangles at the target's scale.
    let rest = scaled_rest(source, target, &tris)?;
    let held: Vec<u32> = anchors.iter().map(|a| a.0).collect();
    let mut newton = SphereNewton::new(s.len(), tris.clone(), rest, &held)?;
    let image = OnTarget::new(SphereLocator::new(target, target_sphere), s.len());
    let global = minimize_refreshed(
        &mut newton,
        Measure::Untangle(GLOBAL_EPS),
        &image,
        &mut s,
        &opts.newton,
        opts.global_iterations,
        progress,
    )?;
    let mut untangle = None;
    let mut turned = newton.turned_over(&image, &s).unwrap_or(usize::MAX);
    if turned > 0 {
        let r = newton.untangle(&image, &mut s, opts.untangle_iterations, SHRINK, &opts.newton, progress)?;
        turned = r.after;
        untangle = Some(r);
    }
    let mut result = None;
    if turned == 0 {
        let iterations = opts.newton.max_iterations;
        result = Some(minimize_refreshed(
            &mut newton,
            Measure::Upright,
            &image,
            &mut s,
            &opts.newton,
            iterations,
            progress,
        )?);
    }
    if !check(&s, &tris).is_bijective() {
        return Err(Error::Internal("the pair map lost bijectivity on the sphere".into()));
    }
    let energy =
        result.map_or_else(|| newton.energy_as(Measure::Untangle(1e-10), &image, &s), |r| Some(r.energy_after));
    let located = locate_all(&image, &s, anchors, target);
    let bound = 4.0 * target_area(target);
    Ok(SpherePair {
        points: s,
        located,
        report: SpherePairReport {
            landmarks,
            global,
            untangle,
            newton: result,
            turned_over: turned,
            distortion: energy.map_or(f64::INFINITY, |e| e / bound),
        },
    })
}

/// The global optimization's `ε`: images with `D ≫ ε` (most) are measured as by the symmetric
/// Dirichlet energy; `ε = 0.1` froze more maps in folds, `ε = 1` lost the orientation (cow:
/// 6 / 1 and 4 / 13 evaluator flips against 1 / 4 at 0.3).
const GLOBAL_EPS: f64 = 0.3;

/// Iterations between refreshes of the shrink barrier's reference.
const REFRESH: usize = 10;
/// A spherical triangle pays the shrink barrier below this fraction of its size at the last
/// refresh.
const SHRINK: f64 = 0.5;

/// [`SphereNewton::minimize_as`] for `iterations` in all, in rounds of [`REFRESH`] iterations,
/// each round's shrink barrier referred to where it starts: no spherical triangle shrinks by
/// more than a fixed factor in one round without paying, so the Newton model sees the
/// inversions on the sphere coming instead of the line search cutting each step short.
fn minimize_refreshed(
    newton: &mut SphereNewton,
    measure: Measure,
    image: &OnTarget<'_>,
    s: &mut Vec<P3>,
    opts: &SphereNewtonOptions,
    iterations: usize,
    progress: &dyn Progress,
) -> Result<SphereNewtonResult> {
    let mut total: Option<SphereNewtonResult> = None;
    let mut done = 0;
    while done < iterations {
        newton.set_reference(s, SHRINK);
        let round = SphereNewtonOptions { max_iterations: REFRESH.min(iterations - done), ..*opts };
        let r = newton.minimize_as(measure, image, s, &round, progress)?;
        done += round.max_iterations;
        match &mut total {
            None => total = Some(r),
            Some(t) => {
                t.iterations += r.iterations;
                t.backtracks += r.backtracks;
                t.converged = r.converged;
            }
        }
        if r.converged {
            break;
        }
    }
    newton.clear_reference();
    if let Some(t) = &mut total {
        t.energy_after = newton.energy_as(measure, image, s).unwrap_or(f64::INFINITY);
    }
    Ok(total.unwrap_or(SphereNewtonResult {
        iterations: 0,
        energy_before: 0.0,
        energy_after: 0.0,
        backtracks: 0,
        converged: true,
    }))
}

/// Anchors in range, no vertex anchored twice on either side.
fn check_anchors(anchors: &[(u32, u32)], n_source: usize, n_target: usize) -> Result<()> {
    let mut seen_s = vec![false; n_source];
    let mut seen_t = vec![false; n_target];
    for &(s, t) in anchors {
        let (si, ti) = (s as usize, t as usize);
        if si >= n_source || ti >= n_target {
            return Err(InputError::Anchors(format!("anchor ({s}, {t}) is outside the meshes")).into());
        }
        if std::mem::replace(&mut seen_s[si], true) || std::mem::replace(&mut seen_t[ti], true) {
            return Err(InputError::Anchors(format!(
                "anchor ({s}, {t}) repeats a vertex another anchor uses: a bijection cannot honour both"
            ))
            .into());
        }
    }
    Ok(())
}

fn target_area(target: &Mesh) -> f64 {
    mesh_area(target)
}

fn mesh_area(mesh: &Mesh) -> f64 {
    let p = mesh.positions();
    mesh.face_indices()
        .iter()
        .map(|t| 0.5 * (p[t[1] as usize] - p[t[0] as usize]).cross(&(p[t[2] as usize] - p[t[0] as usize])).norm())
        .sum()
}

/// The source's rest triangles scaled so their total area is the target's.
///
/// # Errors
/// `Numerical` for a degenerate face.
pub fn scaled_rest(source: &Mesh, target: &Mesh, tris: &[[u32; 3]]) -> Result<Vec<RestTriangle>> {
    let scale = (target_area(target) / mesh_area(source)).sqrt();
    let p = source.positions();
    tris.iter()
        .enumerate()
        .map(|(f, t)| {
            RestTriangle::from_3d(t.map(|v| P3::from(p[v as usize].coords * scale)))
                .ok_or_else(|| Error::Numerical(format!("source face {f} is degenerate")))
        })
        .collect()
}

/// Every source vertex located on the target; an anchor exactly on its partner vertex.
fn locate_all(image: &OnTarget<'_>, s: &[P3], anchors: &[(u32, u32)], target: &Mesh) -> Vec<Located> {
    let mut out: Vec<Located> = s.iter().enumerate().map(|(v, p)| image.locate(v as u32, p)).collect();
    let tris = target.face_indices();
    for &(sv, tv) in anchors {
        let l = &mut out[sv as usize];
        let corner = tris[l.face as usize].iter().position(|&x| x == tv);
        match corner {
            Some(k) => l.bary = std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 }),
            None => {
                // Located in a neighbouring face across the vertex: take any face around it.
                if let Some((f, k)) =
                    tris.iter().enumerate().find_map(|(f, t)| t.iter().position(|&x| x == tv).map(|k| (f, k)))
                {
                    *l = Located { face: f as u32, bary: std::array::from_fn(|i| if i == k { 1.0 } else { 0.0 }) };
                }
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::progress::NoProgress;
    use crate::sphere::{SphereEmbedOptions, embed_sphere};

    #[test]
    fn a_twisted_copy_maps_bijectively_with_anchors_exact_and_every_image_upright() {
        let (a, b) = (shapes::icosphere(3), shapes::twisted_icosphere(3));
        let ea = embed_sphere(&a, &SphereEmbedOptions::default(), &NoProgress).unwrap();
        let eb = embed_sphere(&b, &SphereEmbedOptions::default(), &NoProgress).unwrap();
        let anchors = [(0, 0), (7, 7), (40, 40), (300, 300)];
        let m =
            sphere_pair(&a, &ea.points, &b, &eb.points, &anchors, &SpherePairOptions::default(), &NoProgress).unwrap();
        assert!(check(&m.points, &a.face_indices()).is_bijective());
        assert_eq!(m.report.turned_over, 0, "{:?}", m.report);
        let tris = b.face_indices();
        for &(s, t) in &anchors {
            let l = m.located[s as usize];
            let k = l.bary.iter().position(|&x| x == 1.0).expect("an anchor sits on a vertex");
            assert_eq!(tris[l.face as usize][k], t);
        }
        let newton = m.report.newton.expect("the distortion stage ran");
        assert!(newton.energy_after <= newton.energy_before);
        assert!(m.report.distortion.is_finite() && m.report.distortion >= 1.0, "{:?}", m.report);
    }

    #[test]
    fn a_vertex_anchored_twice_is_refused_by_name() {
        let a = shapes::icosphere(1);
        let e = embed_sphere(&a, &SphereEmbedOptions::default(), &NoProgress).unwrap();
        let err = sphere_pair(
            &a,
            &e.points,
            &a,
            &e.points,
            &[(0, 1), (2, 1), (3, 3)],
            &SpherePairOptions::default(),
            &NoProgress,
        )
        .unwrap_err();
        assert_eq!(err.code(), "invalid_anchors");
        assert!(err.to_string().contains("(2, 1)"), "{err}");
    }
}
