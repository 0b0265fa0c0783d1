//! Integer homology classes of basis loops, and the induced map on H1 in reference bases.
//!
//! Bases of one mesh live on different refinements, so their loops are brought back to the
//! original mesh by a simplicial approximation of the identity (every refined vertex goes to
//! the vertex of its carrier face with the largest barycentric coordinate, ties to the lower
//! id: adjacent refined vertices then go to equal or adjacent original vertices), where the
//! integer tree–cotree cocycles ([`super::cocycle::integer_cohomology`]) give coordinates.
//! With `A_k` the coordinates of basis `k`'s loops, basis `k` reads in basis 0 as
//! `P_k = A_0⁻¹ A_k`, and a map inducing `H` between bases `ks` and `kt` induces
//! `P_t H P_s⁻¹` between the reference bases (basis 0 on each mesh).

use super::basis::CanonicalBasisResult;
use super::cocycle::IntCohomology;
use crate::error::{Error, Result};
use crate::mesh::{Mesh, VertexId};
use nalgebra::DMatrix;

/// Per refined vertex: the original vertex it is approximated by.
fn approximation(b: &CanonicalBasisResult, original: &Mesh) -> Vec<VertexId> {
    let r = &b.refined;
    let mut to = vec![VertexId::INVALID; r.mesh.n_vertices()];
    for (f, t) in r.mesh.faces().iter().enumerate() {
        let of = original.face(r.face_origin[f]);
        for (k, v) in t.iter().enumerate() {
            if to[v.idx()].is_valid() {
                continue;
            }
            let bc = r.corner_bary[f][k];
            let best = (0..3).max_by(|&x, &y| bc[x].total_cmp(&bc[y]).then_with(|| of[y].0.cmp(&of[x].0))).unwrap_or(0);
            to[v.idx()] = of[best];
        }
    }
    to
}

/// Coordinates (columns) of the basis loops in the cohomology's generators.
///
/// # Errors
/// `Internal` when an approximated loop is not an edge path (a bug).
pub fn loop_classes(b: &CanonicalBasisResult, original: &Mesh, coh: &IntCohomology) -> Result<DMatrix<f64>> {
    let to = approximation(b, original);
    let n = b.loops.len();
    let mut a = DMatrix::zeros(coh.rank, n);
    for (j, l) in b.loops.iter().enumerate() {
        let path: Vec<VertexId> = l.iter().map(|v| to[v.idx()]).collect();
        let c = coh
            .class_of(original, &path)
            .ok_or_else(|| Error::Internal(format!("classes: loop {j} does not approximate to an edge path")))?;
        for (i, x) in c.iter().enumerate() {
            a[(i, j)] = *x as f64;
        }
    }
    Ok(a)
}

/// `P = A_ref⁻¹ A_k`, rounded (it is unimodular).
///
/// # Errors
/// `Internal` when the reference loops are not a basis or `P` is not integral.
pub fn change_of_basis(a_ref: &DMatrix<f64>, a_k: &DMatrix<f64>) -> Result<DMatrix<f64>> {
    let inv = a_ref
        .clone()
        .try_inverse()
        .ok_or_else(|| Error::Internal("classes: reference loops are not a basis".into()))?;
    let p = inv * a_k;
    let r = p.map(f64::round);
    if (&p - &r).amax() > 1e-6 {
        return Err(Error::Internal("classes: change of basis is not integral".into()));
    }
    Ok(r)
}

/// `P_t H P_s⁻¹` as integers.
///
/// # Errors
/// `Internal` when `P_s` is singular or the product is not integral.
pub fn in_reference(h: &[Vec<i32>], p_s: &DMatrix<f64>, p_t: &DMatrix<f64>) -> Result<Vec<Vec<i32>>> {
    let n = h.len();
    let hm = DMatrix::from_fn(n, n, |i, j| f64::from(h[i][j]));
    let inv = p_s.clone().try_inverse().ok_or_else(|| Error::Internal("classes: singular change of basis".into()))?;
    let r = p_t * hm * inv;
    let out: Vec<Vec<i32>> = (0..n).map(|i| (0..n).map(|j| r[(i, j)].round() as i32).collect()).collect();
    if (0..n).any(|i| (0..n).any(|j| (r[(i, j)] - f64::from(out[i][j])).abs() > 1e-6)) {
        return Err(Error::Internal("classes: induced map is not integral".into()));
    }
    Ok(out)
}
