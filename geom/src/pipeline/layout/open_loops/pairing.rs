//! Pairing the loops of two open meshes: through the anchors on them, `boundaries` rows, or
//! the anchor nearest a loop that has neither; the correspondences on a loop pair must run the
//! same way round on both.

use super::plan::name;
use crate::error::{InputError, Result};
use crate::mesh::cap::{CapLoop, Capped};
use crate::mesh::{Mesh, VertexId};

/// Per vertex of the open mesh: the loop it lies on.
pub(super) fn loop_of(c: &Capped) -> Vec<Option<usize>> {
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
pub(super) struct Corr {
    pub s: usize,
    pub t: usize,
    pub anchor: Option<usize>,
}

/// Every source loop pairs with one target loop; loops that no anchor or `boundaries` row
/// paired go with the job's anchor nearest to them: the source loop's vertex nearest that
/// anchor corresponds to the target loop's vertex nearest its partner, on the target loop
/// nearest the partner.
pub(super) fn pair_by_nearest_anchor(
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
pub(super) fn check_order(c: &[Corr], sl: &CapLoop, tl: &CapLoop) -> Result<()> {
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
