//! Every tolerance of the crate, in one place, with the reason for its value.

/// Relative area (to the largest face) under which a triangle counts as degenerate.
/// Matches `meshmetrics.py` (`1e-14 * As.max()`).
pub const DEGENERATE_AREA_REL: f64 = 1e-14;
/// Smallest singular value used in distortion ratios (matches `meshmetrics.py`).
pub const MIN_SINGULAR_VALUE: f64 = 1e-12;
/// Guard against division by zero in normalisations (matches `meshmetrics.py`).
pub const TINY: f64 = 1e-300;
/// Relative residual a sparse solve must reach, or it is reported as a numerical failure.
pub const SOLVE_RESIDUAL_REL: f64 = 1e-8;
/// A line search gives up when its step, as a fraction of the Newton step, falls below this.
pub const MIN_STEP: f64 = 1e-12;
/// Barycentric coordinates within this of [0, 1] are clamped when locating points.
pub const BARY_EPS: f64 = 1e-12;
/// A planar triangle with signed area at or below this times the mean |area| is flipped or degenerate.
pub const PLANAR_DEGENERATE_REL: f64 = 1e-14;
/// A planar triangle with |signed area| (twice the area) at or below this times its longest edge
/// squared is degenerate: its three corners are collinear up to rounding.
pub const PLANAR_COLLINEAR_REL: f64 = 1e-12;
/// Largest |coordinate| a mesh may have: lengths, areas and products of up to four lengths
/// (squared areas, Heron's formula, squared cotangent weights) stay finite in f64
/// ((2·√3·1e75)^4 ≈ 2e302 < 1.8e308).
pub const MAX_COORDINATE: f64 = 1e75;
