//! Flipped faces as `meshmetrics.py` counts them: a mapped face is inverted when its normal
//! opposes the target's face normal at every place it lands (the target faces nearest to its
//! centroid and to its three corners, found through the evaluator's [`SurfaceIndex`]).

use super::surface_index::{Nearest, SurfaceIndex, centroid};
use crate::mesh::{FaceId, Mesh};

/// Counts inverted faces of `mapped` on `target`; `vertex_nearest` are the nearest-surface
/// answers for the mapped vertices (reused from the off-surface measurement).
pub fn flipped_faces(mapped: &Mesh, target: &Mesh, index: &SurfaceIndex, vertex_nearest: &[Nearest]) -> usize {
    let tn: Vec<_> = (0..target.n_faces())
        .map(|f| {
            let n = target.face_normal_raw(FaceId::from_idx(f));
            n / n.norm().max(crate::tol::TINY)
        })
        .collect();
    let cents: Vec<_> = (0..mapped.n_faces()).map(|f| centroid(mapped.face_points(FaceId::from_idx(f)))).collect();
    let at_centroid = index.query_all(&cents);
    let mut count = 0;
    for (fi, f) in mapped.faces().iter().enumerate() {
        let fid = FaceId::from_idx(fi);
        let nm = mapped.face_normal_raw(fid);
        let under = [
            at_centroid[fi].face,
            vertex_nearest[f[0].idx()].face,
            vertex_nearest[f[1].idx()].face,
            vertex_nearest[f[2].idx()].face,
        ];
        if under.iter().all(|g| nm.dot(&tn[g.idx()]) < 0.0) {
            count += 1;
        }
    }
    count
}
