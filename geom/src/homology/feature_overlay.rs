//! The meta-mesh of a feature job (Carner et al. section 4 on the circle domains of section
//! 3.4): both cut disks overlaid in the unit circle.
//!
//! Unlike the two 4g-gons, whose sides are the same straight segments, the two circle domains
//! have different boundary polygons: each is inscribed in the circle with its own vertices, so
//! a sliver between two chords belongs to one disk only. Each disk's boundary is therefore
//! refined first by the other's boundary points: a point of the other disk whose angle falls
//! strictly inside a boundary edge becomes a vertex of this disk on the circle (its planar
//! position copied bit for bit), placed on the surface on that edge at the fraction of the angle
//! (the rule the maps use, `feature_map::snap_boundary`), and the face on the edge is fanned.
//! Both disks then tile the same polygon and [`super::overlay::overlay`] merges them. Points
//! the two domains share exactly (junctions between sides, which have the same angle on both,
//! and interior anchors the source domain was warped onto) are one meta-vertex. Copies on the
//! two sides of a slit carry the same key, so the result is sewn along every cut.

use super::feature_map::{FeatureSide, angle};
use super::overlay::{MetaMeshResult, OverlayDisk, OverlayInput, VKey, overlay};
use crate::error::{Error, Result};
use crate::mesh::{FaceId, HalfedgeId, Mesh, P3, VertexId};
use crate::param::Uv;
use std::collections::HashMap;

/// Boundary points closer in angle than this are one point.
const SAME_ANGLE: f64 = 1e-12;

/// A disk with its boundary refined: positions on its own surface, planar positions, keys.
struct RefinedDisk {
    mesh: Mesh,
    uv: Vec<Uv>,
    key: Vec<VKey>,
}

/// One side's boundary walk: angle, key and planar position of each walk vertex, in order.
fn walk(side: &FeatureSide, key: fn(u32) -> VKey) -> Vec<(f64, VKey, Uv)> {
    side.cut
        .walk
        .iter()
        .map(|v| {
            let p = side.domain.uv[v.idx()];
            (angle(p), key(side.cut.disk.orig[v.idx()].0), p)
        })
        .collect()
}

/// Index of a walk point whose angle is within [`SAME_ANGLE`] of `a` (angles ascending from 0).
fn same_point(w: &[(f64, VKey, Uv)], a: f64) -> Option<usize> {
    let tau = std::f64::consts::TAU;
    let i = w.partition_point(|x| x.0 < a - SAME_ANGLE);
    if i < w.len() && (w[i].0 - a).abs() <= SAME_ANGLE {
        return Some(i);
    }
    // The base sits at angle 0, which is also 2π.
    (!w.is_empty() && (a - tau).abs() <= SAME_ANGLE && w[0].0 == 0.0).then_some(0)
}

/// `own`'s disk (its walk `mine`) with every point of `other` (not shared with `own`) inserted
/// into the boundary edge whose angles enclose it.
fn refine(
    own: &FeatureSide,
    own_key: fn(u32) -> VKey,
    mine: &[(f64, VKey, Uv)],
    other: &[(f64, VKey, Uv)],
) -> Result<RefinedDisk> {
    let tau = std::f64::consts::TAU;
    let disk = &own.cut.disk.mesh;
    let mut pos: Vec<P3> = disk.positions().to_vec();
    let mut uv = own.domain.uv.clone();
    let mut key: Vec<VKey> = own.cut.disk.orig.iter().map(|v| own_key(v.0)).collect();
    // Inserted vertices of each boundary edge, by the edge's first walk vertex.
    let mut inserted: HashMap<VertexId, Vec<u32>> = HashMap::new();
    let n = own.cut.walk.len();
    for (i, &v) in own.cut.walk.iter().enumerate() {
        let w = own.cut.walk[(i + 1) % n];
        let (a0, a1) = (mine[i].0, if i + 1 < n { mine[i + 1].0 } else { tau });
        let lo = other.partition_point(|x| x.0 <= a0 + SAME_ANGLE);
        let mut ids = Vec::new();
        for &(a, k, p) in &other[lo..] {
            if a >= a1 - SAME_ANGLE {
                break;
            }
            let t = (a - a0) / (a1 - a0);
            pos.push(P3::from(disk.position(v).coords * (1.0 - t) + disk.position(w).coords * t));
            uv.push(p);
            key.push(k);
            ids.push((pos.len() - 1) as u32);
        }
        if !ids.is_empty() {
            inserted.insert(v, ids);
        }
    }
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(disk.n_faces() + pos.len());
    for f in 0..disk.n_faces() {
        let c = disk.face(FaceId::from_idx(f));
        // The corners in order with the points inserted into boundary edges after their tails.
        let mut ring: Vec<u32> = Vec::with_capacity(3);
        let mut split = Vec::new();
        for (k, ck) in c.iter().enumerate() {
            ring.push(ck.0);
            // The half-edge from corner k to corner k + 1; on the boundary when it has no twin.
            let h = HalfedgeId::of(FaceId::from_idx(f), k);
            if disk.twin(h).is_none()
                && let Some(ids) = inserted.get(ck)
            {
                ring.extend_from_slice(ids);
                split.push(k);
            }
        }
        if split.is_empty() {
            tris.push(c.map(|v| v.0));
            continue;
        }
        // One split edge: fan from the opposite corner (inside the refined polygon, which is
        // convex). More: every corner is on the circle, so the polygon is convex.
        let apex_corner = if split.len() == 1 { c[(split[0] + 2) % 3].0 } else { c[0].0 };
        let s = ring.iter().position(|&x| x == apex_corner).ok_or_else(|| Error::Internal("fan apex".into()))?;
        ring.rotate_left(s);
        for j in 1..ring.len() - 1 {
            tris.push([ring[0], ring[j], ring[j + 1]]);
        }
    }
    let mesh = Mesh::from_triangles(pos, &tris).map_err(|e| Error::Numerical(format!("refined feature disk: {e}")))?;
    Ok(RefinedDisk { mesh, uv, key })
}

/// The meta-mesh of the two sides of a feature job (`source` and `target` are the surfaces the
/// cut disks copy).
///
/// # Errors
/// `Numerical` when a refined disk is not a valid mesh or a piece cannot be placed.
pub fn feature_meta_mesh(s: &FeatureSide, t: &FeatureSide, source: &Mesh, target: &Mesh) -> Result<MetaMeshResult> {
    let (ws, wt) = (walk(s, VKey::S), walk(t, VKey::T));
    // Shared points: boundary points at one angle, and exactly coincident interior points.
    let mut same: Vec<(VKey, VKey)> = Vec::new();
    let mut wt_rest = Vec::with_capacity(wt.len());
    for &x in &wt {
        match same_point(&ws, x.0) {
            Some(i) => same.push((x.1, ws[i].1)),
            None => wt_rest.push(x),
        }
    }
    let ws_rest: Vec<_> = ws.iter().copied().filter(|x| same_point(&wt, x.0).is_none()).collect();
    let bits = |p: Uv| (p[0].to_bits(), p[1].to_bits());
    let at: HashMap<(u64, u64), u32> =
        t.domain.uv.iter().enumerate().map(|(v, &p)| (bits(p), t.cut.disk.orig[v].0)).collect();
    for (v, &p) in s.domain.uv.iter().enumerate() {
        if let Some(&tv) = at.get(&bits(p)) {
            same.push((VKey::T(tv), VKey::S(s.cut.disk.orig[v].0)));
        }
    }
    same.sort();
    same.dedup();
    let (rs, rt) = (refine(s, VKey::S, &ws, &wt_rest)?, refine(t, VKey::T, &wt, &ws_rest)?);
    overlay(&OverlayInput {
        source: OverlayDisk { mesh: &rs.mesh, uv: &rs.uv, key: rs.key },
        target: OverlayDisk { mesh: &rt.mesh, uv: &rt.uv, key: rt.key },
        source_surface: source,
        target_surface: target,
        same,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::homology::feature_map::feature_map;
    use crate::mesh::shapes;

    /// Two unit squares of different resolution (boundary loop only, fixed by a corner anchor):
    /// their circle domains have different boundary polygons. The meta-mesh is a manifold disk
    /// with one face list, every input vertex among its vertices, and every vertex on both
    /// squares (z = 0, inside the unit square).
    #[test]
    fn squares_of_different_resolution_overlay_into_one_disk() {
        let (a, b) = (shapes::grid(5), shapes::grid(7));
        let r = feature_map(&a, &b, &[], &[], &[(VertexId(0), VertexId(0))], &Default::default()).unwrap();
        let m = feature_meta_mesh(&r.source, &r.target, &a, &b).unwrap();
        let (ms, mt) = m.meshes().unwrap();
        assert_eq!(ms.faces(), mt.faces());
        assert_eq!(crate::topology::euler_characteristic(&ms), 1);
        assert_eq!(crate::topology::boundary_loops(&ms).len(), 1);
        assert!(ms.n_vertices() >= a.n_vertices() + b.n_vertices() - 4, "{} vertices", ms.n_vertices());
        for p in ms.positions().iter().chain(mt.positions()) {
            assert!(
                p.z.abs() < 1e-15 && (-1e-12..=1.0 + 1e-12).contains(&p.x) && (-1e-12..=1.0 + 1e-12).contains(&p.y)
            );
        }
        // The two embeddings of the flat square agree up to the map: same total area.
        assert!((ms.area() - mt.area()).abs() < 1e-9, "{} vs {}", ms.area(), mt.area());
    }

    #[test]
    fn the_base_is_the_same_point_at_zero_and_at_a_full_turn() {
        let w = vec![(0.0, VKey::S(0), [1.0, 0.0]), (1.0, VKey::S(1), [0.5, 0.8])];
        assert_eq!(same_point(&w, 1.0 + 1e-13), Some(1));
        assert_eq!(same_point(&w, std::f64::consts::TAU - 1e-13), Some(0));
        assert_eq!(same_point(&w, 0.5), None);
    }
}
