//! Completing a layout into a triangulation (Kwok et al. 5.1, "patch triangulation", and the
//! same step of Kraevoy & Sheffer): every region that is not a triangle gets a path between two
//! of its corners that are not adjacent along its boundary, shortest first, traced inside the
//! region (the sectors of the two corners confine it). Regions that are not disks (a cylinder
//! or a handle left between paths) are opened by a path between corners of two different
//! walks. Works on several meshes at once: a path is inserted only if it traces on all of them.

use super::tracer::{TraceRequest, Tracer};
use super::walks::{graph_components, walks};
use crate::error::{InputError, Result};
use crate::progress::Progress;

/// How often the paths between one anchor pair may be ripped up.
const MAX_RIPS_PER_PAIR: usize = 3;

/// Counts of what completion added.
#[derive(Debug, Default, Clone, Copy)]
pub struct CompleteStats {
    pub diagonals: usize,
    /// Paths removed to merge a region that could not be split.
    pub ripped: usize,
    pub attempts: usize,
}

fn dist(t: &Tracer, a: u32, b: u32) -> f64 {
    let m = t.mesh();
    (m.position(t.anchors()[a as usize]) - m.position(t.anchors()[b as usize])).norm()
}

/// Traces one path on every tracer, each with the sectors of its own walk corners; inserts
/// on all or none. `corners` are (walk index, corner index) in the walks of each tracer.
fn try_link(ts: &mut [&mut Tracer], ends: [(usize, usize); 2], stats: &mut CompleteStats) -> Result<bool> {
    let mut found = Vec::with_capacity(ts.len());
    for t in ts.iter_mut() {
        stats.attempts += 1;
        let ws = walks(t);
        let (w1, c1) = ends[0];
        let (w2, c2) = ends[1];
        let a = ws[w1].corners(t)[c1];
        let b = ws[w2].corners(t)[c2];
        let req = TraceRequest {
            a,
            b,
            sector_a: Some(ws[w1].sector(t, c1)),
            sector_b: Some(ws[w2].sector(t, c2)),
            ..Default::default()
        };
        match t.trace(&req)? {
            Some(p) => found.push(p),
            None => {
                if tracing::enabled!(tracing::Level::DEBUG) {
                    let free = t.trace(&TraceRequest { a, b, ..Default::default() })?.is_some();
                    tracing::debug!(
                        "link {a}-{b} failed; sectors {:?} {:?}; unconstrained ok: {free}; rot a {:?} rot b {:?}",
                        req.sector_a,
                        req.sector_b,
                        t.rotation(a),
                        t.rotation(b)
                    );
                }
                return Ok(false);
            }
        }
    }
    for (t, p) in ts.iter_mut().zip(found) {
        t.insert(p)?;
    }
    stats.diagonals += 1;
    Ok(true)
}

/// Would removing path `p` disconnect the layout graph or leave an anchor without paths?
fn disconnects(t: &Tracer, p: u32) -> bool {
    let na = t.anchors().len();
    let mut parent: Vec<usize> = (0..na).collect();
    let mut degree = vec![0usize; na];
    for (i, q) in t.paths().iter().enumerate() {
        if i == p as usize {
            continue;
        }
        degree[q.a as usize] += 1;
        degree[q.b as usize] += 1;
        let (x, y) = (super::uf_find(&mut parent, q.a as usize), super::uf_find(&mut parent, q.b as usize));
        parent[x] = y;
    }
    let q = &t.paths()[p as usize];
    degree[q.a as usize] == 0
        || degree[q.b as usize] == 0
        || super::uf_find(&mut parent, q.a as usize) != super::uf_find(&mut parent, q.b as usize)
}

/// `V − E + W − χ` of the layout with walks `ws`. A region of genus `g` bounded by `b` walks
/// adds `2 (b − 1 + g)` (an annulus left around a handle adds 2, a disk nothing), so it is 0
/// exactly when every region is a disk (for a connected layout graph).
fn excess(t: &Tracer, ws: &[super::walks::Walk], chi: i64) -> i64 {
    t.anchors().len() as i64 - t.paths().len() as i64 + ws.len() as i64 - chi
}

/// For debug-level tracing: the layout's census before each completion step, [`excess`] and the
/// open walks (the regions still to split).
fn census(t: &Tracer, ws: &[super::walks::Walk], chi: i64) {
    let open: Vec<Vec<u32>> = ws.iter().filter(|w| !w.is_triangle(t)).map(|w| w.corners(t)).collect();
    tracing::debug!(
        "complete: V {} E {} W {} (V - E + W - chi = {}) open walks {open:?}",
        t.anchors().len(),
        t.paths().len(),
        ws.len(),
        excess(t, ws, chi)
    );
}

/// Joins two walks of one region (which must then not be a disk) by the shortest traceable
/// path between corners of theirs (distinct anchors); candidates nearest first, until
/// `max_attempts` traces in all.
fn join_walks(
    ts: &mut [&mut Tracer],
    ws: &[super::walks::Walk],
    max_attempts: usize,
    stats: &mut CompleteStats,
) -> Result<bool> {
    type End = (usize, usize);
    let t0: &Tracer = ts[0];
    let mut cand: Vec<(f64, End, End)> = Vec::new();
    for (wi, w) in ws.iter().enumerate() {
        for (wj, x) in ws.iter().enumerate().skip(wi + 1) {
            for (ci, &a) in w.corners(t0).iter().enumerate() {
                for (cj, &b) in x.corners(t0).iter().enumerate() {
                    if a != b {
                        cand.push((dist(t0, a, b), (wi, ci), (wj, cj)));
                    }
                }
            }
        }
    }
    cand.sort_by(|a, b| a.0.total_cmp(&b.0));
    for (_, e1, e2) in cand {
        if stats.attempts > max_attempts {
            break;
        }
        if try_link(ts, [e1, e2], stats)? {
            return Ok(true);
        }
    }
    Ok(false)
}

/// Adds paths until every region is a triangle and the layout is cellular (`V - E + W = χ`).
///
/// # Errors
/// `InputError::LayoutConflict` when some region cannot be triangulated within
/// `max_attempts` traces; `Cancelled`.
pub fn complete(
    ts: &mut [&mut Tracer],
    chi: i64,
    max_attempts: usize,
    progress: &mut dyn Progress,
) -> Result<CompleteStats> {
    let mut stats = CompleteStats::default();
    let mut ripped: Vec<(u32, u32)> = Vec::new();
    'outer: loop {
        progress.check()?;
        if stats.attempts > max_attempts {
            return Err(InputError::LayoutConflict(format!(
                "gave up completing the layout after {} path searches",
                stats.attempts
            ))
            .into());
        }
        let t0: &Tracer = ts[0];
        let (comps, all) = graph_components(t0);
        if !all || comps != 1 {
            return Err(InputError::LayoutConflict(format!(
                "the paths leave {comps} separate groups of anchors{}",
                if all { "" } else { " and some anchors unlinked" }
            ))
            .into());
        }
        let ws = walks(t0);
        if tracing::enabled!(tracing::Level::DEBUG) {
            census(t0, &ws, chi);
        }
        // 1. Split non-triangular walks by their shortest admissible diagonal.
        for (wi, w) in ws.iter().enumerate() {
            if w.is_triangle(t0) {
                continue;
            }
            let c = w.corners(t0);
            let n = c.len();
            if n < 3 {
                return Err(InputError::LayoutConflict(format!(
                    "two paths between anchors {} and {} enclose a region with no other anchor",
                    c[0],
                    c.get(1).copied().unwrap_or(c[0])
                ))
                .into());
            }
            let mut cand: Vec<(f64, usize, usize)> = Vec::new();
            for i in 0..n {
                for j in i + 2..n {
                    if i == 0 && j == n - 1 || c[i] == c[j] {
                        continue;
                    }
                    cand.push((dist(t0, c[i], c[j]), i, j));
                }
            }
            // Rank by the length of the path each diagonal would really take on the first mesh
            // (the shortest admissible one wins, as in the shortest-first heuristic), falling
            // back to the straight-line distance for diagonals that do not trace there.
            if cand.len() > 1 {
                let sec: Vec<_> = (0..n).map(|i| w.sector(t0, i)).collect();
                let t0m: &mut Tracer = ts[0];
                for x in cand.iter_mut() {
                    stats.attempts += 1;
                    let req = TraceRequest {
                        a: c[x.1],
                        b: c[x.2],
                        sector_a: Some(sec[x.1]),
                        sector_b: Some(sec[x.2]),
                        ..Default::default()
                    };
                    x.0 = match t0m.trace(&req)? {
                        Some(p) => p.length,
                        None => f64::INFINITY,
                    };
                }
            }
            cand.sort_by(|a, b| a.0.total_cmp(&b.0));
            for (_, i, j) in cand {
                if try_link(ts, [(wi, i), (wi, j)], &mut stats)? {
                    continue 'outer;
                }
            }
            // Rip up: drop the shortest side of this region whose anchor pair was not dropped
            // too often already, merging the region with its neighbour, and try again.
            let t0: &Tracer = ts[0];
            let mut sides: Vec<u32> = w.halves.iter().map(|&h| h / 2).collect();
            sides.sort_unstable();
            sides.dedup();
            let pair = |p: u32| {
                let q = &t0.paths()[p as usize];
                (q.a.min(q.b), q.a.max(q.b))
            };
            let victim = sides
                .into_iter()
                .filter(|&p| !t0.is_fixed(p) && ripped.iter().filter(|&&q| q == pair(p)).count() < MAX_RIPS_PER_PAIR)
                // Never a bridge or an anchor's last path: the layout must stay connected.
                .filter(|&p| !disconnects(t0, p))
                .min_by(|&x, &y| t0.paths()[x as usize].length.total_cmp(&t0.paths()[y as usize].length));
            if let Some(p) = victim {
                ripped.push(pair(p));
                stats.ripped += 1;
                for t in ts.iter_mut() {
                    t.remove(p);
                }
                continue 'outer;
            }
            return Err(InputError::LayoutConflict(format!(
                "region with corners {c:?} cannot be split into triangles by non-crossing paths"
            ))
            .into());
        }
        // 2. All triangles: if the layout is not cellular, join two walks of one region.
        if excess(ts[0], &ws, chi) == 0 {
            return Ok(stats);
        }
        if join_walks(ts, &ws, max_attempts, &mut stats)? {
            continue 'outer;
        }
        return Err(InputError::LayoutConflict(
            "the layout does not cut the surface into disks and no joining path could be traced".into(),
        )
        .into());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{VertexId, shapes};

    #[test]
    fn excess_counts_regions_that_are_not_disks() {
        // A triangle of paths on a sphere: two disks.
        let m = shapes::icosphere(3);
        let mut t = Tracer::new(&m, &[VertexId(0), VertexId(5), VertexId(11)], &Default::default()).unwrap();
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            t.trace_insert(&TraceRequest { a, b, ..Default::default() }).unwrap().unwrap();
        }
        assert_eq!(excess(&t, &walks(&t), 2), 0);
        // The same on a torus: one disk, and a one-holed torus (b = 1, g = 1) adds 2.
        let m = shapes::torus(24, 12, 1.0, 0.4);
        let anchors = [VertexId(0), VertexId(2), VertexId(2 * 12 + 1)];
        let mut t = Tracer::new(&m, &anchors, &Default::default()).unwrap();
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            t.trace_insert(&TraceRequest { a, b, ..Default::default() }).unwrap().unwrap();
        }
        assert_eq!(walks(&t).len(), 2);
        assert_eq!(excess(&t, &walks(&t), 0), 2);
    }

    #[test]
    fn bridges_and_last_paths_are_not_ripped() {
        let m = shapes::icosphere(3);
        let anchors = [VertexId(0), VertexId(5), VertexId(11), VertexId(30)];
        let mut t = Tracer::new(&m, &anchors, &Default::default()).unwrap();
        // A chain 0 - 1 - 2: both paths are bridges; anchor 3 has no path at all.
        let p01 = t.trace_insert(&TraceRequest { a: 0, b: 1, ..Default::default() }).unwrap().unwrap();
        let p12 = t.trace_insert(&TraceRequest { a: 1, b: 2, ..Default::default() }).unwrap().unwrap();
        assert!(disconnects(&t, p01) && disconnects(&t, p12));
        // Closing the triangle 0 - 1 - 2: no path is a bridge any more.
        let p20 = t.trace_insert(&TraceRequest { a: 2, b: 0, ..Default::default() }).unwrap().unwrap();
        assert!(!disconnects(&t, p01) && !disconnects(&t, p12) && !disconnects(&t, p20));
        // A dangling path to anchor 3 is its last one.
        let p23 = t.trace_insert(&TraceRequest { a: 2, b: 3, ..Default::default() }).unwrap().unwrap();
        assert!(disconnects(&t, p23));
    }
}
