//! The landmark phase: every anchor's point brought onto its partner's on the target sphere
//! while every spherical triangle stays positive (Schmidt, Pieper & Kobbelt 2023, §5: soft,
//! then hard).
//!
//! 1. **Soft.** The sphere embedding's own distortion ([`OnSphere`]) plus a pull of each anchor
//!    toward its goal, whose weight grows round by round, minimized by injective Newton; a
//!    shrink barrier against the start keeps the pull from squashing the triangles it drags
//!    others through.
//! 2. **Hard.** With the anchors held, each one moves by itself along the gnomonic path to its
//!    goal (`normalize(p + t (g / (p · g) − p))`, which is `g` at `t = 1`), as far as the first
//!    inversion of a triangle around it allows ([`first_inversion`]); the free vertices relax;
//!    again until every anchor sits on its goal exactly.
//!
//! Any distinct anchors on a sphere can be honoured (the configuration space of `k` points on
//! the sphere is connected); anchors still off their goals after the last round are named in a
//! numerical failure, never returned as a folded or inexact map.

use super::max_step::first_inversion;
use super::measure::OnSphere;
use super::newton::{SphereNewton, SphereNewtonOptions};
use super::orient::orient;
use crate::error::{Error, Result};
use crate::mesh::{P3, V3};
use crate::optim::RestTriangle;
use crate::progress::Progress;
use serde::Serialize;

/// Soft rounds, the pull's weight growing by [`WEIGHT_GROWTH`] each.
const SOFT_ROUNDS: usize = 6;
const WEIGHT_GROWTH: f64 = 4.0;
/// Hard rounds at most.
const HARD_ROUNDS: usize = 30;
/// Triangles pay the shrink barrier below this fraction of their size at the phase's start.
const SHRINK_FRACTION: f64 = 0.25;

/// What the landmark phase did.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LandmarkReport {
    pub soft_iterations: usize,
    pub hard_rounds: usize,
    /// The largest anchor's distance to its goal (chord) after the soft phase.
    pub soft_residual: f64,
}

/// Moves each `goals` vertex of the bijective spherical triangulation `s` onto its goal, in
/// place, keeping every triangle positive.
///
/// # Errors
/// `Numerical` naming the anchors that did not reach their goals, or `Numerical` when a Newton system
/// cannot be solved; `Cancelled`.
pub fn place_anchors(
    triangles: &[[u32; 3]],
    rest: &[RestTriangle],
    s: &mut Vec<P3>,
    goals: &[(u32, P3)],
    progress: &dyn Progress,
) -> Result<LandmarkReport> {
    let mut report = LandmarkReport { soft_iterations: 0, hard_rounds: 0, soft_residual: 0.0 };
    if goals.is_empty() {
        return Ok(report);
    }
    let opts = SphereNewtonOptions { max_iterations: 20, ..SphereNewtonOptions::default() };
    // Soft.
    let mut soft = SphereNewton::new(s.len(), triangles.to_vec(), rest.to_vec(), &[])?;
    soft.set_reference(s, SHRINK_FRACTION);
    let gap = |s: &[P3]| goals.iter().map(|(v, g)| (s[*v as usize] - g).norm_squared()).sum::<f64>();
    let e0 = soft.energy(&OnSphere, s).unwrap_or(1.0);
    let mut weight = e0 / gap(s).max(1e-12);
    for _ in 0..SOFT_ROUNDS {
        soft.set_pull(goals, weight)?;
        let r = soft.minimize(&OnSphere, s, &opts, progress)?;
        report.soft_iterations += r.iterations;
        weight *= WEIGHT_GROWTH;
    }
    report.soft_residual = goals.iter().map(|(v, g)| (s[*v as usize] - g).norm()).fold(0.0, f64::max);
    // Hard.
    let held: Vec<u32> = goals.iter().map(|g| g.0).collect();
    let mut hard = SphereNewton::new(s.len(), triangles.to_vec(), rest.to_vec(), &held)?;
    hard.set_reference(s, SHRINK_FRACTION);
    let mut around = vec![Vec::new(); s.len()];
    for (t, tri) in triangles.iter().enumerate() {
        for &v in tri {
            around[v as usize].push(t);
        }
    }
    for _ in 0..HARD_ROUNDS {
        if goals.iter().all(|(v, g)| s[*v as usize] == *g) {
            return Ok(report);
        }
        progress.check()?;
        report.hard_rounds += 1;
        for &(v, g) in goals {
            step_toward(triangles, &around[v as usize], s, v, &g);
        }
        hard.minimize(&OnSphere, s, &opts, progress)?;
    }
    let off: Vec<String> = goals.iter().filter(|(v, g)| s[*v as usize] != *g).map(|(v, _)| v.to_string()).collect();
    if off.is_empty() {
        return Ok(report);
    }
    Err(Error::Numerical(format!(
        "the anchors at source vertices {} did not reach their partners in {HARD_ROUNDS} rounds of the landmark phase",
        off.join(", ")
    )))
}

/// Moves vertex `v` toward `g` as far as its triangles (`star`) stay positive: all the way
/// when nothing inverts on the path, else 80% of the way to the first inversion.
fn step_toward(triangles: &[[u32; 3]], star: &[usize], s: &mut [P3], v: u32, g: &P3) {
    let p = s[v as usize];
    if p == *g {
        return;
    }
    let c = p.coords.dot(&g.coords);
    // The gnomonic path reaches `g` at t = 1 when `g` is in `p`'s hemisphere; beyond it, one
    // radian of tangent step toward it.
    let (d, reach) =
        if c > 0.05 { (g.coords / c - p.coords, true) } else { ((g.coords - p.coords * c).normalize(), false) };
    let zero = V3::zeros();
    let first = star
        .iter()
        .map(|&t| {
            let tri = triangles[t];
            let dirs = tri.map(|x| if x == v { &d } else { &zero });
            first_inversion(tri.map(|x| &s[x as usize]), dirs, 1.0)
        })
        .fold(f64::INFINITY, f64::min);
    let mut t = if first > 1.0 { 1.0 } else { 0.8 * first };
    while t > 1e-12 {
        let q = if reach && t == 1.0 { *g } else { P3::from((p.coords + d * t).normalize()) };
        s[v as usize] = q;
        if star.iter().all(|&k| {
            let [a, b, c] = triangles[k].map(|x| &s[x as usize]);
            orient(a, b, c) > 0.0
        }) {
            return;
        }
        t *= 0.5;
    }
    s[v as usize] = p;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::progress::NoProgress;
    use crate::sphere::multires::rest_on_unit_sphere;
    use crate::sphere::orient::check;

    #[test]
    fn anchors_reach_their_goals_exactly_and_the_triangulation_stays_bijective() {
        let mesh = shapes::icosphere(2);
        let tris = mesh.face_indices();
        let rest = rest_on_unit_sphere(mesh.positions(), &tris).unwrap();
        let mut s: Vec<P3> = mesh.positions().iter().map(|p| P3::from(p.coords.normalize())).collect();
        // Three anchors each moved well off its place (a twist about the z axis).
        let rot = nalgebra::Rotation3::from_axis_angle(&V3::z_axis(), 0.6);
        let goals: Vec<(u32, P3)> = [0u32, 5, 20].iter().map(|&v| (v, rot * s[v as usize])).collect();
        let mut twisted = goals.clone();
        twisted[0].1 = nalgebra::Rotation3::from_axis_angle(&V3::x_axis(), 0.5) * twisted[0].1;
        place_anchors(&tris, &rest, &mut s, &twisted, &NoProgress).unwrap();
        for (v, g) in &twisted {
            assert_eq!(s[*v as usize], *g);
        }
        assert!(check(&s, &tris).is_bijective());
    }
}
