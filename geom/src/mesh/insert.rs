//! Vertices inserted at surface points (anchors given as points): a point close to a vertex is
//! that vertex; close to an edge, the edge is split there (both faces); else its face is split in
//! three. The surface does not move: every new face lies in an old one. Original vertices keep
//! their ids; new ones follow in order.
//!
//! "Close" is within `tol` or within [`SLIVER`] of the face's shortest edge, whichever is
//! larger: snap rounding, as mesh generators do, so that no insertion makes a sliver triangle
//! (a vertex 1e-7 from another, as an f32 export puts it, breaks geodesics and layouts). The
//! caller reports how far each anchor moved.

use super::{FaceId, Mesh, P3, VertexId};
use crate::error::Result;
use std::collections::HashMap;

/// Where each point went.
#[derive(Debug, Clone)]
pub struct InsertResult {
    pub mesh: Mesh,
    /// The vertex at each point.
    pub vertices: Vec<VertexId>,
    /// Whether that vertex was inserted (else an existing vertex within `tol`).
    pub inserted: Vec<bool>,
}

/// Barycentric coordinates of `p` (in the plane of `a b c`).
pub fn barycentric(p: &P3, a: &P3, b: &P3, c: &P3) -> [f64; 3] {
    let (v0, v1, v2) = (b - a, c - a, p - a);
    let (d00, d01, d11) = (v0.dot(&v0), v0.dot(&v1), v1.dot(&v1));
    let (d20, d21) = (v2.dot(&v0), v2.dot(&v1));
    let den = d00 * d11 - d01 * d01;
    if den.abs() < 1e-300 {
        return [1.0, 0.0, 0.0];
    }
    let v = (d11 * d20 - d01 * d21) / den;
    let w = (d00 * d21 - d01 * d20) / den;
    [1.0 - v - w, v, w]
}

fn seg_dist(p: &P3, a: &P3, b: &P3) -> (f64, f64) {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared().max(1e-300)).clamp(0.0, 1.0);
    ((a + ab * t - p).norm(), t)
}

struct Editor {
    pos: Vec<P3>,
    faces: Vec<[u32; 3]>,
    /// Directed edge -> face.
    edge: HashMap<(u32, u32), usize>,
    /// Per original face, the current faces inside it.
    subs: HashMap<usize, Vec<usize>>,
    origin: Vec<usize>,
}

impl Editor {
    /// Sets face `f` (a new face when `f` is the face count) to `t`, inside original `origin`.
    fn set(&mut self, f: usize, t: [u32; 3], origin: usize) {
        if f == self.faces.len() {
            self.faces.push(t);
            self.origin.push(origin);
            self.subs.entry(origin).or_insert_with(|| vec![origin]).push(f);
        } else {
            self.faces[f] = t;
        }
        self.link(f, t);
    }

    fn link(&mut self, f: usize, t: [u32; 3]) {
        for k in 0..3 {
            self.edge.insert((t[k], t[(k + 1) % 3]), f);
        }
    }

    /// The current face inside original face `o` containing `p`, with `p`'s coordinates there.
    fn locate(&self, o: usize, p: &P3) -> (usize, [f64; 3]) {
        let cands = self.subs.get(&o).cloned().unwrap_or_else(|| vec![o]);
        let score = |f: usize| {
            let [a, b, c] = self.faces[f].map(|v| self.pos[v as usize]);
            let w = barycentric(p, &a, &b, &c);
            (w[0].min(w[1]).min(w[2]), w)
        };
        cands
            .iter()
            .map(|&f| (f, score(f)))
            .max_by(|x, y| x.1.0.total_cmp(&y.1.0))
            .map(|(f, s)| (f, s.1))
            .unwrap_or((o, [1.0, 0.0, 0.0]))
    }

    fn split_face(&mut self, f: usize, p: P3) -> u32 {
        let w = self.pos.len() as u32;
        self.pos.push(p);
        let [a, b, c] = self.faces[f];
        let o = self.origin[f];
        self.set(f, [a, b, w], o);
        let n = self.faces.len();
        self.set(n, [b, c, w], o);
        self.set(n + 1, [c, a, w], o);
        w
    }

    fn split_edge(&mut self, u: u32, v: u32, p: P3) -> u32 {
        let w = self.pos.len() as u32;
        self.pos.push(p);
        for (x, y) in [(u, v), (v, u)] {
            let Some(f) = self.edge.remove(&(x, y)) else { continue };
            let t = self.faces[f];
            let k = (0..3).find(|&k| t[k] == x).unwrap_or(0);
            let z = t[(k + 2) % 3];
            let o = self.origin[f];
            self.set(f, [x, w, z], o);
            let n = self.faces.len();
            self.set(n, [w, y, z], o);
        }
        w
    }
}

/// Fraction of a face's shortest edge within which a point snaps to a vertex or an edge.
pub const SLIVER: f64 = 0.01;

/// Inserts a vertex at each `(face, bary)` point of `mesh`, snapping within `tol` (see the
/// module doc).
///
/// # Errors
/// Only if the edited mesh fails validation, which would be a bug.
pub fn insert_points(mesh: &Mesh, points: &[(FaceId, [f64; 3])], tol: f64) -> Result<InsertResult> {
    let faces = mesh.face_indices();
    let mut ed = Editor {
        pos: mesh.positions().to_vec(),
        faces: faces.clone(),
        edge: HashMap::with_capacity(3 * faces.len()),
        subs: HashMap::new(),
        origin: (0..faces.len()).collect(),
    };
    for (f, t) in faces.iter().enumerate() {
        ed.link(f, *t);
    }
    let (mut vertices, mut inserted) = (Vec::new(), Vec::new());
    for &(f0, b) in points {
        let [a, bb, c] = faces[f0.idx()].map(|v| mesh.positions()[v as usize]);
        let p = P3::from(a.coords * b[0] + bb.coords * b[1] + c.coords * b[2]);
        let (f, _) = ed.locate(f0.idx(), &p);
        let t = ed.faces[f];
        let h = (0..3)
            .map(|k| (ed.pos[t[k] as usize] - ed.pos[t[(k + 1) % 3] as usize]).norm())
            .fold(f64::INFINITY, f64::min);
        let tol = tol.max(SLIVER * h);
        let corner = t.iter().map(|&v| (v, (ed.pos[v as usize] - p).norm())).min_by(|x, y| x.1.total_cmp(&y.1));
        if let Some((v, _)) = corner.filter(|c| c.1 <= tol) {
            vertices.push(VertexId(v));
            inserted.push(false);
            continue;
        }
        let edge = (0..3)
            .map(|k| (t[k], t[(k + 1) % 3]))
            .map(|(u, v)| (u, v, seg_dist(&p, &ed.pos[u as usize], &ed.pos[v as usize])))
            .min_by(|x, y| x.2.0.total_cmp(&y.2.0));
        let w = match edge {
            Some((u, v, (d, s))) if d <= tol => {
                let q = ed.pos[u as usize] + (ed.pos[v as usize] - ed.pos[u as usize]) * s;
                ed.split_edge(u, v, q)
            }
            _ => ed.split_face(f, p),
        };
        vertices.push(VertexId(w));
        inserted.push(true);
    }
    let mesh = if inserted.iter().any(|&x| x) { Mesh::from_triangles(ed.pos, &ed.faces)? } else { mesh.clone() };
    Ok(InsertResult { mesh, vertices, inserted })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::topology;

    /// A point inside a face, one on an edge, one on a vertex, and two in the same face: the
    /// surface keeps its Euler characteristic and area, every point becomes a vertex there.
    #[test]
    fn points_become_vertices_without_moving_the_surface() {
        let m = shapes::icosphere(1);
        let pts = [
            (FaceId(3), [0.2, 0.3, 0.5]),
            (FaceId(3), [0.6, 0.2, 0.2]),
            (FaceId(7), [0.5, 0.5, 0.0]),
            (FaceId(9), [1.0, 0.0, 0.0]),
        ];
        let r = insert_points(&m, &pts, 1e-9).unwrap();
        assert_eq!(r.inserted, vec![true, true, true, false]);
        assert_eq!(r.mesh.n_vertices(), m.n_vertices() + 3);
        assert_eq!(topology::euler_characteristic(&r.mesh), 2);
        assert!((r.mesh.area() - m.area()).abs() < 1e-12);
        for (k, &(f, b)) in pts.iter().enumerate() {
            let [a, bb, c] = m.faces()[f.idx()].map(|v| m.position(v));
            let p = P3::from(a.coords * b[0] + bb.coords * b[1] + c.coords * b[2]);
            assert!((r.mesh.position(r.vertices[k]) - p).norm() < 1e-12);
        }
        assert_eq!(r.vertices[3], m.faces()[9][0]);
    }
}
