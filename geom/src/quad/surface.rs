//! What the remeshers need from one model, whatever built its quads: the surface point and
//! normal at quad coordinates `(s, t)` in the unit square, and the model's own vertices in quad
//! coordinates (for the adaptive error). Genus-0 models are two parameterized patches
//! ([`PatchSurface`]); higher-genus models are the `voronoi` layout's triangles, three quads each
//! ([`super::tri_quads::TriQuadSurface`]).

use super::partition::PatchMesh;
use crate::mesh::{Mesh, P3, V3};
use crate::param::Uv;
use crate::planar::locate::Grid;

/// One model's quads.
pub trait QuadSurface: Sync {
    /// Number of quads.
    fn n_quads(&self) -> usize;
    /// Surface point and unit normal (interpolated area-weighted vertex normals) at `st` of quad `q`.
    fn sample(&self, q: usize, st: Uv) -> (P3, V3);
    /// The model's vertices by quad, as `(st, position)`.
    fn vertices(&self) -> Vec<Vec<(Uv, P3)>>;
}

/// Area-weighted vertex normals.
pub fn vertex_normals(m: &Mesh) -> Vec<V3> {
    let mut n = vec![V3::zeros(); m.n_vertices()];
    for (f, t) in m.faces().iter().enumerate() {
        let w = m.face_normal_raw(crate::FaceId::from_idx(f));
        for v in t {
            n[v.idx()] += w;
        }
    }
    n.iter().map(|x| x.try_normalize(0.0).unwrap_or_else(V3::z)).collect()
}

/// Interpolates position and normal at barycentric `b` of triangle `t`.
pub fn interpolate(pos: &[P3], nor: &[V3], t: [u32; 3], b: [f64; 3]) -> (P3, V3) {
    let x = t.map(|v| pos[v as usize]);
    let m = t.map(|v| nor[v as usize]);
    (
        P3::from(x[0].coords * b[0] + x[1].coords * b[1] + x[2].coords * b[2]),
        (m[0] * b[0] + m[1] * b[1] + m[2] * b[2]).try_normalize(0.0).unwrap_or_else(V3::z),
    )
}

/// Genus-0 patches parameterized over the unit square (quad = patch).
pub struct PatchSurface<'a> {
    patches: &'a [PatchMesh],
    uvs: Vec<&'a [Uv]>,
    tris: Vec<Vec<[u32; 3]>>,
    locators: Vec<Grid>,
    normals: Vec<Vec<V3>>,
}

impl<'a> PatchSurface<'a> {
    pub fn new(patches: &'a [PatchMesh], uvs: Vec<&'a [Uv]>) -> Self {
        let tris: Vec<Vec<[u32; 3]>> = patches.iter().map(|p| p.mesh.face_indices()).collect();
        let locators = uvs.iter().zip(&tris).map(|(uv, t)| Grid::new(uv, t)).collect();
        let normals = patches.iter().map(|p| vertex_normals(&p.mesh)).collect();
        PatchSurface { patches, uvs, tris, locators, normals }
    }
}

impl QuadSurface for PatchSurface<'_> {
    fn n_quads(&self) -> usize {
        self.patches.len()
    }

    fn sample(&self, q: usize, st: Uv) -> (P3, V3) {
        let (f, b) = self.locators[q].locate(self.uvs[q], &self.tris[q], st);
        interpolate(self.patches[q].mesh.positions(), &self.normals[q], self.tris[q][f as usize], b)
    }

    fn vertices(&self) -> Vec<Vec<(Uv, P3)>> {
        self.patches
            .iter()
            .zip(&self.uvs)
            .map(|(p, uv)| uv.iter().copied().zip(p.mesh.positions().iter().copied()).collect())
            .collect()
    }
}
