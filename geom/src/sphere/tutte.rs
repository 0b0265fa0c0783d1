//! A known-bijective start on the sphere for a closed genus-0 mesh: Tutte's embedding in the
//! gnomonic plane, lifted to the sphere by central projection.
//!
//! One vertex, the *pole*, is sent to the north pole. Its link (the cycle of its neighbours)
//! is placed on a regular polygon in the plane `z = -1`, and every other vertex at the average
//! of its neighbours (Tutte 1963; uniform weights, so one Cholesky solve). The mesh without the
//! pole's star is a triangulated disk with a strictly convex boundary, so the planar layout is
//! an embedding (Tutte; Floater 2003). Central projection `x ↦ x / |x|` maps the plane
//! `z = -1` onto the open southern hemisphere and straight segments onto great-circle arcs,
//! with `det` of any three points keeping its sign, so the planar triangles become positively
//! oriented geodesic triangles that tile the spherical polygon bounded by the link. The pole's
//! fan tiles the rest: each `(pole, bᵢ, bᵢ₊₁)` is positive since consecutive link points turn
//! counter-clockwise about the z axis. This is exact, not a property of fine meshes: unlike an
//! inverse stereographic projection (which maps segments to circles, not geodesics), it needs no
//! repair.

use crate::error::{Error, InputError, Result};
use crate::linalg::{FixedBoundarySystem, Weights};
use crate::mesh::{Mesh, P3, VertexId};

/// The radius of the link's polygon in the plane `z = -1`: its corners sit 10° south of the
/// equator, so the disk spreads over most of the southern hemisphere and the fan stays small.
const LINK_RADIUS: f64 = 5.671_281_819_617_709; // tan(80°)

/// The pole: the vertex of highest degree (the largest fan, so the link's polygon has the most
/// corners and the fan triangles are the narrowest).
pub fn default_pole(mesh: &Mesh) -> VertexId {
    (0..mesh.n_vertices())
        .map(VertexId::from_idx)
        .max_by_key(|&v| (mesh.outgoing(v).count(), std::cmp::Reverse(v.0)))
        .unwrap_or(VertexId(0))
}

/// Tutte's embedding of the closed genus-0 `mesh` on the unit sphere with `pole` at the north
/// pole. Every triangle is positively oriented (see the module doc); the caller verifies it
/// with [`super::orient::check`] all the same.
///
/// # Errors
/// `Invalid` for a mesh with a boundary or a pole of degree < 3; `Numerical` if the solve fails.
pub fn tutte_sphere(mesh: &Mesh, pole: VertexId) -> Result<Vec<P3>> {
    if (0..mesh.n_vertices()).any(|v| mesh.is_boundary_vertex(VertexId::from_idx(v))) {
        return Err(InputError::Invalid("a sphere embedding needs a closed mesh".into()).into());
    }
    // The link, counter-clockwise about the pole as the mesh is oriented.
    let link: Vec<VertexId> = mesh.outgoing(pole).map(|h| mesh.head(h)).collect();
    if link.len() < 3 {
        return Err(InputError::Invalid(format!("vertex {} has degree {}", pole.0, link.len())).into());
    }
    let mut fixed = link.clone();
    fixed.push(pole);
    let mut corner = vec![[0.0; 2]; mesh.n_vertices()];
    let n = link.len() as f64;
    for (k, &v) in link.iter().enumerate() {
        // Counter-clockwise seen from +z, as the fan asks; the disk's boundary runs the other
        // way (decreasing k), counter-clockwise seen from outside the sphere (from below).
        let a = std::f64::consts::TAU * k as f64 / n;
        corner[v.idx()] = [LINK_RADIUS * a.cos(), LINK_RADIUS * a.sin()];
    }
    let mut system = FixedBoundarySystem::new(mesh, &fixed)?;
    let factor = system.factor(mesh, Weights::Uniform)?;
    let uv = factor.solve(&|v: VertexId| corner[v.idx()])?;
    let mut out: Vec<P3> = uv
        .iter()
        .map(|q| {
            let p = nalgebra::Vector3::new(q[0], q[1], -1.0);
            P3::from(p / p.norm())
        })
        .collect();
    out[pole.idx()] = P3::new(0.0, 0.0, 1.0);
    if out.iter().any(|p| !p.coords.iter().all(|c| c.is_finite())) {
        return Err(Error::Numerical("Tutte's sphere embedding is not finite".into()));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::sphere::orient::check;

    #[test]
    fn tutte_on_the_sphere_is_bijective_from_every_kind_of_pole() {
        for mesh in [shapes::tetrahedron(), shapes::icosphere(3)] {
            let tris = mesh.face_indices();
            for pole in [VertexId(0), VertexId(1), default_pole(&mesh)] {
                let p = tutte_sphere(&mesh, pole).unwrap();
                let c = check(&p, &tris);
                assert!(c.is_bijective(), "{} vertices, pole {}: {c:?}", mesh.n_vertices(), pole.0);
            }
        }
    }

    #[test]
    fn an_open_mesh_is_refused() {
        let e = tutte_sphere(&shapes::grid(3), VertexId(5)).unwrap_err();
        assert_eq!(e.code(), "invalid_argument");
    }
}
