//! Closing a mesh's boundary loops with cones: one new apex vertex per loop, at the loop's
//! centroid, joined to every loop vertex by a fan of faces. The closed mesh keeps the open
//! mesh's vertices and faces under the same ids (the apexes and fans come after them), so a map
//! onto the closed mesh restricts to the open one wherever it avoids the fans
//! ([`Capped::restrict`]).

use crate::error::{Error, InputError, Result};
use crate::mesh::{FaceId, HalfedgeId, Mesh, P3, VertexId};

/// One closed boundary loop.
#[derive(Debug, Clone, PartialEq)]
pub struct CapLoop {
    /// The loop's vertices in the order of its boundary half-edges (the open surface on the
    /// left of each step).
    pub vertices: Vec<VertexId>,
    /// The cone's apex (a vertex of the closed mesh only).
    pub apex: VertexId,
}

/// A mesh with every boundary loop closed by a cone.
#[derive(Debug, Clone)]
pub struct Capped {
    pub mesh: Mesh,
    pub open_vertices: usize,
    pub open_faces: usize,
    pub loops: Vec<CapLoop>,
    /// Per fan face (index minus `open_faces`): the open face across its loop edge.
    across: Vec<FaceId>,
}

/// Closes every boundary loop of `mesh` with a cone.
///
/// # Errors
/// `InputError::TopologyMismatch` when a loop passes a vertex twice or has fewer than three
/// vertices (the cone would not be a surface).
pub fn cap_loops(mesh: &Mesh) -> Result<Capped> {
    let nv = mesh.n_vertices();
    let mut positions: Vec<P3> = mesh.positions().to_vec();
    let mut tris: Vec<[u32; 3]> = mesh.faces().iter().map(|f| [f[0].0, f[1].0, f[2].0]).collect();
    let mut loops = Vec::new();
    let mut across = Vec::new();
    let mut on_loop = vec![false; nv];
    for hs in super::loops::boundary_loops(mesh) {
        let vertices: Vec<VertexId> = hs.iter().map(|&h| mesh.tail(h)).collect();
        if vertices.len() < 3 || vertices.iter().any(|v| std::mem::replace(&mut on_loop[v.idx()], true)) {
            return Err(InputError::TopologyMismatch(format!(
                "the boundary loop through vertex {} passes a vertex twice (a pinched boundary): it cannot be mapped onto a loop",
                vertices[0].0
            ))
            .into());
        }
        let c = vertices.iter().fold(nalgebra::Vector3::zeros(), |s, v| s + mesh.position(*v).coords)
            / vertices.len() as f64;
        let apex = VertexId(positions.len() as u32);
        positions.push(P3::from(c));
        for &h in &hs {
            // The boundary half-edge runs tail -> head with its face on the left; the fan face
            // runs the other way round that edge.
            tris.push([mesh.head(h).0, mesh.tail(h).0, apex.0]);
            across.push(h.face());
        }
        loops.push(CapLoop { vertices, apex });
    }
    let capped = Mesh::from_triangles(positions, &tris)?;
    if capped.n_faces() != tris.len() || capped.n_vertices() != nv + loops.len() {
        return Err(Error::Internal("capping changed the mesh's numbering".into()));
    }
    Ok(Capped { mesh: capped, open_vertices: nv, open_faces: mesh.n_faces(), loops, across })
}

impl Capped {
    /// Is `f` a face of a cone (not of the open mesh)?
    pub fn is_cap_face(&self, f: FaceId) -> bool {
        f.idx() >= self.open_faces
    }

    /// The faces of every cone.
    pub fn cap_faces(&self) -> Vec<FaceId> {
        (self.open_faces..self.mesh.n_faces()).map(FaceId::from_idx).collect()
    }

    /// A point of the closed mesh as a point of the open one: a point of a fan face must lie
    /// on its loop edge (apex weight at most `tol`), and is moved to the open face across it.
    /// `None` for a point inside a cone.
    pub fn restrict(&self, face: FaceId, bary: [f64; 3], tol: f64) -> Option<(FaceId, [f64; 3])> {
        if !self.is_cap_face(face) {
            return Some((face, bary));
        }
        let tri = self.mesh.face(face);
        // Fan faces are (head, tail, apex).
        if bary[2] > tol {
            return None;
        }
        let s = (bary[0] + bary[1]).max(f64::MIN_POSITIVE);
        let (wh, wt) = (bary[0] / s, bary[1] / s);
        let open = self.across[face.idx() - self.open_faces];
        let of = self.mesh.face(open);
        let mut b = [0.0; 3];
        for k in 0..3 {
            if of[k] == tri[0] {
                b[k] = wh;
            } else if of[k] == tri[1] {
                b[k] = wt;
            }
        }
        Some((open, b))
    }

    /// Does the point lie on a loop (on an open face's edge across from a fan face)?
    pub fn on_loop_edge(&self, face: FaceId, bary: [f64; 3]) -> bool {
        if self.is_cap_face(face) {
            return false;
        }
        let tri = self.mesh.face(face);
        let at_vertex = (0..3).find(|&k| bary[k] == 1.0);
        if let Some(k) = at_vertex {
            return self.mesh.vertex_faces(tri[k]).any(|f| self.is_cap_face(f));
        }
        (0..3).any(|k| {
            let h = HalfedgeId(3 * face.0 + ((k as u32 + 1) % 3));
            bary[k] == 0.0 && self.mesh.twin(h).is_some_and(|t| self.is_cap_face(t.face()))
        })
    }

    /// A map from a closed mesh onto this one, as each source vertex's `(face, bary)`,
    /// restricted to the first `from_vertices` source vertices (the open source's), every image
    /// on the open mesh. Images on a loop keep exactly to the loop edge (an open face's off-edge
    /// weight at most `tol` is zeroed). (Plain vectors, not a `map::SurfaceMap`: the mesh
    /// module imports nothing above it.)
    ///
    /// # Errors
    /// `Error::Numerical` when an open vertex maps inside a cone.
    pub fn restrict_map(
        &self,
        (faces, barys): (&[FaceId], &[[f64; 3]]),
        from_vertices: usize,
        on_loop: &[bool],
        tol: f64,
    ) -> Result<(Vec<FaceId>, Vec<[f64; 3]>)> {
        let mut face = Vec::with_capacity(from_vertices);
        let mut bary = Vec::with_capacity(from_vertices);
        for (v, &looped) in on_loop.iter().enumerate().take(from_vertices) {
            let (f, mut b) = self.restrict(faces[v], barys[v], tol).ok_or_else(|| {
                Error::Numerical(format!("vertex {v} of the open mesh maps inside the cap of a boundary loop"))
            })?;
            if looped {
                snap_to_boundary(&self.mesh, f, &mut b, tol, self.open_faces);
            }
            face.push(f);
            bary.push(b);
        }
        Ok((face, bary))
    }
}

/// Zeroes a small weight of face `f`'s corner opposite a loop edge (an edge whose other face is
/// a fan face), so a loop vertex's image lies exactly on the loop.
fn snap_to_boundary(m: &Mesh, f: FaceId, b: &mut [f64; 3], tol: f64, open_faces: usize) {
    for k in 0..3 {
        // Half-edge `3f + c` runs from corner `c` to corner `c + 1`: opposite corner `k`.
        let h = HalfedgeId(3 * f.0 + ((k as u32 + 1) % 3));
        let on_loop = m.twin(h).is_some_and(|t| t.face().idx() >= open_faces);
        if on_loop && b[k] <= tol {
            let s = 1.0 - b[k];
            b[k] = 0.0;
            for x in b.iter_mut() {
                *x /= s.max(f64::MIN_POSITIVE);
            }
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn a_disk_closes_into_a_sphere_with_the_same_numbering() {
        // A disk with one loop.
        let open = shapes::icosphere_with_holes(2, &[0]);
        let c = cap_loops(&open).unwrap();
        assert_eq!(c.loops.len(), 1);
        assert_eq!(crate::topology::euler_characteristic(&c.mesh), 2);
        assert!(crate::topology::boundary_loops(&c.mesh).is_empty());
        for f in 0..open.n_faces() {
            assert_eq!(c.mesh.face(FaceId::from_idx(f)), open.face(FaceId::from_idx(f)));
        }
        // A point on a fan's loop edge restricts onto the open face; one inside does not.
        let fan = FaceId::from_idx(open.n_faces());
        let (f, b) = c.restrict(fan, [0.25, 0.75, 0.0], 1e-9).unwrap();
        assert!(!c.is_cap_face(f));
        let p = |f: FaceId, b: [f64; 3]| {
            let q = c.mesh.face_points(f);
            q[0].coords * b[0] + q[1].coords * b[1] + q[2].coords * b[2]
        };
        assert!((p(f, b) - p(fan, [0.25, 0.75, 0.0])).norm() < 1e-12);
        assert!(c.restrict(fan, [0.2, 0.3, 0.5], 1e-9).is_none());
    }
}
