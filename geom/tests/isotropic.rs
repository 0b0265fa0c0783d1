//! The closed-form projected Hessian of `geom::optim::isotropic` against an eigensolver's
//! clamping of the chain-rule Hessian, for the symmetric Dirichlet energy and its untangling form.

use geom::optim::isotropic::{Profile, projected};
use nalgebra::{Matrix4, SymmetricEigen, Vector4};

/// The Hessian of `|J|² h(det J)` as the chain rule gives it.
fn hessian(v: &Vector4<f64>, p: Profile) -> Matrix4<f64> {
    let s = v.norm_squared();
    let cof = Vector4::new(v[3], -v[2], -v[1], v[0]);
    let mut k = Matrix4::zeros();
    k[(0, 3)] = 1.0;
    k[(3, 0)] = 1.0;
    k[(1, 2)] = -1.0;
    k[(2, 1)] = -1.0;
    Matrix4::identity() * (2.0 * p.h)
        + (v * cof.transpose() + cof * v.transpose()) * (2.0 * p.h1)
        + (cof * cof.transpose() * p.h2 + k * p.h1) * s
}

fn clamp_by_eigen(h: Matrix4<f64>) -> Matrix4<f64> {
    let eig = SymmetricEigen::new(h);
    let l = eig.eigenvalues.map(|x| x.max(0.0));
    eig.eigenvectors * Matrix4::from_diagonal(&l) * eig.eigenvectors.transpose()
}

#[test]
fn the_closed_form_projection_equals_the_eigensolvers() {
    let mut seed = 7u64;
    let mut next = || {
        seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 4.0 - 2.0
    };
    for case in 0..500 {
        let v = Vector4::new(next(), next(), next(), next());
        // The symmetric Dirichlet energy's profile where det > 0, the untangling one's
        // (ε = 0.3) anywhere.
        let det = v[0] * v[3] - v[1] * v[2];
        let eps: f64 = 0.3;
        let r = (eps * eps + det * det).sqrt();
        let chi = 0.5 * (det + r);
        let (c1, c2) = (0.5 * (1.0 + det / r), 0.5 * eps * eps / (r * r * r));
        let mut profiles = vec![Profile {
            h: 1.0 + chi.powi(-2),
            h1: -2.0 * chi.powi(-3) * c1,
            h2: 6.0 * chi.powi(-4) * c1 * c1 - 2.0 * chi.powi(-3) * c2,
        }];
        if det > 0.0 {
            profiles.push(Profile { h: 1.0 + det.powi(-2), h1: -2.0 * det.powi(-3), h2: 6.0 * det.powi(-4) });
        }
        for p in profiles {
            let (_, h) = projected(&v, p).unwrap();
            let want = clamp_by_eigen(hessian(&v, p));
            let scale = 1.0 + want.norm();
            assert!((h - want).norm() < 1e-9 * scale, "{case}: {v:?} {p:?}\n{h}\n{want}");
        }
    }
}
