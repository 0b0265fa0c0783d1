//! Fixed-boundary parameterization of a disk onto a convex polygon: Tutte (uniform weights),
//! harmonic (cotangent weights, Eck et al. 1995) or mean value (Floater 2003). With a convex
//! boundary and positive weights (uniform, mean value) the result is a bijection (Tutte's and
//! Floater's theorems); cotangent weights can fold on obtuse meshes, which the report shows.

use super::{BoundaryShape, InjectivityReport, Uv, check_injective, disk_boundary, map_boundary_to_polygon};
use crate::error::Result;
use crate::linalg::{FixedBoundarySystem, Weights};
use crate::mesh::{Mesh, VertexId};
use serde::{Deserialize, Serialize};

/// Options for [`parameterize_disk`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DiskParamOptions {
    pub weights: Weights,
    pub boundary: BoundaryShape,
}

impl Default for DiskParamOptions {
    fn default() -> Self {
        Self { weights: Weights::Cotan, boundary: BoundaryShape::Circle }
    }
}

/// A planar embedding of a disk.
#[derive(Debug, Clone)]
pub struct DiskParamResult {
    /// Position of every vertex in the plane.
    pub uv: Vec<Uv>,
    /// The boundary loop, in order.
    pub boundary: Vec<VertexId>,
    /// Flips and degeneracies of the result.
    pub injectivity: InjectivityReport,
    /// Relative residual of the linear solve.
    pub residual: f64,
}

/// Parameterizes a topological disk with a fixed convex boundary.
///
/// # Errors
/// `InputError::NotADisk` when the mesh is not a disk; `Error::Numerical` when the solve fails.
pub fn parameterize_disk(mesh: &Mesh, opts: &DiskParamOptions) -> Result<DiskParamResult> {
    let boundary = disk_boundary(mesh)?;
    let buv = map_boundary_to_polygon(mesh, &boundary, &opts.boundary)?;
    let mut fixed_uv = vec![[f64::NAN; 2]; mesh.n_vertices()];
    for (v, p) in boundary.iter().zip(&buv) {
        fixed_uv[v.idx()] = *p;
    }
    let mut sys = FixedBoundarySystem::new(mesh, &boundary)?;
    let factor = sys.factor(mesh, opts.weights)?;
    let (uv, residual) = factor.solve_with_residual::<2>(&|v| fixed_uv[v.idx()])?;
    let injectivity = check_injective(mesh, &uv);
    Ok(DiskParamResult { uv, boundary, injectivity, residual })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{P3, shapes};

    fn bumpy_disk() -> Mesh {
        let g = shapes::grid(12);
        let p: Vec<P3> =
            g.positions().iter().map(|p| P3::new(p.x, p.y, 0.3 * (3.0 * p.x).sin() * (2.0 * p.y).cos())).collect();
        g.with_positions(p).unwrap()
    }

    #[test]
    fn all_weights_give_injective_maps_with_small_residual() {
        let m = bumpy_disk();
        for w in [Weights::Uniform, Weights::Cotan, Weights::MeanValue] {
            let r = parameterize_disk(&m, &DiskParamOptions { weights: w, boundary: BoundaryShape::Circle }).unwrap();
            assert!(r.injectivity.is_injective(), "{w:?}: {:?}", r.injectivity);
            assert!(r.residual < 1e-10, "{w:?} residual {}", r.residual);
        }
    }

    #[test]
    fn cotan_and_mean_value_reproduce_a_flat_mesh_from_its_boundary() {
        // Linear precision: a planar mesh with its own boundary positions is reproduced.
        let g = bumpy_disk();
        let flat: Vec<P3> = g.positions().iter().map(|p| P3::new(p.x + 0.1 * p.y * p.y, p.y, 0.0)).collect();
        let g = g.with_positions(flat).unwrap();
        let boundary = disk_boundary(&g).unwrap();
        let mut sys = FixedBoundarySystem::new(&g, &boundary).unwrap();
        for w in [Weights::Cotan, Weights::MeanValue] {
            let f = sys.factor(&g, w).unwrap();
            let uv = f.solve::<2>(&|v| [g.position(v).x, g.position(v).y]).unwrap();
            for (p, q) in g.positions().iter().zip(&uv) {
                assert!((p.x - q[0]).abs() < 1e-10 && (p.y - q[1]).abs() < 1e-10, "{w:?}");
            }
            assert!(f.residual(&uv) < 1e-10);
        }
    }

    #[test]
    fn closed_mesh_is_not_a_disk() {
        let s = shapes::icosphere(1);
        let e = parameterize_disk(&s, &DiskParamOptions::default()).unwrap_err();
        assert_eq!(e.code(), "not_a_disk");
    }
}
