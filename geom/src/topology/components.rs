//! Connected components of a mesh (through shared edges and vertices: a built mesh is
//! manifold, so face adjacency across edges gives the same components).

use crate::mesh::{FaceId, Mesh};

/// Component labels per face.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Components {
    /// Number of components.
    pub count: usize,
    /// Component of each face.
    pub face_label: Vec<u32>,
}

/// Labels faces by connected component (breadth-first over face adjacency).
pub fn components(mesh: &Mesh) -> Components {
    let nf = mesh.n_faces();
    let mut label = vec![u32::MAX; nf];
    let mut count = 0u32;
    let mut stack = Vec::new();
    for seed in 0..nf {
        if label[seed] != u32::MAX {
            continue;
        }
        label[seed] = count;
        stack.push(FaceId::from_idx(seed));
        while let Some(f) = stack.pop() {
            for g in mesh.face_neighbors(f) {
                if label[g.idx()] == u32::MAX {
                    label[g.idx()] = count;
                    stack.push(g);
                }
            }
        }
        count += 1;
    }
    Components { count: count as usize, face_label: label }
}

/// Counts and genus of one connected component (`surfmap inspect` lists them).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct PartSummary {
    pub vertices: usize,
    pub faces: usize,
    pub edges: usize,
    pub boundary_loops: usize,
    pub genus: i64,
}

/// One [`PartSummary`] per connected component, in [`components`] order.
pub fn parts(mesh: &Mesh) -> Vec<PartSummary> {
    let c = components(mesh);
    let mut out = vec![PartSummary { vertices: 0, faces: 0, edges: 0, boundary_loops: 0, genus: 0 }; c.count];
    let mut vseen = vec![false; mesh.n_vertices()];
    let mut eseen = vec![false; mesh.n_edges()];
    for (f, tri) in mesh.faces().iter().enumerate() {
        let p = &mut out[c.face_label[f] as usize];
        p.faces += 1;
        for (k, v) in tri.iter().enumerate() {
            if !std::mem::replace(&mut vseen[v.idx()], true) {
                p.vertices += 1;
            }
            let e = mesh.edge(crate::mesh::HalfedgeId((3 * f + k) as u32));
            if !std::mem::replace(&mut eseen[e.idx()], true) {
                p.edges += 1;
            }
        }
    }
    for l in super::boundary_loops(mesh) {
        if let Some(&h) = l.first() {
            out[c.face_label[h.idx() / 3] as usize].boundary_loops += 1;
        }
    }
    for p in &mut out {
        let chi = p.vertices as i64 - p.edges as i64 + p.faces as i64;
        p.genus = (2 - p.boundary_loops as i64 - chi) / 2;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    /// A sphere beside a torus: two parts, genus 0 and 1, counts adding up to the whole.
    #[test]
    fn parts_of_a_sphere_and_a_torus() {
        let (a, b) = (shapes::icosphere(1), shapes::torus(8, 6, 1.0, 0.3));
        let n = a.n_vertices() as u32;
        let mut pos = a.positions().to_vec();
        pos.extend(b.positions().iter().map(|p| p + crate::mesh::V3::new(5.0, 0.0, 0.0)));
        let mut tris = a.face_indices();
        tris.extend(b.face_indices().iter().map(|t| t.map(|v| v + n)));
        let m = Mesh::from_triangles(pos, &tris).unwrap();
        let p = parts(&m);
        assert_eq!(p.len(), 2);
        assert_eq!((p[0].genus, p[1].genus), (0, 1));
        assert_eq!(p[0].vertices + p[1].vertices, m.n_vertices());
        assert_eq!(p[0].edges + p[1].edges, m.n_edges());
    }
}
