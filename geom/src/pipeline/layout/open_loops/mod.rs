//! `voronoi` and `greedy` on surfaces with boundary loops. Each loop is closed by a cone on
//! both meshes ([`crate::mesh::cap`]); loops pair up through the anchors on them (or the job's
//! `boundaries` rows, or, for a loop with neither, the anchor nearest to it); each pair of loops
//! gets at least three corresponding loop anchors (the job's, then added ones at equal
//! arc-length fractions between them) and the cone's apex as one more anchor. The layout then
//! runs on the closed meshes with the loops' segments and the cones' spokes as fixed paths
//! ([`crate::domain::loops`]), so every patch map takes loop onto loop and cone onto cone, and
//! the maps restrict to the open meshes ([`Capped::restrict_map`]).

use crate::domain::loops::{LoopAnchors, loop_paths};
use crate::domain::tracer::Tracer;
use crate::error::{InputError, Result};
use crate::map::SurfaceMap;
use crate::mesh::cap::{CapLoop, Capped, cap_loops};
use crate::mesh::{Mesh, VertexId};
use pairing::{Corr, loop_of, pair_by_nearest_anchor};

mod anchors;
mod pairing;
mod plan;
mod sides;

use plan::name;
pub use plan::{BoundaryReport, LoopName, OpenPlan};

/// Weight below which a loop vertex's image counts as on the loop edge.
const ON_LOOP: f64 = 1e-6;

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
        check_loop_counts(source, target)?;
        let (cs, ct) = (cap_loops(source)?, cap_loops(target)?);
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
        // Every loop has its partner now (the nearest-anchor pass fails otherwise).
        let partner: Vec<(usize, &'static str)> = partner.into_iter().flatten().collect();
        if partner.len() != nl {
            return Err(crate::Error::Internal("a boundary loop was left unpaired".into()));
        }
        let mut taken = vec![false; nl];
        for (i, &(j, _)) in partner.iter().enumerate() {
            if std::mem::replace(&mut taken[j], true) {
                return Err(InputError::Anchors(format!(
                    "two source loops pair with target loop {:?} (source loop {:?} is one): list each loop once in boundaries",
                    name(&ct.loops[j]),
                    name(&cs.loops[i])
                ))
                .into());
            }
        }
        anchors::with_loop_anchors(source, target, (cs, ct), pairs, &partner, corr)
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

    /// The maps of the closed meshes restricted to the open ones (source → target, target →
    /// source).
    ///
    /// # Errors
    /// `Error::Numerical` when a vertex of an open mesh maps inside a cone.
    pub fn restrict(&self, s2t: &SurfaceMap, t2s: &SurfaceMap) -> Result<(SurfaceMap, SurfaceMap)> {
        let (on_s, on_t) = (on_loops(&self.source), on_loops(&self.target));
        let (face, bary) =
            self.target.restrict_map((&s2t.face, &s2t.bary), self.source.open_vertices, &on_s, ON_LOOP)?;
        let a = SurfaceMap { face, bary };
        let (face, bary) =
            self.source.restrict_map((&t2s.face, &t2s.bary), self.target.open_vertices, &on_t, ON_LOOP)?;
        let b = SurfaceMap { face, bary };
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
