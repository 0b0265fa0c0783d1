//! Multi-source Dijkstra over the face dual graph: each face is assigned to the nearest
//! source (an approximate geodesic Voronoi diagram by face clustering, Kwok et al. 5.1).
//! Dual arcs join adjacent faces with the centroid-to-edge-midpoint-to-centroid length,
//! which follows the surface better than the straight centroid chord.

use super::heap::MinHeap;
use crate::error::{InputError, Result};
use crate::mesh::{FaceId, HalfedgeId, Mesh, P3, VertexId};

/// Options for [`face_voronoi`].
#[derive(Debug, Clone, Default)]
pub struct FaceVoronoiOptions<'a> {
    /// Only faces in this set (indexed by face) are clustered; others stay unlabeled.
    pub faces: Option<&'a [bool]>,
}

/// Cluster label and distance per face.
#[derive(Debug, Clone)]
pub struct FaceVoronoiResult {
    /// Index of the nearest source per face (`u32::MAX` where unreached).
    pub label: Vec<u32>,
    /// Approximate geodesic distance from the face centroid to its source.
    pub dist: Vec<f64>,
}

fn centroid(mesh: &Mesh, f: FaceId) -> P3 {
    let [a, b, c] = mesh.face_points(f);
    P3::from((a.coords + b.coords + c.coords) / 3.0)
}

/// Clusters faces around vertex sources. A source seeds each of its incident faces with the
/// distance from the vertex to the face centroid.
///
/// # Errors
/// `InputError::OutOfRange` for a source outside the mesh; `Invalid` for a bad face mask.
pub fn face_voronoi(mesh: &Mesh, sources: &[VertexId], opts: &FaceVoronoiOptions) -> Result<FaceVoronoiResult> {
    let nf = mesh.n_faces();
    if let Some(m) = opts.faces
        && m.len() != nf
    {
        return Err(InputError::Invalid(format!("face mask has {} entries for {nf} faces", m.len())).into());
    }
    let allowed = |f: FaceId| opts.faces.is_none_or(|m| m[f.idx()]);
    let cent: Vec<P3> = (0..nf).map(|f| centroid(mesh, FaceId::from_idx(f))).collect();
    let mut dist = vec![f64::INFINITY; nf];
    let mut label = vec![u32::MAX; nf];
    let mut done = vec![false; nf];
    let mut heap = MinHeap::with_capacity(nf / 4 + 16);
    for (i, &s) in sources.iter().enumerate() {
        if s.idx() >= mesh.n_vertices() {
            return Err(
                InputError::OutOfRange { what: "source vertex", index: s.idx(), count: mesh.n_vertices() }.into()
            );
        }
        let ps = mesh.position(s);
        for f in mesh.vertex_faces(s) {
            if !allowed(f) {
                continue;
            }
            let d = (cent[f.idx()] - ps).norm();
            if d < dist[f.idx()] {
                dist[f.idx()] = d;
                label[f.idx()] = i as u32;
                heap.push(d, f.0);
            }
        }
    }
    while let Some((d, f)) = heap.pop() {
        let fi = f as usize;
        if done[fi] || d > dist[fi] {
            continue;
        }
        done[fi] = true;
        for k in 0..3 {
            let h = HalfedgeId::of(FaceId(f), k);
            let Some(t) = mesh.twin(h) else { continue };
            let g = t.face();
            if done[g.idx()] || !allowed(g) {
                continue;
            }
            let m = P3::from((mesh.position(mesh.tail(h)).coords + mesh.position(mesh.head(h)).coords) * 0.5);
            let nd = d + (m - cent[fi]).norm() + (cent[g.idx()] - m).norm();
            if nd < dist[g.idx()] {
                dist[g.idx()] = nd;
                label[g.idx()] = label[fi];
                heap.push(nd, g.0);
            }
        }
    }
    Ok(FaceVoronoiResult { label, dist })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn two_sources_split_sphere_and_cells_are_connected() {
        let s = shapes::icosphere(3);
        // Two antipodal-ish vertices.
        let a = VertexId(0);
        let b = (0..s.n_vertices())
            .map(VertexId::from_idx)
            .max_by(|x, y| (s.position(*x) - s.position(a)).norm().total_cmp(&(s.position(*y) - s.position(a)).norm()))
            .unwrap();
        let r = face_voronoi(&s, &[a, b], &Default::default()).unwrap();
        assert!(r.label.iter().all(|&l| l < 2), "every face covered");
        let n0 = r.label.iter().filter(|&&l| l == 0).count();
        assert!((n0 as f64 / s.n_faces() as f64 - 0.5).abs() < 0.1);
        // Each cell is connected through face adjacency.
        for lab in 0..2u32 {
            let start = r.label.iter().position(|&l| l == lab).unwrap();
            let mut seen = vec![false; s.n_faces()];
            let mut stack = vec![FaceId::from_idx(start)];
            seen[start] = true;
            let mut n = 0;
            while let Some(f) = stack.pop() {
                n += 1;
                for g in s.face_neighbors(f) {
                    if !seen[g.idx()] && r.label[g.idx()] == lab {
                        seen[g.idx()] = true;
                        stack.push(g);
                    }
                }
            }
            assert_eq!(n, r.label.iter().filter(|&&l| l == lab).count());
        }
    }
}
