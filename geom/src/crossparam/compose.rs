//! Composition of two patch parameterizations into a map between the original meshes: a
//! vertex of mesh A is looked up in its patch's triangle coordinates and located in mesh B's
//! embedding of the same patch; the refined face found there is expressed in B's original face.

use super::patch_param::PatchParam;
use crate::domain::refine::{Refined, bary_in};
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, VertexId};
use crate::param::Uv;

/// Where each original vertex of mesh A sits in the patch parameterization: (patch, uv).
pub fn vertex_uv(pa: &[PatchParam], n: usize) -> Vec<(u32, Uv)> {
    let mut out = vec![(u32::MAX, [0.0; 2]); n];
    for (pi, p) in pa.iter().enumerate() {
        for (l, g) in p.global_v.iter().enumerate() {
            if g.idx() < n && out[g.idx()].0 == u32::MAX {
                out[g.idx()] = (pi as u32, p.uv[l]);
            }
        }
    }
    out
}

/// The point of B's original mesh at patch `patch`, triangle coordinates `uv`.
pub fn locate_in(rb: &Refined, b: &Mesh, pb: &[PatchParam], patch: u32, uv: Uv) -> (FaceId, [f64; 3]) {
    let (rf, bary) = pb[patch as usize].locate(uv);
    let parent = rb.parent[rf.idx()];
    let tri = rb.mesh.face(rf);
    let mut out = [0.0; 3];
    for k in 0..3 {
        let q = bary_in(b, parent, &rb.point[tri[k].idx()]);
        for j in 0..3 {
            out[j] += bary[k] * q[j];
        }
    }
    let out = out.map(|x| x.max(0.0));
    let s: f64 = out.iter().sum();
    (parent, if s > 0.0 { out.map(|x| x / s) } else { [1.0, 0.0, 0.0] })
}

/// The map from A's original vertices to B's surface. Anchors go exactly to their partners.
pub fn compose(
    pa: &[PatchParam],
    a: &Mesh,
    rb: &Refined,
    pb: &[PatchParam],
    b: &Mesh,
    anchors: &[(VertexId, VertexId)],
) -> SurfaceMap {
    let n = a.n_vertices();
    let uv = vertex_uv(pa, n);
    let mut face = Vec::with_capacity(n);
    let mut bary = Vec::with_capacity(n);
    for &(patch, p) in uv.iter().take(n) {
        let (f, w) = locate_in(rb, b, pb, patch, p);
        face.push(f);
        bary.push(w);
    }
    let mut map = SurfaceMap { face, bary };
    place_anchors(&mut map, b, anchors);
    map
}

/// Puts each anchor `s` of `map` exactly on its partner `t`, a vertex of `b`.
pub fn place_anchors(map: &mut SurfaceMap, b: &Mesh, anchors: &[(VertexId, VertexId)]) {
    for &(s, t) in anchors {
        if let Some(h) = b.outgoing(t).next() {
            let mut w = [0.0; 3];
            w[h.corner()] = 1.0;
            map.face[s.idx()] = h.face();
            map.bary[s.idx()] = w;
        }
    }
}
