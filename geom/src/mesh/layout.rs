//! The input's own vertex layout: asset formats (glTF, OBJ with `vt`/`vn`) split a vertex
//! wherever an attribute changes (a UV or normal seam), so one surface point is several input
//! vertices. Mapping runs on the *welded* mesh (one vertex per position); [`InputLayout`] keeps
//! the way back, so outputs are written in the input's layout with its attributes.
//!
//! Invariant: `welded[i]` is the mesh vertex of input vertex `i`; `triangles[f]` are the input
//! vertices of mesh face `f` (same order), so `welded[triangles[f][k]] == mesh.faces()[f][k]`.

use super::{RawMesh, Warning};
use crate::error::{InputError, Result};
use std::collections::HashMap;

/// Per-vertex attributes of an asset, in the input's vertex layout. Each is present for all
/// vertices or absent.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Attributes {
    /// `NORMAL` (unit vectors).
    pub normals: Option<Vec<[f32; 3]>>,
    /// `TEXCOORD_0`, `TEXCOORD_1`, ... in order.
    pub texcoords: Vec<Vec<[f32; 2]>>,
    /// `COLOR_0` as linear RGBA.
    pub color: Option<Vec<[f32; 4]>>,
    /// `JOINTS_0`.
    pub joints: Option<Vec<[u16; 4]>>,
    /// `WEIGHTS_0`.
    pub weights: Option<Vec<[f32; 4]>>,
}

impl From<&super::VertexAttributes> for Attributes {
    /// A mesh's own per-vertex attributes in asset form (colours as glTF's linear RGBA).
    fn from(a: &super::VertexAttributes) -> Self {
        let lin = |x: u8| {
            let s = f32::from(x) / 255.0;
            if s <= 0.04045 { s / 12.92 } else { ((s + 0.055) / 1.055).powf(2.4) }
        };
        Attributes {
            normals: a.normals.as_ref().map(|n| n.iter().map(|v| [v.x as f32, v.y as f32, v.z as f32]).collect()),
            texcoords: a.uvs.iter().map(|t| t.iter().map(|u| [u[0] as f32, u[1] as f32]).collect()).collect(),
            color: a
                .colors
                .as_ref()
                .map(|c| c.iter().map(|c| [lin(c[0]), lin(c[1]), lin(c[2]), f32::from(c[3]) / 255.0]).collect()),
            ..Default::default()
        }
    }
}

impl Attributes {
    /// Whether no attribute is present.
    pub fn is_empty(&self) -> bool {
        self.normals.is_none()
            && self.texcoords.is_empty()
            && self.color.is_none()
            && self.joints.is_none()
            && self.weights.is_none()
    }

    /// glTF names of the attributes present, e.g. `["NORMAL", "TEXCOORD_0"]`.
    pub fn names(&self) -> Vec<String> {
        let mut n = Vec::new();
        if self.normals.is_some() {
            n.push("NORMAL".to_string());
        }
        n.extend((0..self.texcoords.len()).map(|k| format!("TEXCOORD_{k}")));
        for (name, here) in [
            ("COLOR_0", self.color.is_some()),
            ("JOINTS_0", self.joints.is_some()),
            ("WEIGHTS_0", self.weights.is_some()),
        ] {
            if here {
                n.push(name.to_string());
            }
        }
        n
    }
}

/// What a reader of a split format returns: triangles over input vertices that may repeat a
/// position.
#[derive(Debug, Clone, Default)]
pub struct SplitMesh {
    pub positions: Vec<[f64; 3]>,
    pub triangles: Vec<[u32; 3]>,
    pub attributes: Attributes,
    pub warnings: Vec<Warning>,
}

/// The input's vertices and triangles over the welded mesh (see the module invariant).
#[derive(Debug, Clone, PartialEq)]
pub struct InputLayout {
    /// Input vertex -> welded mesh vertex.
    pub welded: Vec<u32>,
    /// Input triangles, one per mesh face, in input vertex ids.
    pub triangles: Vec<[u32; 3]>,
    /// The input's attributes, per input vertex.
    pub attributes: Attributes,
    /// Which numbering a job's vertex ids use for this input.
    pub ids: VertexIds,
}

/// The numbering of vertex ids in anchors, features and ground truth for an input with a
/// layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VertexIds {
    /// The input's own vertices (glTF: the vertices of its primitives, in scene order).
    Input,
    /// The welded vertices (OBJ: its `v` lines).
    Welded,
}

impl InputLayout {
    /// Number of input vertices.
    pub fn n_vertices(&self) -> usize {
        self.welded.len()
    }

    /// Input vertices that share a position with another one (seam copies), counted once per
    /// extra copy.
    pub fn n_split(&self) -> usize {
        let n_welded = self.welded.iter().map(|&w| w as usize + 1).max().unwrap_or(0);
        self.welded.len().saturating_sub(n_welded)
    }

    /// `per_welded` (one value per mesh vertex) in the input layout.
    pub fn spread<T: Clone>(&self, per_welded: &[T]) -> Vec<T> {
        self.welded.iter().map(|&w| per_welded[w as usize].clone()).collect()
    }
}

/// Welds input vertices with bit-identical positions (`-0.0` counts as `0.0`). Only vertices
/// some triangle uses become mesh vertices, so [`super::Mesh::from_raw`] keeps the numbering
/// and the faces.
///
/// # Errors
/// `InputError::IndexOutOfRange` for a triangle naming a vertex that does not exist.
pub fn weld(split: SplitMesh) -> Result<(RawMesh, InputLayout)> {
    let SplitMesh { positions, triangles, attributes, warnings } = split;
    let nv = positions.len();
    if let Some((f, &i)) =
        triangles.iter().enumerate().find_map(|(f, t)| t.iter().find(|&&i| i as usize >= nv).map(|i| (f, i)))
    {
        return Err(InputError::IndexOutOfRange { face: f, index: i64::from(i), vertex_count: nv }.into());
    }
    let key = |p: &[f64; 3]| p.map(|c| (c + 0.0).to_bits());
    let mut used = vec![false; nv];
    for &v in triangles.iter().flatten() {
        used[v as usize] = true;
    }
    // Welded ids follow the input order of each position's first used vertex, so an input
    // without seams keeps its numbering.
    let mut index: HashMap<[u64; 3], u32> = HashMap::with_capacity(nv);
    let mut welded = vec![u32::MAX; nv];
    let mut out_pos: Vec<[f64; 3]> = Vec::with_capacity(nv);
    for v in (0..nv).filter(|&v| used[v]) {
        let next = out_pos.len() as u32;
        let w = *index.entry(key(&positions[v])).or_insert(next);
        if w == next {
            out_pos.push(positions[v]);
        }
        welded[v] = w;
    }
    let indices: Vec<u32> = triangles.iter().flatten().map(|&v| welded[v as usize]).collect();
    // An input vertex no triangle uses keeps a place in the layout when a used vertex shares its
    // position; otherwise it is dropped (with a warning).
    let of: Vec<Option<u32>> = (0..positions.len())
        .map(|v| Some(welded[v]).filter(|&w| w != u32::MAX).or_else(|| index.get(&key(&positions[v])).copied()))
        .collect();
    let keep: Vec<u32> = (0..positions.len() as u32).filter(|&v| of[v as usize].is_some()).collect();
    let mut warnings = warnings;
    let (layout_welded, triangles, attributes) = if keep.len() == positions.len() {
        (of.into_iter().flatten().collect(), triangles, attributes)
    } else {
        warnings.push(Warning::new(
            "unreferenced_vertices",
            format!("{} input vertices no triangle uses were dropped", positions.len() - keep.len()),
        ));
        let mut renumber = vec![u32::MAX; positions.len()];
        for (k, &v) in keep.iter().enumerate() {
            renumber[v as usize] = k as u32;
        }
        let w = keep.iter().filter_map(|&v| of[v as usize]).collect();
        let tris = triangles.iter().map(|t| t.map(|v| renumber[v as usize])).collect();
        (w, tris, attributes.select(&keep))
    };
    let raw = RawMesh { positions: out_pos, indices, sizes: None, warnings, ..Default::default() };
    Ok((raw, InputLayout { welded: layout_welded, triangles, attributes, ids: VertexIds::Input }))
}

impl Attributes {
    /// The entries of the vertices in `keep`, in that order.
    pub fn select(&self, keep: &[u32]) -> Attributes {
        fn pick<T: Clone>(v: &[T], keep: &[u32]) -> Vec<T> {
            keep.iter().map(|&i| v[i as usize].clone()).collect()
        }
        Attributes {
            normals: self.normals.as_deref().map(|v| pick(v, keep)),
            texcoords: self.texcoords.iter().map(|v| pick(v, keep)).collect(),
            color: self.color.as_deref().map(|v| pick(v, keep)),
            joints: self.joints.as_deref().map(|v| pick(v, keep)),
            weights: self.weights.as_deref().map(|v| pick(v, keep)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::Mesh;

    /// Two triangles of a square split along their shared edge (a UV seam): the weld joins the
    /// copies, the mesh keeps the layout's face order and the layout maps every copy back.
    #[test]
    fn seam_copies_weld_to_one_vertex() {
        let positions =
            vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [-0.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
        let split = SplitMesh {
            positions,
            triangles: vec![[0, 1, 2], [3, 4, 5]],
            attributes: Attributes { texcoords: vec![vec![[0.0, 0.0]; 6]], ..Default::default() },
            warnings: Vec::new(),
        };
        let (raw, layout) = weld(split).unwrap();
        assert_eq!(raw.positions.len(), 4);
        assert_eq!(layout.welded, vec![0, 1, 2, 0, 2, 3]);
        assert_eq!(layout.n_split(), 2);
        let (mesh, _) = Mesh::from_raw(raw).unwrap();
        for (f, t) in layout.triangles.iter().enumerate() {
            let m = mesh.faces()[f];
            for (k, &v) in t.iter().enumerate() {
                assert_eq!(layout.welded[v as usize], m[k].0);
            }
        }
    }
}
