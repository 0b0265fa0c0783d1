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

    /// The closest point to `p` among the faces within `rings` face-rings of `start` (a point
    /// that moved a little from `start`): a local search that stays on the same sheet of the
    /// surface. Falls back to the BVH when the best face is on the outermost ring (the true
    /// closest point may lie beyond).
    pub fn project_near(&self, mesh: &Mesh, p: &P3, start: FaceId, rings: usize) -> Projection {
        let mut faces = vec![start];
        let mut ring_start = 0;
        for _ in 0..rings {
            let ring_end = faces.len();
            for i in ring_start..ring_end {
                for g in mesh.face_neighbors(faces[i]) {
                    if !faces.contains(&g) {
                        faces.push(g);
                    }
                }
            }
            ring_start = ring_end;
        }
        let mut best: Option<(f64, usize, P3)> = None;
        for (i, &f) in faces.iter().enumerate() {
            let [a, b, c] = mesh.face_points(f);
            let q = crate::metrics::closest_point(*p, a, b, c);
            let d = (q - p).norm_squared();
            if best.is_none_or(|(bd, _, _)| d < bd) {
                best = Some((d, i, q));
            }
        }
        match best {
            Some((d, i, q)) if i < ring_start || rings == 0 => {
                let f = faces[i];
                Projection { face: f, bary: barycentric(mesh.face_points(f), q), point: q, distance: d.sqrt() }
            }
            _ => self.project(p),
        }
    }
}

/// Barycentric coordinates of `q` (on or near triangle `t`), clamped to the triangle.
fn barycentric(t: [P3; 3], q: P3) -> [f64; 3] {
    let [_, v, w] = plane_barycentric(t, q);
    let v = v.clamp(0.0, 1.0);
    let w = w.clamp(0.0, 1.0 - v);
    [1.0 - v - w, v, w]
}

/// Unclamped barycentric coordinates of `q` projected into the plane of triangle `t`
/// (`[1, 0, 0]` for a degenerate triangle).
pub(crate) fn plane_barycentric(t: [P3; 3], q: P3) -> [f64; 3] {
    let (e1, e2, d) = (t[1] - t[0], t[2] - t[0], q - t[0]);
    let (a, b, c) = (e1.dot(&e1), e1.dot(&e2), e2.dot(&e2));
    let (r1, r2) = (e1.dot(&d), e2.dot(&d));
    let det = a * c - b * b;
    if det <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let v = (c * r1 - b * r2) / det;
    let w = (a * r2 - b * r1) / det;
    [1.0 - v - w, v, w]
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
