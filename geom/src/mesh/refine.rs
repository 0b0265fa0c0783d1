//! Geometry-preserving refinement (used by `homology` and `quad`): edges split at their midpoints, so
//! every refined face lies flat inside one original face. Each refined face remembers that face
//! and the barycentric coordinates of its corners there, so a point found on the refined mesh
//! converts exactly to a point on the original mesh.

use crate::error::Result;
use crate::mesh::{FaceId, Mesh, P3, VertexId};
use std::collections::HashMap;

/// A refinement of an original mesh. Original vertices keep their indices; new vertices follow.
#[derive(Debug, Clone)]
pub struct Refined {
    pub mesh: Mesh,
    /// Per refined face: the original face it lies in.
    pub face_origin: Vec<FaceId>,
    /// Per refined face: barycentric coordinates of its three corners in that original face.
    pub corner_bary: Vec<[[f64; 3]; 3]>,
}

impl Refined {
    /// The trivial refinement (the mesh itself).
    pub fn identity(mesh: &Mesh) -> Refined {
        let e = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
        Refined {
            mesh: mesh.clone(),
            face_origin: (0..mesh.n_faces()).map(FaceId::from_idx).collect(),
            corner_bary: vec![e; mesh.n_faces()],
        }
    }

    /// A point of refined face `f` (barycentric `b`) as a point of the original mesh.
    pub fn to_original(&self, f: FaceId, b: [f64; 3]) -> (FaceId, [f64; 3]) {
        let cb = &self.corner_bary[f.idx()];
        let mut o = [0.0; 3];
        for k in 0..3 {
            for (j, oj) in o.iter_mut().enumerate() {
                *oj += b[k] * cb[k][j];
            }
        }
        let s: f64 = o.iter().map(|x| x.max(0.0)).sum();
        let o = if s > 0.0 { o.map(|x| x.max(0.0) / s) } else { o };
        (self.face_origin[f.idx()], o)
    }

    /// Splits every listed edge (vertex pairs, either order) at its midpoint; faces with one, two
    /// or three split edges become two, three (shorter diagonal) or four faces.
    ///
    /// # Errors
    /// Only if the refined mesh fails validation, which would be a bug.
    pub fn split_edges(&self, edges: &[[VertexId; 2]]) -> Result<Refined> {
        if edges.is_empty() {
            return Ok(self.clone());
        }
        let mut pos: Vec<P3> = self.mesh.positions().to_vec();
        let mut mid: HashMap<(u32, u32), u32> = HashMap::with_capacity(edges.len());
        for &[a, b] in edges {
            let key = (a.0.min(b.0), a.0.max(b.0));
            mid.entry(key).or_insert_with(|| {
                pos.push(nalgebra::center(&pos[a.idx()], &pos[b.idx()]));
                (pos.len() - 1) as u32
            });
        }
        let nf = self.mesh.n_faces();
        let mut faces: Vec<[u32; 3]> = Vec::with_capacity(nf + 2 * edges.len());
        let mut origin = Vec::with_capacity(faces.capacity());
        let mut cbary = Vec::with_capacity(faces.capacity());
        for (f, tri) in self.mesh.faces().iter().enumerate() {
            let v = tri.map(|x| x.0);
            let b = self.corner_bary[f];
            let m = |i: usize, j: usize| mid.get(&(v[i].min(v[j]), v[i].max(v[j]))).copied();
            let avg = |i: usize, j: usize| {
                let mut o = [0.0; 3];
                for (k, ok) in o.iter_mut().enumerate() {
                    *ok = 0.5 * (b[i][k] + b[j][k]);
                }
                o
            };
            // Local corners: (vertex id, barycentric) for p0, p1, p2 and the midpoints.
            let split = [m(0, 1), m(1, 2), m(2, 0)];
            let n_split = split.iter().filter(|s| s.is_some()).count();
            let mut emit = |c: [(u32, [f64; 3]); 3]| {
                faces.push([c[0].0, c[1].0, c[2].0]);
                origin.push(self.face_origin[f]);
                cbary.push([c[0].1, c[1].1, c[2].1]);
            };
            let p = |i: usize| (v[i % 3], b[i % 3]);
            let q = |i: usize| split[i % 3].map(|id| (id, avg(i % 3, (i + 1) % 3)));
            match n_split {
                0 => emit([p(0), p(1), p(2)]),
                1 => {
                    let r = (0..3).find(|&i| split[i].is_some()).unwrap_or(0);
                    let Some(mr) = q(r) else { continue };
                    emit([p(r), mr, p(r + 2)]);
                    emit([mr, p(r + 1), p(r + 2)]);
                }
                2 => {
                    // r: the unsplit edge (p_r, p_{r+1}); split edges r+1 and r+2.
                    let r = (0..3).find(|&i| split[i].is_none()).unwrap_or(0);
                    let (Some(m1), Some(m2)) = (q(r + 1), q(r + 2)) else { continue };
                    // Corner p_{r+2} between m1 (on p_{r+1}p_{r+2}) and m2 (on p_{r+2}p_r).
                    emit([m1, p(r + 2), m2]);
                    let (a, bb) = (p(r), p(r + 1));
                    let d1 = (pos[a.0 as usize] - pos[m1.0 as usize]).norm();
                    let d2 = (pos[bb.0 as usize] - pos[m2.0 as usize]).norm();
                    if d1 <= d2 {
                        emit([a, bb, m1]);
                        emit([a, m1, m2]);
                    } else {
                        emit([a, bb, m2]);
                        emit([bb, m1, m2]);
                    }
                }
                _ => {
                    let (Some(m0), Some(m1), Some(m2)) = (q(0), q(1), q(2)) else { continue };
                    emit([p(0), m0, m2]);
                    emit([m0, p(1), m1]);
                    emit([m2, m1, p(2)]);
                    emit([m0, m1, m2]);
                }
            }
        }
        let mesh = Mesh::from_triangles(pos, &faces)?;
        Ok(Refined { mesh, face_origin: origin, corner_bary: cbary })
    }

    /// Splits the edges opposite `v` in its star, doubling its valence, until it has at least
    /// `min_valence` neighbours.
    ///
    /// # Errors
    /// As [`Refined::split_edges`].
    pub fn raise_valence(&self, v: VertexId, min_valence: usize) -> Result<Refined> {
        let mut r = self.clone();
        for _ in 0..6 {
            if r.mesh.outgoing(v).count() >= min_valence {
                break;
            }
            let link: Vec<[VertexId; 2]> =
                r.mesh.outgoing(v).map(|h| [r.mesh.head(h), r.mesh.head(h.next())]).collect();
            r = r.split_edges(&link)?;
        }
        Ok(r)
    }

    /// One round of midpoint subdivision (every face into four).
    ///
    /// # Errors
    /// As [`Refined::split_edges`].
    pub fn subdivide(&self) -> Result<Refined> {
        let all: Vec<[VertexId; 2]> =
            (0..self.mesh.n_edges()).map(|e| self.mesh.edge_vertices(crate::mesh::EdgeId::from_idx(e))).collect();
        self.split_edges(&all)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn refinement_keeps_the_surface_and_maps_back_exactly() {
        let t = shapes::torus(10, 5, 1.0, 0.3);
        let r = Refined::identity(&t).raise_valence(VertexId(0), 20).unwrap().subdivide().unwrap();
        assert!(r.mesh.outgoing(VertexId(0)).count() >= 20);
        assert_eq!(crate::topology::euler_characteristic(&r.mesh), 0);
        assert!((r.mesh.area() - t.area()).abs() < 1e-12 * t.area());
        // Every refined face centroid, mapped back, is the same 3D point on the original face.
        for f in 0..r.mesh.n_faces() {
            let f = FaceId::from_idx(f);
            let p = r.mesh.face_points(f);
            let c = P3::from((p[0].coords + p[1].coords + p[2].coords) / 3.0);
            let (of, b) = r.to_original(f, [1.0 / 3.0; 3]);
            let q = t.face_points(of);
            let back = q[0].coords * b[0] + q[1].coords * b[1] + q[2].coords * b[2];
            assert!((c.coords - back).norm() < 1e-12);
        }
    }
}
