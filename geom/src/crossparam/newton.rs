//! Global projected-Newton relaxation of a map's symmetric Dirichlet energy: every free image
//! moves at once, in the tangent plane of the target face it lies on, by one sparse Newton
//! step whose per-face Hessians are made positive semi-definite by clamping their eigenvalues
//! (Teran, Sifakis, Irving & Fedkiw 2005; the projected Newton of Smith, de Goes & Kim 2019
//! for the symmetric Dirichlet energy). A backtracking line search keeps a step only if the
//! total energy drops and no face that faced the way the target does turns against it; the
//! images are projected back onto the target near where they were.
//!
//! The Gauss–Seidel moves of [`super::smooth`] fix each vertex's neighbours while it moves, so
//! they cannot shift a whole region: a limb whose tip the patch maps left short (the tip of the
//! target's limb then covered by a few long faces) stays short. A global step moves the region
//! together, so its energy can drop where no single vertex's can. Measured, it lowers the L2
//! stretch by 0.001–0.004 but leaves such a limb where it is (a local minimum of the
//! surface-constrained energy; ARCHITECTURE.md), and costs four to six times the sweeps, so it
//! is opt-in.

use super::smooth::SourceFrame;
use crate::error::{Error, Result};
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, P3, V3, VertexId};
use crate::progress::Progress;
use crate::topology::Locator;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{Pair, SparseColMat, SymbolicSparseColMat};
use faer::{Mat, Side};
use nalgebra::{SMatrix, SymmetricEigen};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Options for [`relax_newton`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct NewtonOptions {
    /// Newton steps at most (0, the default, turns the stage off: it costs four to five times
    /// the smoothing sweeps for an L2 stretch about 0.001 to 0.005 lower).
    pub iterations: usize,
    /// Stop once a step lowers the energy by less than this fraction of it.
    pub tolerance: f64,
    /// An image moves at most this many times the mean length of its mapped edges per step.
    pub max_move: f64,
    /// Vertices of faces whose energy per unit area exceeds this (4 for an isometry) stay put.
    pub max_density: f64,
    /// Vertices of faces whose normal makes an angle with this cosine or less with the target's
    /// normal at a corner stay put (a small move could turn such a face over).
    pub min_cos: f64,
}

impl Default for NewtonOptions {
    fn default() -> Self {
        Self { iterations: 0, tolerance: 1e-4, max_move: 1.0, max_density: 40.0, min_cos: 0.3 }
    }
}

/// What [`relax_newton`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct NewtonReport {
    /// Steps taken (accepted by the line search).
    pub steps: usize,
    pub energy_before: f64,
    pub energy_after: f64,
}

/// Gradient and Hessian of [`SourceFrame::energy`] with respect to the mapped triangle's three
/// corners, each moving in the plane of its own orthonormal pair `t[k]` (variable `2k + r` is
/// corner `k` along `t[k][r]`). With `J = [c0 c1]`, corner `k` moving by `δ` changes the
/// columns by `α_k δ` and `β_k δ`; the energy `A (F + F / D)` (`F = |c0|² + |c1|²`,
/// `D = |c0|²|c1|² − (c0·c1)²`) is differentiated through `|c0|²`, `|c1|²` and `c0·c1`, all
/// quadratic in the corners. `None` for a degenerate mapped triangle.
pub(crate) fn face_derivatives(
    fr: &SourceFrame,
    m: [P3; 3],
    scale: f64,
    t: &[[V3; 2]; 3],
) -> Option<([f64; 6], SMatrix<f64, 6, 6>)> {
    let [[a, b], [_, c]] = fr.inverse();
    let super::smooth::Jacobian { c0, c1, n0, n1, d, det: dd } = fr.jacobian(m, scale)?;
    let al = [-scale * a, scale * a, 0.0];
    let be = [-scale * (b + c), scale * b, scale * c];
    let tv = |i: usize| t[i / 2][i % 2];
    let (mut gn0, mut gn1, mut gd) = ([0.0; 6], [0.0; 6], [0.0; 6]);
    for i in 0..6 {
        let (k, ti) = (i / 2, tv(i));
        gn0[i] = 2.0 * al[k] * c0.dot(&ti);
        gn1[i] = 2.0 * be[k] * c1.dot(&ti);
        gd[i] = al[k] * c1.dot(&ti) + be[k] * c0.dot(&ti);
    }
    let f = n0 + n1;
    let gf: [f64; 6] = std::array::from_fn(|i| gn0[i] + gn1[i]);
    let gdd: [f64; 6] = std::array::from_fn(|i| n1 * gn0[i] + n0 * gn1[i] - 2.0 * d * gd[i]);
    let area = fr.area();
    let (inv, inv2) = (1.0 / dd, 1.0 / (dd * dd));
    let grad: [f64; 6] = std::array::from_fn(|i| area * (gf[i] * (1.0 + inv) - f * gdd[i] * inv2));
    let mut hess = SMatrix::<f64, 6, 6>::zeros();
    for i in 0..6 {
        for j in 0..6 {
            let (k, l) = (i / 2, j / 2);
            let tt = tv(i).dot(&tv(j));
            let hn0 = 2.0 * al[k] * al[l] * tt;
            let hn1 = 2.0 * be[k] * be[l] * tt;
            let hd = (al[k] * be[l] + be[k] * al[l]) * tt;
            let hdd = gn0[i] * gn1[j] + gn1[i] * gn0[j] + n1 * hn0 + n0 * hn1 - 2.0 * gd[i] * gd[j] - 2.0 * d * hd;
            hess[(i, j)] = area
                * ((hn0 + hn1) * (1.0 + inv) - (gf[i] * gdd[j] + gdd[i] * gf[j]) * inv2 - f * hdd * inv2
                    + 2.0 * f * gdd[i] * gdd[j] * inv2 * inv);
        }
    }
    Some((grad, hess))
}

/// `h` with its negative eigenvalues clamped to zero (the closest positive semi-definite
/// matrix).
fn clamp_psd(h: SMatrix<f64, 6, 6>) -> SMatrix<f64, 6, 6> {
    let h = (h + h.transpose()) * 0.5;
    let eig = SymmetricEigen::new(h);
    if eig.eigenvalues.iter().all(|&l| l >= 0.0) {
        return h;
    }
    let l = eig.eigenvalues.map(|x| x.max(0.0));
    eig.eigenvectors * SMatrix::<f64, 6, 6>::from_diagonal(&l) * eig.eigenvectors.transpose()
}

/// An orthonormal pair spanning the plane normal to `n` (not zero).
pub(crate) fn tangents(n: V3) -> [V3; 2] {
    let n = n.normalize();
    let t1 = if n.x.abs() < 0.9 { V3::x().cross(&n) } else { V3::y().cross(&n) }.normalize();
    [t1, n.cross(&t1)]
}

/// Whether the mapped face `m` faces the way the target does at one corner's face at least
/// (not folded by the evaluator's rule, which needs all three corners against).
fn faces_forward(target: &Mesh, m: [P3; 3], faces: [FaceId; 3]) -> bool {
    let nm = (m[1] - m[0]).cross(&(m[2] - m[0]));
    faces.iter().any(|&g| nm.dot(&target.face_normal_raw(g)) > 0.0)
}

/// Relaxes `map: source -> target` by global projected-Newton steps; `fixed` vertices (the
/// anchors) and boundary vertices never move. The map only changes by accepted steps, each
/// lowering the energy and turning no forward face against the target.
///
/// # Errors
/// `Cancelled`; `Internal` if the target's BVH cannot be built; `Numerical` if the sparse
/// system cannot be assembled.
pub fn relax_newton(
    source: &Mesh,
    target: &Mesh,
    map: &mut SurfaceMap,
    fixed: &[VertexId],
    opts: &NewtonOptions,
    progress: &mut dyn Progress,
) -> Result<NewtonReport> {
    let mut rep = NewtonReport::default();
    if opts.iterations == 0 {
        return Ok(rep);
    }
    let n = source.n_vertices();
    let scale = (source.area() / target.area().max(f64::MIN_POSITIVE)).sqrt();
    let mut index = vec![u32::MAX; n];
    let mut is_fixed = vec![false; n];
    for v in fixed {
        is_fixed[v.idx()] = true;
    }
    let frames: Vec<Option<SourceFrame>> =
        (0..source.n_faces()).map(|f| SourceFrame::new(source.face_points(FaceId::from_idx(f)))).collect();
    let face_list: Vec<[VertexId; 3]> = (0..source.n_faces()).map(|f| source.face(FaceId::from_idx(f))).collect();
    let mut pos: Vec<P3> = (0..n).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    // Vertices of badly distorted or backward faces stay where they are: such a face's
    // Hessian is ill-conditioned (its gradient dwarfs the rest) and tiny moves turn it over;
    // the one-vertex repairs deal with them.
    for (tri, fr) in face_list.iter().zip(&frames) {
        let m = tri.map(|w| pos[w.idx()]);
        let density = fr.and_then(|fr| Some(fr.energy(m, scale)? / fr.area())).unwrap_or(f64::INFINITY);
        let nm = (m[1] - m[0]).cross(&(m[2] - m[0]));
        let cos = tri
            .iter()
            .map(|w| {
                let nt = target.face_normal_raw(map.face[w.idx()]);
                nm.dot(&nt) / (nm.norm() * nt.norm()).max(f64::MIN_POSITIVE)
            })
            .fold(f64::INFINITY, f64::min);
        if density > opts.max_density || cos.is_nan() || cos <= opts.min_cos {
            for w in tri {
                is_fixed[w.idx()] = true;
            }
        }
    }
    let mut free = 0usize;
    for v in 0..n {
        if !is_fixed[v] && !source.is_boundary_vertex(VertexId::from_idx(v)) {
            index[v] = free as u32;
            free += 1;
        }
    }
    if free == 0 {
        return Ok(rep);
    }
    let loc = Locator::new(target)?;
    // The pattern: every pair of free corners of a face, both coordinates (one 2x2 block).
    let mut pairs: Vec<Pair<usize, usize>> = Vec::new();
    for tri in &face_list {
        for &p in tri {
            for &q in tri {
                let (ip, iq) = (index[p.idx()], index[q.idx()]);
                if ip == u32::MAX || iq == u32::MAX {
                    continue;
                }
                for r in 0..2 {
                    for c in 0..2 {
                        pairs.push(Pair { row: 2 * ip as usize + r, col: 2 * iq as usize + c });
                    }
                }
            }
        }
    }
    for i in 0..2 * free {
        pairs.push(Pair { row: i, col: i });
    }
    let num = |e: faer::sparse::CreationError| Error::Numerical(format!("Newton system pattern: {e:?}"));
    let (pattern, argsort) = SymbolicSparseColMat::try_new_from_indices(2 * free, 2 * free, &pairs).map_err(num)?;
    let mut symbolic: Option<SymbolicLlt<usize>> = None;
    let energy = |pos: &[P3]| -> f64 {
        face_list
            .par_iter()
            .zip(frames.par_iter())
            .map(|(tri, fr)| fr.and_then(|fr| fr.energy(tri.map(|w| pos[w.idx()]), scale)).unwrap_or(f64::INFINITY))
            .sum()
    };
    let forward = |pos: &[P3], faces: &[FaceId]| -> Vec<bool> {
        face_list
            .par_iter()
            .map(|tri| faces_forward(target, tri.map(|w| pos[w.idx()]), tri.map(|w| faces[w.idx()])))
            .collect()
    };
    let mut e0 = energy(&pos);
    rep.energy_before = e0;
    rep.energy_after = e0;
    if !e0.is_finite() {
        return Ok(rep);
    }
    for it in 0..opts.iterations {
        progress.check()?;
        progress.report(crate::progress::Stage::Newton, it as f64 / opts.iterations as f64);
        let tan: Vec<[V3; 2]> = map.face.iter().map(|&f| tangents(target.face_normal_raw(f))).collect();
        // Per face: gradient and clamped Hessian, in the order of `pairs`.
        let blocks: Vec<Option<([f64; 6], SMatrix<f64, 6, 6>)>> = face_list
            .par_iter()
            .zip(frames.par_iter())
            .map(|(tri, fr)| {
                let t = tri.map(|w| tan[w.idx()]);
                let (g, h) = face_derivatives(fr.as_ref()?, tri.map(|w| pos[w.idx()]), scale, &t)?;
                Some((g, clamp_psd(h)))
            })
            .collect();
        let mut vals: Vec<f64> = Vec::with_capacity(pairs.len());
        let mut grad = vec![0.0; 2 * free];
        let mut diag_max = 0.0f64;
        for (tri, b) in face_list.iter().zip(&blocks) {
            let Some((g, h)) = b else {
                // A degenerate mapped face (the energy is then infinite): nothing to descend.
                return Ok(rep);
            };
            for (k, &p) in tri.iter().enumerate() {
                let ip = index[p.idx()];
                if ip == u32::MAX {
                    continue;
                }
                grad[2 * ip as usize] += g[2 * k];
                grad[2 * ip as usize + 1] += g[2 * k + 1];
                for (l, &q) in tri.iter().enumerate() {
                    if index[q.idx()] == u32::MAX {
                        continue;
                    }
                    for r in 0..2 {
                        for c in 0..2 {
                            vals.push(h[(2 * k + r, 2 * l + c)]);
                        }
                    }
                }
            }
            for i in 0..6 {
                diag_max = diag_max.max(h[(i, i)]);
            }
        }
        // A small ridge keeps the system definite where every face Hessian is singular.
        let ridge = 1e-9 * diag_max.max(f64::MIN_POSITIVE);
        vals.extend(std::iter::repeat_n(ridge, 2 * free));
        let mat = SparseColMat::<usize, f64>::new_from_argsort(pattern.clone(), &argsort, &vals)
            .map_err(|e| Error::Numerical(format!("Newton system: {e:?}")))?;
        let sym = match &symbolic {
            Some(s) => s.clone(),
            None => {
                let s = SymbolicLlt::try_new(mat.symbolic(), Side::Lower)
                    .map_err(|e| Error::Numerical(format!("Newton symbolic factorization: {e:?}")))?;
                symbolic = Some(s.clone());
                s
            }
        };
        let Ok(llt) = Llt::try_new_with_symbolic(sym, mat.as_ref(), Side::Lower) else {
            break;
        };
        let mut x = Mat::<f64>::from_fn(2 * free, 1, |r, _| -grad[r]);
        llt.solve_in_place(x.as_mut());
        // Each image's step in 3D, capped at `max_move` times the mean length of its mapped edges.
        let step: Vec<V3> = (0..n)
            .into_par_iter()
            .map(|v| {
                let i = index[v];
                if i == u32::MAX {
                    return V3::zeros();
                }
                let (a, b) = (x[(2 * i as usize, 0)], x[(2 * i as usize + 1, 0)]);
                let s = tan[v][0] * a + tan[v][1] * b;
                let (mut reach, mut k) = (0.0, 0.0);
                for w in source.vertex_neighbors(VertexId::from_idx(v)) {
                    reach += (pos[w.idx()] - pos[v]).norm();
                    k += 1.0;
                }
                let cap = opts.max_move * reach / f64::max(k, 1.0);
                let l = s.norm();
                if l > cap && l > 0.0 { s * (cap / l) } else { s }
            })
            .collect();
        if !step.iter().all(|s| s.iter().all(|x| x.is_finite())) {
            break;
        }
        let was_forward = forward(&pos, &map.face);
        let mut alpha = 1.0;
        let mut accepted = None;
        let mut step = step;
        let (mut halvings, mut rounds) = (0, 0);
        while halvings < 8 && rounds < 40 {
            rounds += 1;
            let proj: Vec<Option<crate::topology::Projection>> = (0..n)
                .into_par_iter()
                .map(|v| {
                    (index[v] != u32::MAX && step[v] != V3::zeros())
                        .then(|| loc.project_near(target, &(pos[v] + step[v] * alpha), map.face[v], 2))
                })
                .collect();
            let trial_pos: Vec<P3> = (0..n).map(|v| proj[v].map_or(pos[v], |p| p.point)).collect();
            let trial_face: Vec<FaceId> = (0..n).map(|v| proj[v].map_or(map.face[v], |p| p.face)).collect();
            // Faces turned against the target: their corners sit this step out, same length.
            let fw = forward(&trial_pos, &trial_face);
            let mut turned = 0;
            for (f, tri) in face_list.iter().enumerate() {
                if was_forward[f] && !fw[f] {
                    turned += 1;
                    for w in tri {
                        step[w.idx()] = V3::zeros();
                    }
                }
            }
            if turned > 0 {
                continue;
            }
            let e = energy(&trial_pos);
            if e < e0 {
                accepted = Some((e, proj, trial_pos));
                break;
            }
            alpha *= 0.5;
            halvings += 1;
        }
        let Some((e, proj, trial_pos)) = accepted else {
            break;
        };
        for (v, p) in proj.into_iter().enumerate() {
            if let Some(p) = p {
                map.face[v] = p.face;
                map.bary[v] = p.bary;
            }
        }
        pos = trial_pos;
        rep.steps += 1;
        let drop = (e0 - e) / e0;
        e0 = e;
        rep.energy_after = e;
        if drop < opts.tolerance {
            break;
        }
    }
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact 6x6 gradient and Hessian agree with central differences of the energy, with
    /// a different tangent plane at each corner (cross-corner terms included).
    #[test]
    fn face_derivatives_match_central_differences() {
        let fr = SourceFrame::new([P3::new(0.1, 0.0, 0.2), P3::new(1.3, 0.2, 0.0), P3::new(0.4, 0.9, 0.1)]).unwrap();
        let m = [P3::new(0.0, 0.1, 0.0), P3::new(1.7, 0.0, 0.4), P3::new(0.2, 1.1, 0.6)];
        let t =
            [tangents(V3::new(0.0, 0.0, 1.0)), tangents(V3::new(0.2, -0.1, 1.0)), tangents(V3::new(-0.3, 0.4, 0.8))];
        let scale = 0.9;
        let e = |u: &[f64; 6]| {
            let mut q = m;
            for k in 0..3 {
                q[k] += t[k][0] * u[2 * k] + t[k][1] * u[2 * k + 1];
            }
            fr.energy(q, scale).unwrap()
        };
        let (g, hm) = face_derivatives(&fr, m, scale, &t).unwrap();
        let h = 1e-4;
        let close = |a: f64, b: f64| (a - b).abs() <= 1e-5 * (1.0 + b.abs());
        for i in 0..6 {
            let mut up = [0.0; 6];
            up[i] = h;
            let mut dn = [0.0; 6];
            dn[i] = -h;
            let gi = (e(&up) - e(&dn)) / (2.0 * h);
            assert!(close(g[i], gi), "gradient {i}: {} vs {gi}", g[i]);
            for j in 0..6 {
                let mut pp = [0.0; 6];
                let mut pm = [0.0; 6];
                let mut mp = [0.0; 6];
                let mut mm = [0.0; 6];
                pp[i] += h;
                pp[j] += h;
                pm[i] += h;
                pm[j] -= h;
                mp[i] -= h;
                mp[j] += h;
                mm[i] -= h;
                mm[j] -= h;
                let hij = (e(&pp) - e(&pm) - e(&mp) + e(&mm)) / (4.0 * h * h);
                assert!(close(hm[(i, j)], hij), "hessian {i},{j}: {} vs {hij}", hm[(i, j)]);
            }
        }
    }

    /// Clamping leaves a positive semi-definite matrix alone and makes an indefinite one
    /// positive semi-definite.
    #[test]
    fn clamp_makes_positive_semidefinite() {
        let mut a = SMatrix::<f64, 6, 6>::identity();
        assert_eq!(clamp_psd(a), a);
        a[(0, 1)] = 3.0;
        a[(1, 0)] = 3.0;
        let c = clamp_psd(a);
        let eig = SymmetricEigen::new(c);
        assert!(eig.eigenvalues.iter().all(|&l| l >= -1e-12), "{:?}", eig.eigenvalues);
        // The positive part is kept: eigenvalue 4 along (1, 1).
        assert!((c[(0, 0)] - 2.0).abs() < 1e-12 && (c[(0, 1)] - 2.0).abs() < 1e-12);
    }

    /// A map of a sphere onto itself, each free image pushed off its vertex along the surface,
    /// relaxes back to the identity: the energy falls to the isometric minimum (4 times the
    /// area), no forward face turns, and the fixed vertices do not move.
    #[test]
    fn relaxes_a_perturbed_self_map_back_to_the_identity() {
        let mesh = crate::mesh::shapes::icosphere(3);
        let n = mesh.n_vertices();
        let fixed: Vec<VertexId> = [0usize, 40, 97, 300, 511].iter().map(|&v| VertexId::from_idx(v)).collect();
        let moved: Vec<P3> = (0..n)
            .map(|v| {
                let p = mesh.position(VertexId::from_idx(v));
                if fixed.iter().any(|f| f.idx() == v) {
                    return p;
                }
                let t = tangents(p.coords);
                let a = 0.02 * ((v as f64) * 1.7).sin();
                let b = 0.02 * ((v as f64) * 0.9).cos();
                p + t[0] * a + t[1] * b
            })
            .collect();
        let mut map = SurfaceMap::from_positions(&moved, &mesh, None).unwrap();
        for f in &fixed {
            let id = SurfaceMap::identity(&mesh);
            map.face[f.idx()] = id.face[f.idx()];
            map.bary[f.idx()] = id.bary[f.idx()];
        }
        let before = map.clone();
        let pos = |m: &SurfaceMap| -> Vec<P3> { (0..n).map(|v| m.position(VertexId::from_idx(v), &mesh)).collect() };
        let fw = |m: &SurfaceMap| -> Vec<bool> {
            let p = pos(m);
            mesh.faces()
                .iter()
                .map(|t| faces_forward(&mesh, t.map(|w| p[w.idx()]), t.map(|w| m.face[w.idx()])))
                .collect()
        };
        let opts = NewtonOptions { iterations: 30, tolerance: 1e-9, ..Default::default() };
        let rep = relax_newton(&mesh, &mesh, &mut map, &fixed, &opts, &mut crate::progress::NoProgress).unwrap();
        assert!(rep.steps > 0 && rep.energy_after < rep.energy_before, "{rep:?}");
        let iso = 4.0 * mesh.area();
        assert!(rep.energy_before > 1.01 * iso, "the perturbation must cost energy: {rep:?} vs {iso}");
        assert!(rep.energy_after < 1.0001 * iso, "{rep:?} vs the isometric minimum {iso}");
        for (a, b) in fw(&before).iter().zip(fw(&map)) {
            assert!(!a || b, "a forward face turned");
        }
        for f in &fixed {
            assert_eq!((map.face[f.idx()], map.bary[f.idx()]), (before.face[f.idx()], before.bary[f.idx()]));
        }
        let worst = (0..n)
            .map(|v| (map.position(VertexId::from_idx(v), &mesh) - mesh.position(VertexId::from_idx(v))).norm())
            .fold(0.0, f64::max);
        assert!(worst < 2e-3, "images end {worst} from their vertices");
    }
}
