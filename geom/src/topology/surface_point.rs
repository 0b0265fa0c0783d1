//! Points on a mesh surface: at a vertex, on an edge, or inside a face.

use crate::mesh::{FaceId, HalfedgeId, Mesh, P3, VertexId};
use serde::{Deserialize, Serialize};

/// A point on the surface of a mesh.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum SurfacePoint {
    /// Exactly at a vertex.
    Vertex { vertex: VertexId },
    /// On the edge of half-edge `halfedge`, at `t` in (0, 1) from its tail to its head.
    Edge { halfedge: HalfedgeId, t: f64 },
    /// Inside a face, with barycentric coordinates for its three corners (summing to 1).
    Face { face: FaceId, bary: [f64; 3] },
}

impl SurfacePoint {
    /// The 3D position.
    pub fn position(&self, mesh: &Mesh) -> P3 {
        match *self {
            SurfacePoint::Vertex { vertex } => mesh.position(vertex),
            SurfacePoint::Edge { halfedge, t } => {
                let a = mesh.position(mesh.tail(halfedge));
                let b = mesh.position(mesh.head(halfedge));
                P3::from(a.coords * (1.0 - t) + b.coords * t)
            }
            SurfacePoint::Face { face, bary } => {
                let [a, b, c] = mesh.face_points(face);
                P3::from(a.coords * bary[0] + b.coords * bary[1] + c.coords * bary[2])
            }
        }
    }

    /// The same point as a face and barycentric coordinates (a face incident to it).
    pub fn in_face(&self, mesh: &Mesh) -> (FaceId, [f64; 3]) {
        match *self {
            SurfacePoint::Vertex { vertex } => {
                let h = mesh.outgoing(vertex).next().unwrap_or(HalfedgeId(0));
                let mut b = [0.0; 3];
                b[h.corner()] = 1.0;
                (h.face(), b)
            }
            SurfacePoint::Edge { halfedge, t } => {
                let mut b = [0.0; 3];
                b[halfedge.corner()] = 1.0 - t;
                b[(halfedge.corner() + 1) % 3] = t;
                (halfedge.face(), b)
            }
            SurfacePoint::Face { face, bary } => (face, bary),
        }
    }
}
