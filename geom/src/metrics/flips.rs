//! Flipped faces as `meshmetrics.py` counts them: a mapped face is inverted when its normal
//! opposes the target's face normal at every place it lands (the target faces nearest to its
//! centroid and to its three corners, found through the evaluator's [`SurfaceIndex`]).

use super::surface_index::{Nearest, SurfaceIndex, centroid};
use crate::mesh::{FaceId, Mesh};

/// The inverted faces of `mapped` on `target`, in increasing order; `vertex_nearest` are the
/// nearest-surface answers for the mapped vertices (reused from the off-surface measurement).
pub fn flipped_faces(mapped: &Mesh, target: &Mesh, index: &SurfaceIndex, vertex_nearest: &[Nearest]) -> Vec<usize> {
    let tn: Vec<_> = (0..target.n_faces())
        .map(|f| {
            let n = target.face_normal_raw(FaceId::from_idx(f));
            n / n.norm().max(crate::tol::TINY)
        })
        .collect();
    let opposes = |nm: &crate::mesh::V3, g: FaceId| nm.dot(&tn[g.idx()]) < 0.0;
    // The centroid's nearest face is looked up only for faces already opposed at all three
    // corners, instead of for every face; the count is the same.
    let suspects: Vec<usize> = (0..mapped.n_faces())
        .filter(|&fi| {
            let nm = mapped.face_normal_raw(FaceId::from_idx(fi));
            mapped.faces()[fi].iter().all(|v| opposes(&nm, vertex_nearest[v.idx()].face))
        })
        .collect();
    let cents: Vec<_> = suspects.iter().map(|&f| centroid(mapped.face_points(FaceId::from_idx(f)))).collect();
    let at_centroid = index.query_all(&cents);
    suspects
        .iter()
        .zip(&at_centroid)
        .filter(|(fi, c)| opposes(&mapped.face_normal_raw(FaceId::from_idx(**fi)), c.face))
        .map(|(&fi, _)| fi)
        .collect()
}
