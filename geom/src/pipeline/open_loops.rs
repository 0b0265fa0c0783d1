//! `voronoi` and `greedy` on surfaces with boundary loops. Each loop is closed by a cone on
//! both meshes ([`crate::mesh::cap`]); loops pair up through the anchors on them (or the job's
//! `boundaries` rows, or, for a loop with neither, the anchor nearest to it); each pair of loops
//! gets at least three corresponding loop anchors (the job's, then added ones at equal
//! arc-length fractions between them) and the cone's apex as one more anchor. The layout then
//! runs on the closed meshes with the loops' segments and the cones' spokes as fixed paths
//! ([`crate::domain::loops`]), so every patch map takes loop onto loop and cone onto cone, and
//! the maps restrict to the open meshes ([`Capped::restrict_map`]).

use crate::crossparam::SideFractions;
use crate::domain::loops::{LoopAnchors, loop_paths};
use crate::domain::refine::Refined;
use crate::domain::tracer::Tracer;
use crate::error::{InputError, Result};
use crate::homology::curve_align::{CurveAlignOptions, angle_sums, warp};
use crate::map::SurfaceMap;
use crate::mesh::cap::{CapLoop, Capped, cap_loops};
use crate::mesh::{Mesh, VertexId};
use serde::Serialize;

/// Weight below which a loop vertex's image counts as on the loop edge.
const ON_LOOP: f64 = 1e-6;

/// A boundary loop named by its first vertex and its length in vertices.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LoopName {
    pub first_vertex: u32,
    pub vertices: usize,
}

/// How one pair of loops was mapped (`metrics.json`, `boundaries`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoundaryReport {
    pub source_loop: LoopName,
    pub target_loop: LoopName,
    /// `anchors` (the job's anchors on the loop), `boundaries` (a `boundaries` row) or
    /// `nearest_anchor` (the loop had neither).
    pub paired_by: &'static str,
    /// The job's anchors on the loop (indices into its anchor list).
    pub anchors: Vec<usize>,
    /// Loop anchors added at equal arc-length fractions between the given ones.
    pub added: usize,
    /// Loop vertices whose image is not on the other mesh's loop, both ways (0 when done).
    pub off_loop: [usize; 2],
}

/// The closed meshes of a job on open meshes, with every anchor the layout needs.
pub struct OpenPlan {
    pub source: Capped,
    pub target: Capped,
    /// Anchors on the closed meshes: the job's, then the added loop anchors, then the apexes.
    pub sa: Vec<VertexId>,
    pub ta: Vec<VertexId>,
    /// Anchors held through relaxation on the open meshes (all but the apexes).
    pub held: usize,
    s_loops: Vec<LoopAnchors>,
    t_loops: Vec<LoopAnchors>,
    /// Interior angle at each vertex of the open meshes (the loops' turning, for alignment).
    angles: [Vec<f64>; 2],
    report: Vec<BoundaryReport>,
}

fn name(l: &CapLoop) -> LoopName {
    LoopName { first_vertex: l.vertices[0].0, vertices: l.vertices.len() }
}

fn names(c: &Capped) -> Vec<LoopName> {
    c.loops.iter().map(name).collect()
}

/// Equal boundary-loop counts, or `InputError::TopologyMismatch` naming each mesh's loops
/// (first vertex and length).
///
/// # Errors
/// As above.
pub fn check_loop_counts(source: &Mesh, target: &Mesh) -> Result<()> {
    let (ls, lt) = (crate::topology::boundary_loops(source), crate::topology::boundary_loops(target));
    if ls.len() == lt.len() {
        return Ok(());
    }
    let names = |m: &Mesh, l: &[Vec<crate::mesh::HalfedgeId>]| -> Vec<LoopName> {
        l.iter().map(|hs| LoopName { first_vertex: m.tail(hs[0]).0, vertices: hs.len() }).collect()
    };
    Err(InputError::TopologyMismatch(format!(
        "the source has {} boundary loops {:?}, the target {} {:?}: loops map one to one",
        ls.len(),
        names(source, &ls),
        lt.len(),
        names(target, &lt)
    ))
    .into())
}

/// Per vertex of the open mesh: the loop it lies on.
fn loop_of(c: &Capped) -> Vec<Option<usize>> {
    let mut out = vec![None; c.open_vertices];
    for (i, l) in c.loops.iter().enumerate() {
        for v in &l.vertices {
            out[v.idx()] = Some(i);
        }
    }
    out
}

/// One correspondence on a pair of loops: positions in each loop's vertex list, and the job's
/// anchor it came from.
#[derive(Debug, Clone, Copy)]
struct Corr {
    s: usize,
    t: usize,
    anchor: Option<usize>,
}

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

impl OpenPlan {
    /// Pairs the loops and chooses the loop anchors.
    ///
    /// # Errors
    /// `InputError::TopologyMismatch` naming the loops when their counts differ or a loop is
    /// pinched; `InputError::Anchors` when anchors on loops do not pair them consistently, run
    /// in another order on the target, or a loop is too short for its anchors.
    pub fn new(
        source: &Mesh,
        target: &Mesh,
        pairs: &[(VertexId, VertexId)],
        boundaries: &[(VertexId, VertexId)],
    ) -> Result<OpenPlan> {
        let (cs, ct) = (cap_loops(source)?, cap_loops(target)?);
        if cs.loops.len() != ct.loops.len() {
            return Err(InputError::TopologyMismatch(format!(
                "the source has {} boundary loops {:?}, the target {} {:?}: loops map one to one",
                cs.loops.len(),
                names(&cs),
                ct.loops.len(),
                names(&ct)
            ))
            .into());
        }
        let (ls, lt) = (loop_of(&cs), loop_of(&ct));
        let nl = cs.loops.len();
        let mut partner: Vec<Option<(usize, &'static str)>> = vec![None; nl];
        let mut corr: Vec<Vec<Corr>> = vec![Vec::new(); nl];
        let rows = pairs.iter().map(|&p| (p, true)).chain(boundaries.iter().map(|&p| (p, false)));
        for (k, ((s, t), is_anchor)) in rows.enumerate() {
            let what = if is_anchor { format!("anchor {k}") } else { format!("boundaries row {}", k - pairs.len()) };
            let (i, j) = match (ls.get(s.idx()).copied().flatten(), lt.get(t.idx()).copied().flatten()) {
                (Some(i), Some(j)) => (i, j),
                (None, None) if is_anchor => continue,
                (a, b) => {
                    return Err(InputError::Anchors(format!(
                        "{what}: source vertex {} is {} a boundary loop, target vertex {} is {}: a vertex on a loop maps to a vertex on a loop",
                        s.0,
                        if a.is_some() { "on" } else { "not on" },
                        t.0,
                        if b.is_some() { "on" } else { "not on" }
                    ))
                    .into());
                }
            };
            let by = if is_anchor { "anchors" } else { "boundaries" };
            match partner[i] {
                Some((j2, _)) if j2 != j => {
                    return Err(InputError::Anchors(format!(
                        "{what} pairs source loop {:?} with target loop {:?}, an earlier row with {:?}",
                        name(&cs.loops[i]),
                        name(&ct.loops[j]),
                        name(&ct.loops[j2])
                    ))
                    .into());
                }
                Some(_) => {}
                None => partner[i] = Some((j, by)),
            }
            let pos = |l: &CapLoop, v: VertexId| l.vertices.iter().position(|&x| x == v).unwrap_or(0);
            corr[i].push(Corr { s: pos(&cs.loops[i], s), t: pos(&ct.loops[j], t), anchor: is_anchor.then_some(k) });
        }
        pair_by_nearest_anchor(source, target, &cs, &ct, pairs, &mut partner, &mut corr)?;
        let mut taken = vec![false; nl];
        for (i, p) in partner.iter().enumerate() {
            let (j, _) = p.expect("every loop paired");
            if std::mem::replace(&mut taken[j], true) {
                return Err(InputError::Anchors(format!(
                    "two source loops pair with target loop {:?} (source loop {:?} is one): list each loop once in boundaries",
                    name(&ct.loops[j]),
                    name(&cs.loops[i])
                ))
                .into());
            }
        }
        Self::with_loop_anchors(source, target, cs, ct, pairs, &partner, corr)
    }

    /// Orders each loop's correspondences, checks their order on the target, adds loop anchors
    /// up to three per loop, and numbers every anchor of the closed meshes.
    fn with_loop_anchors(
        source: &Mesh,
        target: &Mesh,
        cs: Capped,
        ct: Capped,
        pairs: &[(VertexId, VertexId)],
        partner: &[Option<(usize, &'static str)>],
        mut corr: Vec<Vec<Corr>>,
    ) -> Result<OpenPlan> {
        let mut sa: Vec<VertexId> = pairs.iter().map(|p| p.0).collect();
        let mut ta: Vec<VertexId> = pairs.iter().map(|p| p.1).collect();
        let mut loop_anchor_ids: Vec<Vec<u32>> = Vec::new();
        let mut report = Vec::new();
        for (i, c) in corr.iter_mut().enumerate() {
            let (j, by) = partner[i].expect("paired");
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
        let held = sa.len();
        let (mut s_loops, mut t_loops) = (Vec::new(), Vec::new());
        for (i, ids) in loop_anchor_ids.into_iter().enumerate() {
            let (j, _) = partner[i].expect("paired");
            let apex = sa.len() as u32;
            sa.push(cs.loops[i].apex);
            ta.push(ct.loops[j].apex);
            s_loops.push(LoopAnchors { apex, anchors: ids.clone(), vertices: cs.loops[i].vertices.clone() });
            t_loops.push(LoopAnchors { apex, anchors: ids, vertices: ct.loops[j].vertices.clone() });
        }
        let angles = [angle_sums(source), angle_sums(target)];
        Ok(OpenPlan { source: cs, target: ct, sa, ta, held, s_loops, t_loops, angles, report })
    }

    /// Gives both tracers (on the closed meshes) the loops' fixed paths and closes the cones.
    ///
    /// # Errors
    /// `Error::Internal` if a fixed path cannot be placed.
    pub fn fix(&self, st: &mut Tracer, tt: &mut Tracer) -> Result<()> {
        let ps = loop_paths(st.graph(), st.anchors(), &self.s_loops)?;
        st.fix(ps, &self.source.cap_faces())?;
        let pt = loop_paths(tt.graph(), tt.anchors(), &self.t_loops)?;
        tt.fix(pt, &self.target.cap_faces())?;
        Ok(())
    }

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

    /// The maps of the closed meshes restricted to the open ones (source → target, target →
    /// source).
    ///
    /// # Errors
    /// `Error::Numerical` when a vertex of an open mesh maps inside a cone.
    pub fn restrict(&self, s2t: &SurfaceMap, t2s: &SurfaceMap) -> Result<(SurfaceMap, SurfaceMap)> {
        let (on_s, on_t) = (on_loops(&self.source), on_loops(&self.target));
        let a = self.target.restrict_map(s2t, self.source.open_vertices, &on_s, ON_LOOP)?;
        let b = self.source.restrict_map(t2s, self.target.open_vertices, &on_t, ON_LOOP)?;
        Ok((a, b))
    }

    /// The report per loop pair, with the loop vertices whose image (maps between the open
    /// meshes) is not on the partner loop counted, both ways.
    pub fn report(&self, s2t: &SurfaceMap, t2s: &SurfaceMap) -> Vec<BoundaryReport> {
        let off = |m: &SurfaceMap, to: &Capped, loops: &[LoopAnchors]| -> Vec<usize> {
            loops
                .iter()
                .map(|l| l.vertices.iter().filter(|v| !to.on_loop_edge(m.face[v.idx()], m.bary[v.idx()])).count())
                .collect()
        };
        let (os, ot) = (off(s2t, &self.target, &self.s_loops), off(t2s, &self.source, &self.t_loops));
        let mut out = self.report.clone();
        for (i, r) in out.iter_mut().enumerate() {
            r.off_loop = [os[i], ot[i]];
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

/// Per vertex of the open mesh: is it on a loop?
fn on_loops(c: &Capped) -> Vec<bool> {
    let mut f = vec![false; c.open_vertices];
    for l in &c.loops {
        for v in &l.vertices {
            f[v.idx()] = true;
        }
    }
    f
}

/// Every source loop pairs with one target loop; loops that no anchor or `boundaries` row
/// paired go with the job's anchor nearest to them: the source loop's vertex nearest that
/// anchor corresponds to the target loop's vertex nearest its partner, on the target loop
/// nearest the partner.
fn pair_by_nearest_anchor(
    source: &Mesh,
    target: &Mesh,
    cs: &Capped,
    ct: &Capped,
    pairs: &[(VertexId, VertexId)],
    partner: &mut [Option<(usize, &'static str)>],
    corr: &mut [Vec<Corr>],
) -> Result<()> {
    let nearest = |m: &Mesh, vs: &[VertexId], p: crate::mesh::P3| -> (usize, f64) {
        vs.iter()
            .enumerate()
            .map(|(k, v)| (k, (m.position(*v) - p).norm()))
            .min_by(|a, b| a.1.total_cmp(&b.1))
            .unwrap_or((0, f64::INFINITY))
    };
    for i in 0..partner.len() {
        if partner[i].is_some() {
            continue;
        }
        let sl = &cs.loops[i].vertices;
        let Some((k, (s_pos, _))) = pairs
            .iter()
            .enumerate()
            .map(|(k, p)| (k, nearest(source, sl, source.position(p.0))))
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
        else {
            return Err(InputError::Anchors(format!(
                "source boundary loop {:?} has no anchor to pair it: list it in boundaries",
                name(&cs.loops[i])
            ))
            .into());
        };
        let t = target.position(pairs[k].1);
        let used: Vec<usize> = partner.iter().flatten().map(|p| p.0).collect();
        let Some((j, (t_pos, _))) = (0..ct.loops.len())
            .filter(|j| !used.contains(j))
            .map(|j| (j, nearest(target, &ct.loops[j].vertices, t)))
            .min_by(|a, b| a.1.1.total_cmp(&b.1.1))
        else {
            return Err(InputError::Anchors(format!(
                "source boundary loop {:?} has no free target loop to pair with: list it in boundaries",
                name(&cs.loops[i])
            ))
            .into());
        };
        partner[i] = Some((j, "nearest_anchor"));
        corr[i].push(Corr { s: s_pos, t: t_pos, anchor: None });
    }
    Ok(())
}

/// The correspondences of a loop pair, in source loop order, must run in loop order on the
/// target too (one turn, the same way round).
fn check_order(c: &[Corr], sl: &CapLoop, tl: &CapLoop) -> Result<()> {
    let n = c.len();
    let mut ts: Vec<usize> = c.iter().map(|x| x.t).collect();
    ts.sort_unstable();
    ts.dedup();
    if ts.len() < n {
        return Err(InputError::Anchors(format!(
            "two rows on source boundary loop {:?} name one vertex of target loop {:?}",
            name(sl),
            name(tl)
        ))
        .into());
    }
    if n < 3 {
        return Ok(());
    }
    let descents = (0..n).filter(|&k| c[(k + 1) % n].t < c[k].t).count();
    if descents != 1 {
        let who: Vec<String> = c
            .iter()
            .map(|x| {
                x.anchor
                    .map_or_else(|| format!("row at source vertex {}", sl.vertices[x.s].0), |a| format!("anchor {a}"))
            })
            .collect();
        return Err(InputError::Anchors(format!(
            "the anchors on source boundary loop {:?} ({}) run in another order along target loop {:?}",
            name(sl),
            who.join(", "),
            name(tl)
        ))
        .into());
    }
    Ok(())
}
