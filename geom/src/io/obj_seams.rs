//! OBJ with seams: when corners of one `v` use different `vt` or `vn`, every distinct
//! `(v, vt, vn)` triple becomes an input vertex (as glTF stores it), welded back to its `v`
//! (see [`crate::mesh::layout`]).

use crate::mesh::{Attributes, SplitMesh, V3};

/// Per-corner indices of a triangle-only OBJ.
pub(super) struct Corners<'a> {
    pub positions: &'a [[f64; 3]],
    pub indices: &'a [u32],
    pub vt: &'a [u32],
    pub vts: &'a [[f64; 2]],
    pub vn: &'a [u32],
    pub vns: &'a [V3],
}

/// `None` unless some corner carries an index (`u32::MAX` = absent).
fn value<T: Copy>(values: &[T], i: u32) -> Option<T> {
    values.get(i as usize).copied()
}

impl Corners<'_> {
    /// The welded (`v`) vertex of each input vertex, and the split mesh, keeping `vt` and `vn`
    /// only when every corner has a valid one.
    pub fn split(&self) -> (Vec<u32>, SplitMesh) {
        let has_vt = !self.vts.is_empty() && self.vt.iter().all(|&i| (i as usize) < self.vts.len());
        let has_vn = !self.vns.is_empty() && self.vn.iter().all(|&i| (i as usize) < self.vns.len());
        let mut index = std::collections::HashMap::new();
        let mut out = SplitMesh::default();
        let mut uv = Vec::new();
        let mut nrm = Vec::new();
        let mut welded = Vec::new();
        let mut corner_ids = Vec::with_capacity(self.indices.len());
        for k in 0..self.indices.len() {
            let key = (self.indices[k], if has_vt { self.vt[k] } else { 0 }, if has_vn { self.vn[k] } else { 0 });
            let next = out.positions.len() as u32;
            let id = *index.entry(key).or_insert(next);
            if id == next {
                welded.push(key.0);
                out.positions.push(self.positions[key.0 as usize]);
                if let (true, Some(t)) = (has_vt, value(self.vts, key.1)) {
                    uv.push([t[0] as f32, t[1] as f32]);
                }
                if let (true, Some(n)) = (has_vn, value(self.vns, key.2)) {
                    nrm.push([n.x as f32, n.y as f32, n.z as f32]);
                }
            }
            corner_ids.push(id);
        }
        out.triangles = corner_ids.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        out.attributes = Attributes {
            normals: has_vn.then_some(nrm),
            texcoords: if has_vt { vec![uv] } else { Vec::new() },
            ..Default::default()
        };
        (welded, out)
    }
}
