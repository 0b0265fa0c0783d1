//! [`SurfaceMap`]: one surface point on the target for each source vertex.

use crate::error::{InputError, Result};
use crate::mesh::{FaceId, Mesh, P3, VertexId};
use crate::topology::Locator;
use serde::{Deserialize, Serialize};

/// A vertex map from a source mesh onto a target mesh's surface.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SurfaceMap {
    /// Target face of each source vertex.
    pub face: Vec<FaceId>,
    /// Barycentric coordinates in that face (non-negative, summing to 1).
    pub bary: Vec<[f64; 3]>,
}

impl SurfaceMap {
    /// The identity map of a mesh onto itself.
    pub fn identity(mesh: &Mesh) -> SurfaceMap {
        let mut face = vec![FaceId(0); mesh.n_vertices()];
        let mut bary = vec![[0.0; 3]; mesh.n_vertices()];
        for (f, tri) in mesh.faces().iter().enumerate() {
            for (k, v) in tri.iter().enumerate() {
                face[v.idx()] = FaceId::from_idx(f);
                let mut b = [0.0; 3];
                b[k] = 1.0;
                bary[v.idx()] = b;
            }
        }
        SurfaceMap { face, bary }
    }

    /// Maps each position to its closest point on the target (point location through a BVH).
    ///
    /// # Errors
    /// `Error::Internal` if the BVH cannot be built.
    pub fn from_positions(positions: &[P3], target: &Mesh, locator: Option<&Locator>) -> Result<SurfaceMap> {
        let own;
        let loc = match locator {
            Some(l) => l,
            None => {
                own = Locator::new(target)?;
                &own
            }
        };
        let (face, bary) = positions
            .iter()
            .map(|p| {
                let pr = loc.project(p);
                (pr.face, pr.bary)
            })
            .unzip();
        Ok(SurfaceMap { face, bary })
    }

    /// Number of mapped (source) vertices.
    pub fn len(&self) -> usize {
        self.face.len()
    }
    /// True for a map of no vertices.
    pub fn is_empty(&self) -> bool {
        self.face.is_empty()
    }

    /// Checks that the map fits a source with `n_source` vertices and the target mesh.
    ///
    /// # Errors
    /// `InputError::Invalid` naming the first bad entry.
    pub fn validate(&self, n_source: usize, target: &Mesh) -> Result<()> {
        if self.face.len() != n_source || self.bary.len() != n_source {
            return Err(InputError::Invalid(format!(
                "map has {} entries for {n_source} source vertices",
                self.face.len()
            ))
            .into());
        }
        for (v, (f, b)) in self.face.iter().zip(&self.bary).enumerate() {
            if f.idx() >= target.n_faces() {
                return Err(InputError::Invalid(format!(
                    "vertex {v} maps to face {f}, but the target has {} faces",
                    target.n_faces()
                ))
                .into());
            }
            let s = b[0] + b[1] + b[2];
            if b.iter().any(|x| !x.is_finite() || *x < -1e-9) || (s - 1.0).abs() > 1e-9 {
                return Err(InputError::Invalid(format!("vertex {v} has invalid barycentric coordinates {b:?}")).into());
            }
        }
        Ok(())
    }

    /// Position on the target of source vertex `v`.
    pub fn position(&self, v: VertexId, target: &Mesh) -> P3 {
        let [a, b, c] = target.face_points(self.face[v.idx()]);
        let w = self.bary[v.idx()];
        P3::from(a.coords * w[0] + b.coords * w[1] + c.coords * w[2])
    }

    /// The source mesh re-embedded on the target: source connectivity, mapped positions.
    ///
    /// # Errors
    /// `InputError::Invalid` if the map does not fit (see [`SurfaceMap::validate`]).
    pub fn embed(&self, source: &Mesh, target: &Mesh) -> Result<Mesh> {
        self.validate(source.n_vertices(), target)?;
        let pos = (0..source.n_vertices()).map(|v| self.position(VertexId::from_idx(v), target)).collect();
        let mut m = source.with_positions(pos)?;
        m.attributes = Default::default();
        Ok(m)
    }

    /// Composes `self: S -> T` with `next: T -> U`: each source vertex's point in a T face is
    /// carried by linear interpolation of `next` over that face's corners, then located on U.
    ///
    /// # Errors
    /// `InputError::Invalid` if `next` does not fit `t` and `u`.
    pub fn compose(&self, t: &Mesh, next: &SurfaceMap, u: &Mesh, u_locator: Option<&Locator>) -> Result<SurfaceMap> {
        next.validate(t.n_vertices(), u)?;
        let pts: Vec<P3> = self
            .face
            .iter()
            .zip(&self.bary)
            .map(|(&f, b)| {
                let tri = t.face(f);
                let q = tri.map(|v| next.position(v, u));
                P3::from(q[0].coords * b[0] + q[1].coords * b[1] + q[2].coords * b[2])
            })
            .collect();
        SurfaceMap::from_positions(&pts, u, u_locator)
    }

    /// Writes the map as CSV `vertex,face,b0,b1,b2`.
    pub fn to_csv(&self) -> String {
        let mut s = String::with_capacity(self.len() * 48 + 24);
        s.push_str("vertex,face,b0,b1,b2\n");
        for (v, (f, b)) in self.face.iter().zip(&self.bary).enumerate() {
            s.push_str(&format!("{v},{f},{},{},{}\n", b[0], b[1], b[2]));
        }
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn identity_embeds_to_the_same_mesh() {
        let s = shapes::icosphere(2);
        let m = SurfaceMap::identity(&s);
        let e = m.embed(&s, &s).unwrap();
        for (a, b) in s.positions().iter().zip(e.positions()) {
            assert!((a - b).norm() < 1e-15);
        }
    }

    #[test]
    fn composing_with_identity_is_a_no_op_and_location_recovers_vertices() {
        let s = shapes::icosphere(2);
        let fine = shapes::icosphere(3);
        // s -> fine by closest point (vertices of s are vertices of fine).
        let m = SurfaceMap::from_positions(s.positions(), &fine, None).unwrap();
        let e = m.embed(&s, &fine).unwrap();
        for (a, b) in s.positions().iter().zip(e.positions()) {
            assert!((a - b).norm() < 1e-12);
        }
        let id = SurfaceMap::identity(&fine);
        let c = m.compose(&fine, &id, &fine, None).unwrap();
        let e2 = c.embed(&s, &fine).unwrap();
        for (a, b) in e.positions().iter().zip(e2.positions()) {
            assert!((a - b).norm() < 1e-12);
        }
        assert!(m.validate(s.n_vertices(), &fine).is_ok());
        assert!(m.validate(s.n_vertices() + 1, &fine).is_err());
    }
}
