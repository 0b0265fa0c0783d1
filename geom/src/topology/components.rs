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
