//! The Voronoi-cue layout of Kwok, Zhang, Wang: a source layout dual to the anchors'
//! approximate geodesic Voronoi diagram (5.1) and its consistent copy on the target
//! (5.2, Procedure 1).
//!
//! Source: one path per cut, traced inside the two clusters and forced through its cut by
//! blocking the nodes of the pair's other cuts and of any vertex where the two clusters only
//! touch at a point; several cuts give several linkages. Regions that are not triangles are
//! then split ([`super::complete`]).
//!
//! Target: the source's paths in the paper's group order — single linkages whose target
//! clusters share one cut (traced inside those two clusters), then single linkages between
//! clusters that share no cut, then multiple linkages, postponed while two linkages of one pair
//! would still leave an anchor through the same sector. Every path leaves and enters its anchors
//! in the sector that the source's rotation prescribes, so the rotation systems agree and the
//! target's regions are the source's.

use super::complete::complete;
use super::cuts::{Clusters, clusters_in};
use super::tracer::{Half, TraceRequest, Tracer};
use super::walks::walks;
use super::{LayoutOptions, LayoutPath, LayoutStats, Sector};
use crate::error::{InputError, Result};
use crate::geodesic::NodeId;
use crate::mesh::{Mesh, VertexId};
use crate::progress::Progress;

/// Nodes that a path through cut `keep` of the pair (i, j) may not use.
fn blocked_for_cut(t: &Tracer, cl: &Clusters, keep: usize) -> Vec<NodeId> {
    let mesh = t.mesh();
    let g = t.graph();
    let c = &cl.cuts[keep];
    let (i, j) = (c.i, c.j);
    let mut out = Vec::new();
    for (k, other) in cl.between(i, j) {
        if k == keep {
            continue;
        }
        for &e in &other.edges {
            for n in 0..g.edge_node_count(e) {
                out.push(g.edge_node(e, n));
            }
        }
        out.extend(other.vertices.iter().map(|&v| g.vertex_node(v)));
    }
    // Point contacts: vertices where the clusters touch without sharing an edge of this cut.
    let in_keep = |v: VertexId| c.vertices.binary_search(&v).is_ok();
    for &f in &cl.faces[i as usize] {
        for v in mesh.face(f) {
            if !in_keep(v) && mesh.vertex_faces(v).any(|g2| cl.label[g2.idx()] == j) {
                out.push(g.vertex_node(v));
            }
        }
    }
    out
}

fn anchor_dist(m: &Mesh, anchors: &[VertexId], a: u32, b: u32) -> f64 {
    (m.position(anchors[a as usize]) - m.position(anchors[b as usize])).norm()
}

/// Builds the source layout on `t` (which must hold no paths yet but its fixed ones).
///
/// # Errors
/// `InputError::LayoutConflict` when the layout cannot be completed; `Cancelled`.
pub fn source_layout(
    t: &mut Tracer,
    chi: i64,
    opts: &LayoutOptions,
    progress: &mut dyn Progress,
) -> Result<(Clusters, LayoutStats)> {
    let mesh = t.mesh();
    let anchors = t.anchors().to_vec();
    let cl = clusters_in(mesh, &anchors, t.open_faces().as_deref())?;
    let mut stats = LayoutStats { cuts: cl.cuts.len(), ..Default::default() };
    let mut order: Vec<usize> = (0..cl.cuts.len()).collect();
    let multi = |c: usize| cl.between(cl.cuts[c].i, cl.cuts[c].j).count() > 1;
    order.sort_by(|&x, &y| {
        let (cx, cy) = (&cl.cuts[x], &cl.cuts[y]);
        (multi(x), anchor_dist(mesh, &anchors, cx.i, cx.j))
            .partial_cmp(&(multi(y), anchor_dist(mesh, &anchors, cy.i, cy.j)))
            .unwrap_or(std::cmp::Ordering::Equal)
    });
    for (k, &ci) in order.iter().enumerate() {
        progress.check()?;
        progress.report(crate::progress::Stage::LayoutSource, 0.8 * k as f64 / order.len().max(1) as f64);
        let c = &cl.cuts[ci];
        // A cap's apex is linked by its fixed spokes only, and a pair a fixed path joins
        // already (along a boundary loop) gets no second path.
        if t.is_enclosed(c.i) || t.is_enclosed(c.j) || t.linked_by_fixed(c.i, c.j) {
            continue;
        }
        let mask = cl.mask(c.i, c.j);
        let blocked = blocked_for_cut(t, &cl, ci);
        let req = TraceRequest { a: c.i, b: c.j, faces: Some(&mask), blocked: &blocked, ..Default::default() };
        match t.trace_insert(&req)? {
            Some(_) => {
                if multi(ci) {
                    stats.multiple_linkages += 1;
                }
            }
            None => stats.failed_traces += 1,
        }
    }
    if tracing::enabled!(tracing::Level::DEBUG) {
        tracing::debug!("source cuts {} paths {} failed {}", cl.cuts.len(), t.paths().len(), stats.failed_traces);
        for c in &cl.cuts {
            tracing::debug!("  cut {}-{} edges {}", c.i, c.j, c.edges.len());
        }
    }
    link_isolated(t, &mut stats)?;
    let before = t.paths().len();
    complete(&mut [t], chi, opts.max_attempts, progress)?;
    stats.triangulation_paths = t.paths().len() - before;
    stats.paths = t.paths().len();
    Ok((cl, stats))
}

/// Links anchors that no cut path reached to their nearest reachable anchor.
fn link_isolated(t: &mut Tracer, stats: &mut LayoutStats) -> Result<()> {
    let na = t.anchors().len() as u32;
    for a in 0..na {
        if !t.rotation(a).is_empty() {
            continue;
        }
        let anchors = t.anchors().to_vec();
        let mut others: Vec<u32> = (0..na).filter(|&b| b != a).collect();
        others
            .sort_by(|&x, &y| anchor_dist(t.mesh(), &anchors, a, x).total_cmp(&anchor_dist(t.mesh(), &anchors, a, y)));
        for b in others {
            if t.trace_insert(&TraceRequest { a, b, ..Default::default() })?.is_some() {
                stats.triangulation_paths += 1;
                break;
            }
        }
    }
    Ok(())
}

/// The sector at anchor `x` for the source half `hs` (leaving `x`), given which source paths
/// already exist on the target (`tid`), or `None` when `x` has no paths on the target yet.
fn target_sector(src: &Tracer, tgt: &Tracer, tid: &[Option<u32>], x: u32, hs: Half) -> Option<Sector> {
    let r = src.rotation(x);
    let i = r.iter().position(|&(_, h)| h == hs)?;
    let n = r.len();
    let to_target = |h: Half| tid[(h / 2) as usize].map(|p| 2 * p + (h % 2));
    for step in 1..n {
        let (_, h) = r[(i + n - step) % n];
        if let Some(th) = to_target(h) {
            return tgt.sector_after(x, Some(th));
        }
    }
    None
}

/// Sorted cluster labels (anchor indices) of the source faces that source path `s` touches.
fn corridor_of(src: &Tracer, cl: &Clusters, s: usize) -> Vec<u32> {
    let m = src.mesh();
    let g = src.graph();
    let p = &src.paths()[s];
    let mut out = vec![p.a, p.b];
    for &n in &p.nodes {
        match g.as_edge_node(n) {
            Some((e, _)) => {
                let (f, h) = m.edge_faces(e);
                out.push(cl.label[f.idx()]);
                if let Some(h) = h {
                    out.push(cl.label[h.idx()]);
                }
            }
            None => out.extend(m.vertex_faces(VertexId(n.0)).map(|f| cl.label[f.idx()])),
        }
    }
    out.retain(|&l| l != u32::MAX);
    out.sort_unstable();
    out.dedup();
    out
}

/// The present-path interval (predecessor, successor) around `hs` in the source rotation.
fn present_interval(src: &Tracer, tid: &[Option<u32>], x: u32, hs: Half) -> (Option<Half>, Option<Half>) {
    let r = src.rotation(x);
    let Some(i) = r.iter().position(|&(_, h)| h == hs) else { return (None, None) };
    let n = r.len();
    let present = |h: Half| tid[(h / 2) as usize].is_some();
    let pred = (1..n).map(|s| r[(i + n - s) % n].1).find(|&h| present(h));
    let succ = (1..n).map(|s| r[(i + s) % n].1).find(|&h| present(h));
    (pred, succ)
}

/// Builds the target layout as a copy of the source's on `tgt` (which must hold the source's
/// fixed paths and no others),
/// then renumbers its paths to the source's numbering.
///
/// # Errors
/// `InputError::LayoutConflict` naming the first path that cannot be traced consistently.
pub fn target_layout(
    src: &Tracer,
    src_clusters: &Clusters,
    tgt: &mut Tracer,
    opts: &LayoutOptions,
    priority: &[usize],
    progress: &mut dyn Progress,
) -> Result<std::result::Result<LayoutStats, usize>> {
    let anchors = tgt.anchors().to_vec();
    let cl = clusters_in(tgt.mesh(), &anchors, tgt.open_faces().as_deref())?;
    let np = src.paths().len();
    let order = PathOrder::new(src, &cl, priority);
    // Fixed paths are on both meshes already, under the same numbers.
    let nf = src.n_fixed();
    if tgt.n_fixed() != nf || tgt.paths().len() as u32 != nf {
        return Err(crate::error::Error::Internal("the target tracer must hold the source's fixed paths only".into()));
    }
    let mut queue: Vec<usize> = order.queue(src).into_iter().filter(|&s| s as u32 >= nf).collect();
    let mut tid: Vec<Option<u32>> = (0..np as u32).map(|s| (s < nf).then_some(s)).collect();
    let mut sid: Vec<u32> = (0..nf).collect();
    let mut stats = LayoutStats { cuts: cl.cuts.len(), ..Default::default() };
    let mut attempts = 0usize;
    let mut force = false;
    while !queue.is_empty() {
        progress.check()?;
        progress.report(crate::progress::Stage::LayoutTarget, sid.len() as f64 / np.max(1) as f64);
        let mut progressed = false;
        let mut postponed = Vec::new();
        for &s in &queue {
            if order.group[s] == 2 && !force && order.rank[s] == usize::MAX && ambiguous(src, &tid, &queue, s) {
                postponed.push(s);
                continue;
            }
            attempts += 1;
            if attempts > opts.max_attempts {
                return Err(InputError::LayoutConflict(format!(
                    "gave up after {attempts} path searches on the target"
                ))
                .into());
            }
            match trace_in_corridor(src, src_clusters, &cl, tgt, &tid, s, &mut attempts)? {
                Some(path) => {
                    let id = tgt.insert(path)?;
                    tid[s] = Some(id);
                    sid.push(s as u32);
                    progressed = true;
                    if order.group[s] == 2 {
                        stats.multiple_linkages += 1;
                    }
                }
                None => {
                    stats.failed_traces += 1;
                    postponed.push(s);
                }
            }
        }
        stats.postponed += postponed.len();
        if !progressed {
            if !force && !postponed.is_empty() {
                force = true;
                queue = postponed;
                continue;
            }
            if tracing::enabled!(tracing::Level::DEBUG) {
                debug_postponed(src, tgt, &tid, &postponed, &order, sid.len())?;
            }
            return Ok(Err(postponed[0]));
        }
        queue = postponed;
    }
    tgt.renumber(&sid)?;
    // The rotation systems agree by construction; check it, and the walks, anyway.
    let (ws, wt) = (walks(src), walks(tgt));
    if ws != wt {
        return Err(InputError::LayoutConflict("target regions differ from the source's".into()).into());
    }
    stats.paths = np;
    Ok(Ok(stats))
}

/// The order in which [`target_layout`] traces the source's paths on the target: paths asked
/// for first (`priority`, a restart's), then by group — 0: a single linkage whose anchors' target
/// cells share one cut, 1: another single linkage, 2: one of several linkages of an anchor pair —
/// then shortest source path first.
struct PathOrder {
    group: Vec<u8>,
    rank: Vec<usize>,
}

impl PathOrder {
    fn new(src: &Tracer, cl: &Clusters, priority: &[usize]) -> PathOrder {
        let key = |p: &LayoutPath| (p.a.min(p.b), p.a.max(p.b));
        let mut linkages = std::collections::HashMap::<(u32, u32), usize>::new();
        for p in src.paths() {
            *linkages.entry(key(p)).or_default() += 1;
        }
        let group = src
            .paths()
            .iter()
            .map(|p| {
                if linkages[&key(p)] > 1 {
                    2
                } else if cl.between(p.a, p.b).count() == 1 {
                    0
                } else {
                    1
                }
            })
            .collect();
        let rank =
            (0..src.paths().len()).map(|s| priority.iter().position(|&p| p == s).unwrap_or(usize::MAX)).collect();
        PathOrder { group, rank }
    }

    fn queue(&self, src: &Tracer) -> Vec<usize> {
        let mut queue: Vec<usize> = (0..src.paths().len()).collect();
        queue.sort_by(|&x, &y| {
            (self.rank[x], self.group[x], src.paths()[x].length)
                .partial_cmp(&(self.rank[y], self.group[y], src.paths()[y].length))
                .unwrap_or(std::cmp::Ordering::Equal)
        });
        queue
    }
}

/// Whether another absent linkage of path `s`'s anchor pair shares its sector at its first
/// anchor (then which of them goes where is not yet decided, and `s` waits).
fn ambiguous(src: &Tracer, tid: &[Option<u32>], queue: &[usize], s: usize) -> bool {
    let p = &src.paths()[s];
    let ia = present_interval(src, tid, p.a, 2 * s as Half);
    queue.iter().any(|&o| {
        o != s && tid[o].is_none() && {
            let q = &src.paths()[o];
            let ho = if q.a == p.a { 2 * o as Half } else { 2 * o as Half + 1 };
            (q.a.min(q.b), q.a.max(q.b)) == (p.a.min(p.b), p.a.max(p.b)) && present_interval(src, tid, p.a, ho) == ia
        }
    })
}

/// Traces source path `s` on the target between the sectors its neighbours leave, inside its
/// corridor: the target faces in the clusters of the anchors whose source clusters the source
/// path crosses (its two ends' included), so it passes every handle and limb on the same side as
/// on the source; anywhere when the corridor admits no path (one more attempt counted).
fn trace_in_corridor(
    src: &Tracer,
    src_clusters: &Clusters,
    cl: &Clusters,
    tgt: &mut Tracer,
    tid: &[Option<u32>],
    s: usize,
    attempts: &mut usize,
) -> Result<Option<LayoutPath>> {
    let p = &src.paths()[s];
    let sector_a = target_sector(src, tgt, tid, p.a, 2 * s as Half);
    let sector_b = target_sector(src, tgt, tid, p.b, 2 * s as Half + 1);
    let corridor = corridor_of(src, src_clusters, s);
    let mask: Option<Vec<bool>> =
        Some(cl.label.iter().map(|&l| l != u32::MAX && corridor.binary_search(&l).is_ok()).collect());
    let mut req = TraceRequest { a: p.a, b: p.b, faces: mask.as_deref(), sector_a, sector_b, blocked: &[] };
    let mut got = tgt.trace(&req)?;
    if got.is_none() && req.faces.is_some() {
        req.faces = None;
        *attempts += 1;
        got = tgt.trace(&req)?;
    }
    Ok(got)
}

/// Debug events for the paths that could not be placed: whether each could be traced at all,
/// or with either end's sector alone, and the regions still open.
fn debug_postponed(
    src: &Tracer,
    tgt: &mut Tracer,
    tid: &[Option<u32>],
    postponed: &[usize],
    order: &PathOrder,
    placed: usize,
) -> Result<()> {
    let np = src.paths().len();
    for &s in postponed {
        let p = &src.paths()[s];
        let free = tgt.trace(&TraceRequest { a: p.a, b: p.b, ..Default::default() })?.is_some();
        let sa = target_sector(src, tgt, tid, p.a, 2 * s as Half);
        let sb = target_sector(src, tgt, tid, p.b, 2 * s as Half + 1);
        let only_a = tgt.trace(&TraceRequest { a: p.a, b: p.b, sector_a: sa, ..Default::default() })?.is_some();
        let only_b = tgt.trace(&TraceRequest { a: p.a, b: p.b, sector_b: sb, ..Default::default() })?.is_some();
        tracing::debug!(
            "target path {s} {}-{} group {} free {free} only_a {only_a} only_b {only_b} placed {placed}/{np}",
            p.a,
            p.b,
            order.group[s],
        );
        for w in walks(tgt) {
            if !w.is_triangle(tgt) {
                tracing::debug!("  open walk {:?} halves {:?}", w.corners(tgt), w.halves);
            }
        }
    }
    Ok(())
}

/// [`target_layout`], restarted with each path that could not be traced moved to the front
/// (a rip-up-and-reroute of the whole target), at most `restarts` times.
///
/// # Errors
/// `InputError::LayoutConflict` naming the path that still cannot be traced.
pub fn target_layout_with_restarts<'m>(
    src: &Tracer,
    src_clusters: &Clusters,
    tgt: &mut Tracer<'m>,
    opts: &LayoutOptions,
    restarts: usize,
    progress: &mut dyn Progress,
) -> Result<LayoutStats> {
    let mut priority: Vec<usize> = Vec::new();
    loop {
        let mut fresh = tgt.fresh()?;
        match target_layout(src, src_clusters, &mut fresh, opts, &priority, progress)? {
            Ok(mut s) => {
                s.postponed += priority.len();
                *tgt = fresh;
                return Ok(s);
            }
            Err(s) if priority.len() < restarts && !priority.contains(&s) => priority.insert(0, s),
            Err(s) => {
                return Err(InputError::LayoutConflict(format!(
                    "the path between anchors {} and {} cannot be traced on the target without crossing others or breaking their cyclic order",
                    src.paths()[s].a,
                    src.paths()[s].b
                ))
                .into());
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::refine::refine;
    use crate::domain::walks::is_complete;
    use crate::domain::{patches_of, straighten::straighten};
    use crate::mesh::{P3, shapes};
    use crate::progress::NoProgress;

    /// The six vertices of an icosphere nearest to the octahedron's corners.
    fn octahedron_anchors(m: &Mesh) -> Vec<VertexId> {
        let dirs =
            [[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0], [0.0, 0.0, -1.0]];
        dirs.iter()
            .map(|d| {
                let best = (0..m.n_vertices())
                    .max_by(|&a, &b| {
                        let p = |v: usize| m.position(VertexId::from_idx(v));
                        let dot = |v: usize| p(v).x * d[0] + p(v).y * d[1] + p(v).z * d[2];
                        dot(a).total_cmp(&dot(b))
                    })
                    .unwrap();
                VertexId::from_idx(best)
            })
            .collect()
    }

    #[test]
    fn octahedral_layout_on_a_sphere_is_consistent_on_a_copy() {
        let m = shapes::icosphere(3);
        let a = octahedron_anchors(&m);
        let mut s = Tracer::new(&m, &a, &Default::default()).unwrap();
        let (cl, stats) = source_layout(&mut s, 2, &LayoutOptions::default(), &mut NoProgress).unwrap();
        assert_eq!(cl.cuts.len(), 12, "the Voronoi cells of an octahedron meet along 12 cuts");
        assert_eq!(stats.paths, 12);
        assert!(is_complete(&s, 2));
        let patches = patches_of(&s);
        assert_eq!(patches.len(), 8);
        // The same layout on a scaled copy, traced by Procedure 1: identical walks.
        let scaled = m.with_positions(m.positions().iter().map(|p| P3::from(p.coords * 2.0)).collect()).unwrap();
        let mut t = Tracer::new(&scaled, &a, &Default::default()).unwrap();
        target_layout_with_restarts(&s, &cl, &mut t, &LayoutOptions::default(), 4, &mut NoProgress).unwrap();
        assert_eq!(walks(&s), walks(&t));
        // Straightening keeps every walk; refinement labels every face with a patch.
        straighten(&mut t, 2, &mut NoProgress).unwrap();
        assert_eq!(walks(&s), walks(&t));
        let r = refine(&t, &patches).unwrap();
        let mut seen = vec![false; patches.len()];
        for &p in &r.patch {
            seen[p as usize] = true;
        }
        assert!(seen.iter().all(|&x| x));
        assert_eq!(crate::topology::euler_characteristic(&r.mesh), 2);
    }
}
