//! Morphs between remeshes with identical connectivity (Yu & Chuang, section 6): spatial
//! interpolation (linear, or a cubic Hermite spline through the models), multi-target blends
//! with one weight per model, and scheduled interpolation in the wavelet domain, where each
//! resolution level blends on its own start time and speed.

use super::remesh::RemeshGrid;
use super::wavelet;
use crate::mesh::P3;
use serde::{Deserialize, Serialize};

/// Interpolation in time between consecutive models.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum Interpolation {
    #[default]
    Linear,
    /// Cubic Hermite through the models (Catmull–Rom tangents, zero at the ends).
    Spline,
}

/// When one wavelet level starts to blend (time in [0, 1]) and how fast (1 = over the whole morph).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LevelSchedule {
    pub start: f64,
    pub speed: f64,
}

/// Model segment and local time of global time `t` in [0, 1] through `n` models.
fn segment(t: f64, n: usize) -> (usize, f64) {
    let x = t.clamp(0.0, 1.0) * (n - 1) as f64;
    let a = (x.floor() as usize).min(n - 2);
    (a, x - a as f64)
}

/// The spatial morph at time `t` through `models` (at least two) in order.
pub fn spatial(models: &[Vec<P3>], t: f64, interp: Interpolation) -> Vec<P3> {
    let n = models.len();
    if n == 1 {
        return models[0].clone();
    }
    let (a, s) = segment(t, n);
    let b = a + 1;
    // The models themselves at the knots, bit for bit.
    if s == 0.0 {
        return models[a].clone();
    }
    if s == 1.0 {
        return models[b].clone();
    }
    match interp {
        Interpolation::Linear => models[a].iter().zip(&models[b]).map(|(p, q)| p + (q - p) * s).collect(),
        Interpolation::Spline => {
            // Cubic Hermite with Catmull–Rom tangents (one-sided zero at the ends).
            let (h00, h10, h01, h11) = (
                2.0 * s.powi(3) - 3.0 * s * s + 1.0,
                s.powi(3) - 2.0 * s * s + s,
                -2.0 * s.powi(3) + 3.0 * s * s,
                s.powi(3) - s * s,
            );
            (0..models[a].len())
                .map(|v| {
                    let p = |k: usize| models[k][v].coords;
                    let m0 = if a == 0 { nalgebra::Vector3::zeros() } else { (p(b) - p(a - 1)) * 0.5 };
                    let m1 = if b + 1 >= n { nalgebra::Vector3::zeros() } else { (p(b + 1) - p(a)) * 0.5 };
                    P3::from(p(a) * h00 + m0 * h10 + p(b) * h01 + m1 * h11)
                })
                .collect()
        }
    }
}

/// A weighted blend of the models (weights normalized by their sum unless it is zero).
pub fn blend(models: &[Vec<P3>], weights: &[f64]) -> Vec<P3> {
    let sum: f64 = weights.iter().sum();
    let norm = if sum.abs() > 1e-12 { sum } else { 1.0 };
    (0..models[0].len())
        .map(|v| {
            P3::from(models.iter().zip(weights).map(|(m, w)| m[v].coords * (w / norm)).sum::<nalgebra::Vector3<f64>>())
        })
        .collect()
}

/// Default schedule of level `c` of `levels` (0 coarsest): the coarse shape blends over the
/// whole morph, each finer level later and faster, centred on the middle.
pub fn default_schedule(c: usize) -> LevelSchedule {
    let speed = 1.0 + c as f64;
    LevelSchedule { start: 0.5 - 0.5 / speed, speed }
}

/// Per-patch wavelet coefficients of one model.
pub struct Coefficients(Vec<Vec<[f64; 3]>>);

/// Transforms a model's remesh, patch by patch.
pub fn analyze(grid: &RemeshGrid, pos: &[P3]) -> Coefficients {
    Coefficients(
        grid.node
            .iter()
            .map(|nd| {
                let mut x: Vec<[f64; 3]> =
                    nd.iter().map(|&v| [pos[v as usize].x, pos[v as usize].y, pos[v as usize].z]).collect();
                wavelet::forward(&mut x, grid.n);
                x
            })
            .collect(),
    )
}

/// The wavelet-domain morph at time `t` through the analyzed models.
pub fn wavelet_morph(grid: &RemeshGrid, coefs: &[Coefficients], t: f64, schedule: &[LevelSchedule]) -> Vec<P3> {
    let n_vertices = grid.owner.len();
    if coefs.len() == 1 {
        return synthesize(grid, &coefs[0].0, n_vertices);
    }
    let (a, s) = segment(t, coefs.len());
    let m = grid.n + 1;
    let alpha: Vec<f64> = (0..=grid.level as usize)
        .map(|c| {
            let sc = schedule.get(c).copied().unwrap_or_else(|| default_schedule(c));
            ((s - sc.start) * sc.speed).clamp(0.0, 1.0)
        })
        .collect();
    let mixed: Vec<Vec<[f64; 3]>> = (0..grid.node.len())
        .map(|p| {
            let (x, y) = (&coefs[a].0[p], &coefs[a + 1].0[p]);
            (0..m * m)
                .map(|k| {
                    let al = alpha[wavelet::level(k % m, k / m, grid.n) as usize];
                    [0, 1, 2].map(|c| x[k][c] + (y[k][c] - x[k][c]) * al)
                })
                .collect()
        })
        .collect();
    synthesize(grid, &mixed, n_vertices)
}

fn synthesize(grid: &RemeshGrid, coefs: &[Vec<[f64; 3]>], n_vertices: usize) -> Vec<P3> {
    let mut out = vec![P3::origin(); n_vertices];
    let mut set = vec![false; n_vertices];
    for (p, nd) in grid.node.iter().enumerate() {
        let mut x = coefs[p].clone();
        wavelet::inverse(&mut x, grid.n);
        for (k, &v) in nd.iter().enumerate() {
            if !set[v as usize] {
                out[v as usize] = P3::new(x[k][0], x[k][1], x[k][2]);
                set[v as usize] = true;
            }
        }
    }
    out
}
