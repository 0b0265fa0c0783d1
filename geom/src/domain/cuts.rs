//! Voronoi cues: face clusters around the anchors and the cuts between them (Kwok et al. 5.1).
//! A cut is a maximal run of edges, connected through shared vertices, along which the same
//! two clusters touch; two clusters may share several cuts (Observation 2).

use super::uf_find;
use crate::error::Result;
use crate::geodesic::{FaceVoronoiOptions, face_voronoi};
use crate::mesh::{EdgeId, FaceId, Mesh, VertexId};
use std::collections::HashMap;

/// One cut between clusters `i < j`.
#[derive(Debug, Clone, PartialEq)]
pub struct Cut {
    pub i: u32,
    pub j: u32,
    pub edges: Vec<EdgeId>,
    pub vertices: Vec<VertexId>,
}

/// Clusters and cuts of a mesh.
#[derive(Debug, Clone)]
pub struct Clusters {
    /// Anchor index per face.
    pub label: Vec<u32>,
    pub cuts: Vec<Cut>,
    /// Faces of each cluster.
    pub faces: Vec<Vec<FaceId>>,
}

impl Clusters {
    /// Cuts between `i` and `j` (any order).
    pub fn between(&self, i: u32, j: u32) -> impl Iterator<Item = (usize, &Cut)> {
        let (i, j) = (i.min(j), i.max(j));
        self.cuts.iter().enumerate().filter(move |(_, c)| c.i == i && c.j == j)
    }
    /// Face mask of the union of clusters `i` and `j`.
    pub fn mask(&self, i: u32, j: u32) -> Vec<bool> {
        self.label.iter().map(|&l| l == i || l == j).collect()
    }

    /// Anchors whose cell is not a disk: it falls apart into several pieces, or its Euler
    /// characteristic `V − E + F` is not 1 (a handle or a tube runs through it, or it holds a
    /// whole boundary loop). The dual layout of such cells is not cellular — the closed-ball
    /// property of a Voronoi diagram fails — and completing it may need more anchors there.
    pub fn non_disk(&self, mesh: &Mesh) -> Vec<u32> {
        let mut out = Vec::new();
        for (a, faces) in self.faces.iter().enumerate() {
            if faces.is_empty() {
                // An anchor inside faces left out (a cone's apex) has no cell.
                continue;
            }
            let mut verts: Vec<VertexId> = faces.iter().flat_map(|&f| mesh.face(f)).collect();
            verts.sort_unstable();
            verts.dedup();
            // Edges as sorted vertex pairs, each with the first cluster face seen on it.
            let mut edges: HashMap<(VertexId, VertexId), usize> = HashMap::new();
            let mut parent: Vec<usize> = (0..faces.len()).collect();
            for (k, &f) in faces.iter().enumerate() {
                let [x, y, z] = mesh.face(f);
                for (u, w) in [(x, y), (y, z), (z, x)] {
                    let key = (u.min(w), u.max(w));
                    if let Some(&o) = edges.get(&key) {
                        let (r, q) = (uf_find(&mut parent, k), uf_find(&mut parent, o));
                        parent[r] = q;
                    } else {
                        edges.insert(key, k);
                    }
                }
            }
            let pieces = (0..faces.len()).filter(|&k| uf_find(&mut parent, k) == k).count();
            let chi = verts.len() as i64 - edges.len() as i64 + faces.len() as i64;
            if pieces != 1 || chi != 1 {
                out.push(a as u32);
            }
        }
        out
    }
}

/// Clusters faces around `anchors` (multi-source Dijkstra on the face dual) and finds the cuts.
///
/// # Errors
/// As [`face_voronoi`].
pub fn clusters(mesh: &Mesh, anchors: &[VertexId]) -> Result<Clusters> {
    clusters_in(mesh, anchors, None)
}

/// [`clusters`] of the faces in `faces` only (distances do not pass through the others: the
/// cones that close an open mesh's loops, whose faces stay unlabelled).
///
/// # Errors
/// As [`clusters`].
pub fn clusters_in(mesh: &Mesh, anchors: &[VertexId], faces: Option<&[bool]>) -> Result<Clusters> {
    let fv = face_voronoi(mesh, anchors, &FaceVoronoiOptions { faces })?;
    let label = fv.label;
    let mut by_pair: HashMap<(u32, u32), Vec<EdgeId>> = HashMap::new();
    for e in 0..mesh.n_edges() {
        let e = EdgeId::from_idx(e);
        let (f, g) = mesh.edge_faces(e);
        let Some(g) = g else { continue };
        let (a, b) = (label[f.idx()], label[g.idx()]);
        if a != b && a != u32::MAX && b != u32::MAX {
            by_pair.entry((a.min(b), a.max(b))).or_default().push(e);
        }
    }
    let mut pairs: Vec<_> = by_pair.into_iter().collect();
    pairs.sort_unstable_by_key(|(k, _)| *k);
    let mut cuts = Vec::new();
    for ((i, j), edges) in pairs {
        // Union-find over the pair's edges through shared vertices.
        let mut parent: Vec<usize> = (0..edges.len()).collect();
        let mut at_vertex: HashMap<VertexId, usize> = HashMap::new();
        for (k, &e) in edges.iter().enumerate() {
            for v in mesh.edge_vertices(e) {
                if let Some(&o) = at_vertex.get(&v) {
                    let (a, b) = (uf_find(&mut parent, k), uf_find(&mut parent, o));
                    parent[a] = b;
                } else {
                    at_vertex.insert(v, k);
                }
            }
        }
        let mut groups: HashMap<usize, Vec<EdgeId>> = HashMap::new();
        for (k, &e) in edges.iter().enumerate() {
            groups.entry(uf_find(&mut parent, k)).or_default().push(e);
        }
        // Longest first; equal lengths by their first edge, so the order does not depend on the
        // hash map's (per-process random) iteration order.
        let mut gs: Vec<Vec<EdgeId>> = groups.into_values().collect();
        gs.sort_unstable_by_key(|g| (std::cmp::Reverse(g.len()), g[0]));
        for g in gs {
            let mut vertices: Vec<VertexId> = g.iter().flat_map(|&e| mesh.edge_vertices(e)).collect();
            vertices.sort_unstable();
            vertices.dedup();
            cuts.push(Cut { i, j, edges: g, vertices });
        }
    }
    let mut faces = vec![Vec::new(); anchors.len()];
    for (f, &l) in label.iter().enumerate() {
        if let Some(v) = faces.get_mut(l as usize) {
            v.push(FaceId::from_idx(f));
        }
    }
    Ok(Clusters { label, cuts, faces })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn two_anchors_on_a_sphere_share_one_cut_and_torus_rings_share_two() {
        let s = shapes::icosphere(3);
        let far = (0..s.n_vertices())
            .max_by(|&a, &b| {
                let d = |v: usize| (s.position(VertexId::from_idx(v)) - s.position(VertexId(0))).norm();
                d(a).total_cmp(&d(b))
            })
            .unwrap();
        let c = clusters(&s, &[VertexId(0), VertexId::from_idx(far)]).unwrap();
        assert_eq!(c.cuts.len(), 1);
        // Two anchors on opposite sides of a torus's tube: two cuts (multiple linkage cue).
        let t = shapes::torus(24, 8, 1.0, 0.3);
        let c = clusters(&t, &[VertexId(0), VertexId(12 * 8)]).unwrap();
        assert_eq!(c.between(0, 1).count(), 2);
        // Each of those two cells is a band around the tube (V - E + F = 0), not a disk; the
        // sphere's two cells are disks.
        assert_eq!(c.non_disk(&t), vec![0, 1]);
        let c = clusters(&s, &[VertexId(0), VertexId::from_idx(far)]).unwrap();
        assert!(c.non_disk(&s).is_empty());
    }
}
