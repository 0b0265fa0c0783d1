//! Closest-point location on a mesh through a BVH (`parry3d-f64`'s `TriMesh`): the face, the
//! barycentric coordinates of the closest point, and its distance.

use crate::error::{Error, Result};
use crate::mesh::{FaceId, Mesh, P3};
use parry3d_f64::math::Vector;
use parry3d_f64::query::PointQueryWithLocation;
use parry3d_f64::shape::TriMesh;

/// A closest-point query result.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Projection {
    pub face: FaceId,
    pub bary: [f64; 3],
    pub point: P3,
    pub distance: f64,
}

/// A BVH over the faces of one mesh, for repeated closest-point queries.
pub struct Locator {
    tri: TriMesh,
}

impl Locator {
    /// Builds the BVH (O(F log F)).
    ///
    /// # Errors
    /// `Error::Internal` if the BVH cannot be built (the mesh has no faces).
    pub fn new(mesh: &Mesh) -> Result<Locator> {
        let v = mesh.positions().iter().map(|p| Vector::new(p.x, p.y, p.z)).collect();
        let tri =
            TriMesh::new(v, mesh.face_indices()).map_err(|e| Error::Internal(format!("BVH construction: {e:?}")))?;
        Ok(Locator { tri })
    }

    /// The closest point of the surface to `p`.
    pub fn project(&self, p: &P3) -> Projection {
        let q = Vector::new(p.x, p.y, p.z);
        let (proj, (fid, loc)) = self.tri.project_local_point_and_get_location(q, false);
        let bary = loc.barycentric_coordinates().unwrap_or([1.0 / 3.0; 3]);
        let point = P3::new(proj.point.x, proj.point.y, proj.point.z);
        Projection { face: FaceId(fid), bary, point, distance: (point - p).norm() }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn projects_onto_sphere() {
        let s = shapes::icosphere(3);
        let loc = Locator::new(&s).unwrap();
        let p = P3::new(0.0, 0.0, 2.0);
        let pr = loc.project(&p);
        assert!((pr.distance - 1.0).abs() < 0.02);
        let [a, b, c] = s.face_points(pr.face);
        let q = a.coords * pr.bary[0] + b.coords * pr.bary[1] + c.coords * pr.bary[2];
        assert!((q - pr.point.coords).norm() < 1e-12);
        // A vertex projects onto itself.
        let v = s.positions()[7];
        assert!(loc.project(&v).distance < 1e-12);
    }
}
