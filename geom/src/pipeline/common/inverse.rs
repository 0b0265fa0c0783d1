//! A folded direction replaced by the inverse of the other, fold-free one. A fold-free map
//! `S -> T` whose image covers `T` is a bijection between the surfaces, so its inverse is a
//! fold-free `T -> S`: every target vertex is located on the source re-embedded on the target
//! (the image mesh, the source's faces at their mapped positions) by closest point, and its
//! barycentric coordinates in that image face are read on the same source face. Anchors are
//! placed exactly, the inverse is relaxed like any direction, and it replaces the folded
//! direction only if the evaluator then counts no flipped face. The two directions of the
//! pipelines are computed apart and fold in different places (a limb that slides past an
//! anchor one way is mapped cleanly the other way).

use super::relax::{Direction, FinishedPair, finish_direction};
use super::{VISIBLE, on_surface};
use crate::crossparam::compose::place_anchors;
use crate::crossparam::smooth::SmoothReport;
use crate::error::Result;
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, VertexId};
use crate::pipeline::spec::RelaxOptions;
use crate::progress::Progress;

/// The two meshes of a pair with their anchors, one row per anchor (source, target).
pub struct InversePair<'a> {
    pub source: &'a Mesh,
    pub target: &'a Mesh,
    pub pairs: &'a [(VertexId, VertexId)],
}

impl InversePair<'_> {
    /// `(s2t, t2s)` with a folded direction replaced by the other's relaxed inverse when that is
    /// fold-free and on the surface; also which direction was replaced (`"source_to_target"` or
    /// `"target_to_source"`), if any.
    ///
    /// # Errors
    /// `Cancelled`; what the relaxation reports.
    pub fn repair(
        &self,
        (s2t, t2s): (Direction, Direction),
        o: &RelaxOptions,
        progress: &mut dyn Progress,
    ) -> Result<((Direction, Direction), Option<&'static str>)> {
        let (f1, f2) = (s2t.3.flipped_faces, t2s.3.flipped_faces);
        let rev: Vec<(VertexId, VertexId)> = self.pairs.iter().map(|&(s, t)| (t, s)).collect();
        if f1 > 0 && f2 == 0 {
            if let Some(d) = self.inverse_of(self.target, self.source, &t2s, &rev, o, progress)? {
                return Ok(((d, t2s), Some("source_to_target")));
            }
        } else if f2 > 0
            && f1 == 0
            && let Some(d) = self.inverse_of(self.source, self.target, &s2t, self.pairs, o, progress)?
        {
            return Ok(((s2t, d), Some("target_to_source")));
        }
        Ok(((s2t, t2s), None))
    }

    /// [`InversePair::repair`] on a one-patch method's finished pair (its relaxation report
    /// stays that of the maps it started from).
    ///
    /// # Errors
    /// As [`InversePair::repair`].
    pub fn repair_finished(
        &self,
        f: FinishedPair,
        o: &RelaxOptions,
        progress: &mut dyn Progress,
    ) -> Result<(FinishedPair, Option<&'static str>)> {
        let smoothing = f.smoothing;
        let d1 = (f.s2t, SmoothReport::default(), f.on_target, f.m1);
        let d2 = (f.t2s, SmoothReport::default(), f.on_source, f.m2);
        let ((a, b), inverted) = self.repair((d1, d2), o, progress)?;
        let f = FinishedPair { s2t: a.0, t2s: b.0, on_target: a.2, on_source: b.2, m1: a.3, m2: b.3, smoothing };
        Ok((f, inverted))
    }

    /// The relaxed inverse of `d` (a direction `from -> to`) as a direction `to -> from`, if the
    /// evaluator counts no flipped face on it. `anchors` are the rows `(from, to)` of `d`.
    fn inverse_of(
        &self,
        from: &Mesh,
        to: &Mesh,
        d: &Direction,
        anchors: &[(VertexId, VertexId)],
        o: &RelaxOptions,
        progress: &mut dyn Progress,
    ) -> Result<Option<Direction>> {
        progress.check()?;
        let mut inv = invert(to, &d.2)?;
        let rows: Vec<(VertexId, VertexId)> = anchors.iter().map(|&(f, t)| (t, f)).collect();
        place_anchors(&mut inv, from, &rows);
        let fixed: Vec<VertexId> = rows.iter().map(|r| r.0).collect();
        let out = finish_direction(to, from, inv, &fixed, &rows, o, progress, &mut || {})?;
        let m = &out.3;
        tracing::debug!(flipped = m.flipped_faces, off = m.off_surface_max, "inverse of the fold-free direction");
        // Every image must also lie on the surface as the evaluator finds it (a hidden image,
        // one the evaluator's nearest faces miss, is as wrong as a fold).
        Ok((m.flipped_faces == 0 && on_surface(m, from, VISIBLE)).then_some(out))
    }
}

/// The inverse of a map given by its image mesh `image` (the map's source faces at their
/// positions on `to`): each vertex of `to` at its closest point on `image`, as a map onto the
/// map's source (same faces as `image`).
///
/// # Errors
/// `Internal` if the point locator cannot be built.
pub fn invert(to: &Mesh, image: &Mesh) -> Result<SurfaceMap> {
    SurfaceMap::from_positions(to.positions(), image, None)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::metrics::{MetricsOptions, evaluate_map};

    /// A sphere mapped onto its own midpoint subdivision (vertex `i` to vertex `i`, which lies on
    /// the same flat faces): the inverse places every fine vertex at its own position on the
    /// coarse sphere, and neither direction folds.
    #[test]
    fn the_inverse_of_a_map_onto_a_refinement_recovers_the_refinement() {
        let coarse = shapes::icosphere(2);
        let fine = shapes::subdivide(&coarse, 1);
        let n = coarse.n_vertices();
        assert!(fine.n_vertices() > n);
        let rows: Vec<(VertexId, VertexId)> = (0..n).map(|v| (VertexId::from_idx(v), VertexId::from_idx(v))).collect();
        let mut map = SurfaceMap::identity(&coarse);
        place_anchors(&mut map, &fine, &rows);
        let image = map.embed(&coarse, &fine).unwrap();
        let inv = invert(&fine, &image).unwrap();
        let back = inv.embed(&fine, &coarse).unwrap();
        let worst = (0..fine.n_vertices())
            .map(|v| (back.position(VertexId::from_idx(v)) - fine.position(VertexId::from_idx(v))).norm())
            .fold(0.0, f64::max);
        assert!(worst <= 1e-12, "inverse off by {worst}");
        let o = MetricsOptions { samples: 1000, ..Default::default() };
        let m = evaluate_map(&fine, &coarse, &back, None, None, &o).unwrap();
        assert_eq!(m.flipped_faces, 0);
        assert!(m.off_surface_max <= 1e-12, "off the surface by {}", m.off_surface_max);
    }
}
