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
}

/// Clusters faces around `anchors` (multi-source Dijkstra on the face dual) and finds the cuts.
///
/// # Errors
/// As [`face_voronoi`].
pub fn clusters(mesh: &Mesh, anchors: &[VertexId]) -> Result<Clusters> {
    let fv = face_voronoi(mesh, anchors, &FaceVoronoiOptions::default())?;
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
        let mut gs: Vec<Vec<EdgeId>> = groups.into_values().collect();
        gs.sort_unstable_by_key(|g| std::cmp::Reverse(g.len()));
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
    }
}
