//! Loop anchors: each pair of loops gets its correspondences in loop order (checked on the
//! target), at least three of them (more added at equal arc-length fractions of the longest
//! gap), and every anchor of the closed meshes its number: the job's, the added ones, the apexes.

use super::pairing::{Corr, check_order};
use super::plan::{BoundaryReport, OpenPlan, name};
use crate::domain::loops::LoopAnchors;
use crate::error::{InputError, Result};
use crate::homology::curve_align::angle_sums;
use crate::mesh::cap::Capped;
use crate::mesh::{Mesh, VertexId};

/// Cumulative arc length along a loop, from its first vertex (`n + 1` entries).
fn arc(m: &Mesh, vs: &[VertexId]) -> Vec<f64> {
    let mut out = vec![0.0];
    for i in 0..vs.len() {
        let d = (m.position(vs[(i + 1) % vs.len()]) - m.position(vs[i])).norm();
        out.push(out[i] + d);
    }
    out
}

/// Arc length from position `p` forward to `q` (the whole loop when equal).
fn gap_len(arc: &[f64], p: usize, q: usize) -> f64 {
    let total = arc[arc.len() - 1];
    let d = arc[q] - arc[p];
    if q > p { d } else { d + total }
}

/// The position strictly inside the gap `p -> q` nearest to arc length `at` past `p`.
fn inside_at(arc: &[f64], p: usize, q: usize, at: f64) -> Option<usize> {
    let n = arc.len() - 1;
    let steps = match (q + n - p) % n {
        0 => n,
        s => s,
    };
    (1..steps)
        .map(|s| (p + s) % n)
        .min_by(|&x, &y| (gap_len(arc, p, x) - at).abs().total_cmp(&(gap_len(arc, p, y) - at).abs()))
}

/// Orders each loop's correspondences, checks their order on the target, adds loop anchors
/// up to three per loop, and numbers every anchor of the closed meshes.
pub(super) fn with_loop_anchors(
    source: &Mesh,
    target: &Mesh,
    (cs, ct): (Capped, Capped),
    pairs: &[(VertexId, VertexId)],
    partner: &[(usize, &'static str)],
    mut corr: Vec<Vec<Corr>>,
) -> Result<OpenPlan> {
    let mut sa: Vec<VertexId> = pairs.iter().map(|p| p.0).collect();
    let mut ta: Vec<VertexId> = pairs.iter().map(|p| p.1).collect();
    let mut loop_anchor_ids: Vec<Vec<u32>> = Vec::new();
    let mut report = Vec::new();
    for (i, c) in corr.iter_mut().enumerate() {
        let (j, by) = partner[i];
        let (sl, tl) = (&cs.loops[i].vertices, &ct.loops[j].vertices);
        c.sort_by_key(|x| x.s);
        c.dedup_by_key(|x| x.s);
        check_order(c, &cs.loops[i], &ct.loops[j])?;
        let (arc_s, arc_t) = (arc(source, sl), arc(target, tl));
        while c.len() < 3 {
            // Split the longest gap (source arc length) into as many parts as anchors are
            // missing plus one.
            let g = (0..c.len())
                .max_by(|&x, &y| {
                    let l = |k: usize| gap_len(&arc_s, c[k].s, c[(k + 1) % c.len()].s);
                    l(x).total_cmp(&l(y))
                })
                .unwrap_or(0);
            let (p, q) = (c[g], c[(g + 1) % c.len()]);
            let parts = 4 - c.len();
            let mut added = Vec::new();
            for k in 1..parts {
                let f = k as f64 / parts as f64;
                let s = inside_at(&arc_s, p.s, q.s, f * gap_len(&arc_s, p.s, q.s));
                let t = inside_at(&arc_t, p.t, q.t, f * gap_len(&arc_t, p.t, q.t));
                match (s, t) {
                    (Some(s), Some(t)) if !added.iter().any(|x: &Corr| x.s == s || x.t == t) => {
                        added.push(Corr { s, t, anchor: None });
                    }
                    _ => {
                        return Err(InputError::Anchors(format!(
                            "boundary loops {:?} (source) and {:?} (target) are too short for three loop anchors",
                            name(&cs.loops[i]),
                            name(&ct.loops[j])
                        ))
                        .into());
                    }
                }
            }
            c.extend(added);
            c.sort_by_key(|x| x.s);
        }
        let mut ids = Vec::with_capacity(c.len());
        for x in c.iter() {
            match x.anchor {
                Some(k) => ids.push(k as u32),
                None => {
                    ids.push(sa.len() as u32);
                    sa.push(sl[x.s]);
                    ta.push(tl[x.t]);
                }
            }
        }
        loop_anchor_ids.push(ids);
        report.push(BoundaryReport {
            source_loop: name(&cs.loops[i]),
            target_loop: name(&ct.loops[j]),
            paired_by: by,
            anchors: c.iter().filter_map(|x| x.anchor).collect(),
            added: c.iter().filter(|x| x.anchor.is_none()).count(),
            off_loop: [0, 0],
        });
    }
    let (mut s_loops, mut t_loops) = (Vec::new(), Vec::new());
    for (i, ids) in loop_anchor_ids.into_iter().enumerate() {
        let (j, _) = partner[i];
        let apex = sa.len() as u32;
        sa.push(cs.loops[i].apex);
        ta.push(ct.loops[j].apex);
        s_loops.push(LoopAnchors { apex, anchors: ids.clone(), vertices: cs.loops[i].vertices.clone() });
        t_loops.push(LoopAnchors { apex, anchors: ids, vertices: ct.loops[j].vertices.clone() });
    }
    let angles = [angle_sums(source), angle_sums(target)];
    let job_anchors = pairs.len();
    Ok(OpenPlan { source: cs, target: ct, sa, ta, job_anchors, s_loops, t_loops, angles, report })
}
