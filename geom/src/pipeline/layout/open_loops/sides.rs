//! The target's loop sides aligned with the source's for the patch maps.

use super::plan::OpenPlan;
use crate::crossparam::SideFractions;
use crate::domain::loops::LoopAnchors;
use crate::domain::refine::Refined;
use crate::homology::curve_align::{CurveAlignOptions, warp};
use crate::mesh::{Mesh, VertexId};

impl OpenPlan {
    /// Where the target's loop vertices sit along their layout paths: each loop segment's
    /// vertices aligned with the source's by dynamic time warping of arc length and turning
    /// ([`crate::homology::curve_align`]), so that a zigzag boundary's tips land on tips and no
    /// triangle with three corners on the loop folds; refined vertices between them by arc
    /// length. `rt` is the target's refinement along its layout, whose paths start with the
    /// loops' fixed ones (each loop's segments, then its spokes).
    pub fn target_sides(&self, rt: &Refined) -> SideFractions {
        let mut out: SideFractions = vec![None; rt.mesh.n_vertices()];
        let mut path = 0;
        for (sl, tl) in self.s_loops.iter().zip(&self.t_loops) {
            let k = sl.anchors.len();
            for i in 0..k {
                let s = segment(&self.source.mesh, sl, &self.sa, i, &self.angles[0]);
                let t = segment(&self.target.mesh, tl, &self.ta, i, &self.angles[1]);
                let mut w = warp(&s.0, &s.1, &t.0, &t.1, &CurveAlignOptions::default())
                    .unwrap_or_else(|| t.0[..t.0.len() - 1].to_vec());
                w.push(1.0);
                // Knots: the target's arc length at each loop vertex, and its aligned fraction.
                let total = t.2;
                let pv = &rt.path_vertices[path + i];
                let mut at = 0.0;
                for j in 1..pv.len().saturating_sub(1) {
                    at += (rt.mesh.position(pv[j]) - rt.mesh.position(pv[j - 1])).norm();
                    let x = at / total.max(f64::MIN_POSITIVE);
                    let q = t.0.partition_point(|&f| f <= x).clamp(1, t.0.len() - 1);
                    let (f0, f1) = (t.0[q - 1], t.0[q]);
                    let u = if f1 > f0 { ((x - f0) / (f1 - f0)).clamp(0.0, 1.0) } else { 0.0 };
                    out[pv[j].idx()] = Some((sl.anchors[i], w[q - 1] + u * (w[q] - w[q - 1])));
                }
            }
            path += 2 * k;
        }
        out
    }
}

/// Loop segment `i` (from its `i`-th anchor to the next) of one mesh: the arc-length fraction
/// of each of its vertices (1 at the end), their interior angles, and its length.
fn segment(m: &Mesh, l: &LoopAnchors, anchors: &[VertexId], i: usize, angles: &[f64]) -> (Vec<f64>, Vec<f64>, f64) {
    let n = l.vertices.len();
    let k = l.anchors.len();
    let pos = |a: u32| l.vertices.iter().position(|&v| v == anchors[a as usize]).unwrap_or(0);
    let (from, to) = (pos(l.anchors[i]), pos(l.anchors[(i + 1) % k]));
    let steps = match (to + n - from) % n {
        0 => n,
        s => s,
    };
    let vs: Vec<VertexId> = (0..=steps).map(|s| l.vertices[(from + s) % n]).collect();
    let mut cum = vec![0.0];
    for w in vs.windows(2) {
        cum.push(cum[cum.len() - 1] + (m.position(w[1]) - m.position(w[0])).norm());
    }
    let total = cum[cum.len() - 1];
    let frac = cum.iter().map(|c| c / total.max(f64::MIN_POSITIVE)).collect();
    (frac, vs.iter().map(|v| angles[v.idx()]).collect(), total)
}
