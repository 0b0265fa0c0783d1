//! Foldover-free alignment of feature points in the parameter square (Yu & Chuang, section
//! 3.4, after Fujimura & Makarov's foldover-free image warping). The warp mesh is the Delaunay
//! triangulation (spade) of the square's corners, the patch's feature points and, as still
//! points, the rest of the fixed boundary (so nothing is carried across it); every other free
//! vertex is marshaled into its warp triangle by barycentric coordinates and follows it.
//! Features move one at a time toward their targets. Where the paper bisects for the moment a
//! warp triangle would degenerate (an *event*), the area of each triangle around the moving
//! point is linear in the step, so the event time is solved for exactly; the point stops half
//! way to it, the warp mesh is re-triangulated (Delaunay removes the collapsing sliver) and the
//! marshaled vertices are re-located, then the motion resumes. Base-mesh triangles whose
//! corners fall in different warp triangles can still fold, so the motion is made in steps
//! (an eighth of the way, a quarter as long after a step the repairs could not undo), the
//! carried vertices are relaxed by stretch optimization after each, and the free vertices of
//! any folded triangle are moved to the centroid of their star's kernel; the features
//! themselves never leave their straight paths.

use super::kernel::kernel_centroid;
use super::stretch::{ParamState, StretchOptOptions, area2};
use crate::error::{Error, Result};
use crate::param::Uv;
use crate::planar::locate::barycentric;
use spade::{DelaunayTriangulation, Point2, Triangulation};

/// The features move to their targets in this many equal steps, the carried vertices relaxed
/// (stretch optimization, features held) after each, so no step shears the base mesh much.
const SUBSTEPS: usize = 8;

/// The shortest step (a fraction of the whole motion) before the alignment gives up; steps
/// start at `1 / SUBSTEPS`, shrink by 4 when a step folds more than the repairs undo, and grow
/// back by 2 after each clean one.
const MIN_STEP: f64 = 1.0 / 4096.0;

/// Most re-triangulations per feature before the alignment gives up.
const MAX_EVENTS: usize = 2000;

/// Output of [`align_features`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct WarpResult {
    /// Re-triangulations of the warp mesh (events).
    pub events: usize,
    /// Vertices moved to their kernel centroid afterwards to undo folds.
    pub repaired: usize,
}

fn delaunay(pts: &[Uv]) -> Result<Vec<[usize; 3]>> {
    let mut dt: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::new();
    for p in pts {
        dt.insert(Point2::new(p[0], p[1])).map_err(|e| Error::Numerical(format!("warp mesh: {e}")))?;
    }
    if dt.num_vertices() != pts.len() {
        return Err(Error::Numerical("warp mesh: two feature points coincide in the parameter square".into()));
    }
    Ok(dt
        .inner_faces()
        .map(|f| {
            let [a, b, c] = f.vertices().map(|v| v.fix().index());
            if area2(pts[a], pts[b], pts[c]) < 0.0 { [a, c, b] } else { [a, b, c] }
        })
        .collect())
}

/// Triangle of `tris` containing `p` (largest smallest barycentric coordinate) and the coordinates.
fn marshal(pts: &[Uv], tris: &[[usize; 3]], p: Uv) -> (usize, [f64; 3]) {
    let mut best = (f64::NEG_INFINITY, 0, [1.0, 0.0, 0.0]);
    for (i, t) in tris.iter().enumerate() {
        let b = barycentric(t.map(|v| pts[v]), p);
        let m = b[0].min(b[1]).min(b[2]);
        if m > best.0 {
            best = (m, i, b);
        }
    }
    (best.1, best.2)
}

/// Moves each `(vertex, target)` of `state` to its target in the unit square, carrying the
/// other free vertices along. `corners` are the square's corner vertices.
///
/// # Errors
/// `Numerical` when the warp stalls or a fold cannot be undone.
pub fn align_features(state: &mut ParamState, corners: [u32; 4], targets: &[(u32, Uv)]) -> Result<WarpResult> {
    if targets.is_empty() {
        return Ok(WarpResult { events: 0, repaired: 0 });
    }
    let start: Vec<Uv> = targets.iter().map(|&(v, _)| state.uv[v as usize]).collect();
    let held: Vec<u32> = targets.iter().map(|&(v, _)| v).collect();
    let (mut events, mut repaired) = (0, 0);
    let (mut done, mut step) = (0.0f64, 1.0 / SUBSTEPS as f64);
    while done < 1.0 {
        let f = (done + step).min(1.0);
        let sub: Vec<(u32, Uv)> = targets
            .iter()
            .zip(&start)
            .map(|(&(v, t), p)| (v, if f >= 1.0 { t } else { [p[0] + f * (t[0] - p[0]), p[1] + f * (t[1] - p[1])] }))
            .collect();
        let before = state.uv.clone();
        events += warp_to(state, corners, &sub)?;
        match repair_folds(state, &held, step <= MIN_STEP) {
            Ok(r) => repaired += r,
            // The step sheared the base mesh more than the repairs undo: take a shorter one.
            Err(_) if step > MIN_STEP => {
                state.uv = before;
                step /= 4.0;
                continue;
            }
            Err(e) => return Err(e),
        }
        done = f;
        step = (2.0 * step).min(1.0 / SUBSTEPS as f64);
        // Relax the carried vertices with the features held, so the next step starts from a
        // well-shaped embedding.
        let was: Vec<bool> = targets.iter().map(|&(v, _)| state.fixed[v as usize]).collect();
        for &(v, _) in targets {
            state.fixed[v as usize] = true;
        }
        let free: Vec<u32> =
            (0..state.pos.len() as u32).filter(|&v| state.active[v as usize] && !state.fixed[v as usize]).collect();
        state.optimize(&free, &StretchOptOptions { max_sweeps: 15, ..Default::default() });
        for (&(v, _), h) in targets.iter().zip(was) {
            state.fixed[v as usize] = h;
        }
    }
    Ok(WarpResult { events, repaired })
}

/// One kinetic warp of every feature to its target; returns the events.
fn warp_to(state: &mut ParamState, corners: [u32; 4], targets: &[(u32, Uv)]) -> Result<usize> {
    let mut warp_ids: Vec<u32> = corners.to_vec();
    warp_ids.extend(targets.iter().map(|&(v, _)| v));
    // The rest of the fixed boundary joins the warp mesh as still points, so the vertices
    // carried near the boundary stay inside it.
    let still: Vec<u32> = (0..state.pos.len() as u32)
        .filter(|&v| state.active[v as usize] && state.fixed[v as usize] && !warp_ids.contains(&v))
        .collect();
    warp_ids.extend(still);
    let movers: Vec<u32> = (0..state.pos.len() as u32)
        .filter(|&v| state.active[v as usize] && !state.fixed[v as usize] && !warp_ids.contains(&v))
        .collect();
    let mut pts: Vec<Uv> = warp_ids.iter().map(|&v| state.uv[v as usize]).collect();
    let mut events = 0;
    for (k, &(_, target)) in targets.iter().enumerate() {
        let w = 4 + k;
        for step in 0.. {
            if step >= MAX_EVENTS {
                return Err(Error::Numerical(format!("feature alignment of feature {k} stalled")));
            }
            let tris = delaunay(&pts)?;
            let places: Vec<(usize, [f64; 3])> =
                movers.iter().map(|&v| marshal(&pts, &tris, state.uv[v as usize])).collect();
            let p = pts[w];
            let d = [target[0] - p[0], target[1] - p[1]];
            // Largest step before a triangle around w degenerates.
            let mut t_max = f64::INFINITY;
            for t in tris.iter().filter(|t| t.contains(&w)) {
                let r = t.iter().position(|&x| x == w).unwrap_or(0);
                let (a, b) = (pts[t[(r + 1) % 3]], pts[t[(r + 2) % 3]]);
                let area = area2(p, a, b);
                let slope = (a[1] - b[1]) * d[0] + (b[0] - a[0]) * d[1];
                if slope < 0.0 {
                    t_max = t_max.min(-area / slope);
                }
            }
            let done = t_max > 1.0;
            pts[w] = if done { target } else { [p[0] + 0.5 * t_max * d[0], p[1] + 0.5 * t_max * d[1]] };
            for (i, &v) in movers.iter().enumerate() {
                let (ti, b) = places[i];
                let tri = tris[ti];
                if tri.contains(&w) {
                    let q = tri.map(|x| pts[x]);
                    state.uv[v as usize] = [
                        b[0] * q[0][0] + b[1] * q[1][0] + b[2] * q[2][0],
                        b[0] * q[0][1] + b[1] * q[1][1] + b[2] * q[2][1],
                    ];
                }
            }
            events += 1;
            if done {
                break;
            }
        }
        state.uv[targets[k].0 as usize] = target;
    }
    Ok(events)
}

/// Moves the free vertices of folded triangles to their kernel centroids until nothing folds;
/// a tangle that one-vertex moves cannot free is untangled as a whole
/// ([`crate::crossparam::foldover_free`], Garanzha et al. 2021) with the boundary and the
/// `held` features in place.
fn repair_folds(state: &mut ParamState, held: &[u32], last_resort: bool) -> Result<usize> {
    let mut moved = 0;
    for round in 0..50 {
        let mut bad: Vec<u32> = Vec::new();
        for t in state.live_faces() {
            if area2(state.uv[t[0] as usize], state.uv[t[1] as usize], state.uv[t[2] as usize]) <= 0.0 {
                bad.extend(t.iter().copied().filter(|&v| !state.fixed[v as usize] && !held.contains(&v)));
            }
        }
        if bad.is_empty() {
            return Ok(moved);
        }
        if round == 10 && last_resort {
            moved += untangle(state, held)?;
            continue;
        }
        bad.sort_unstable();
        bad.dedup();
        for v in bad {
            if let Some(c) = kernel_centroid(&state.link_uv(v)) {
                state.uv[v as usize] = c;
                moved += 1;
            }
        }
    }
    if tracing::enabled!(tracing::Level::DEBUG) {
        let folded: Vec<[u32; 3]> = state
            .live_faces()
            .filter(|t| area2(state.uv[t[0] as usize], state.uv[t[1] as usize], state.uv[t[2] as usize]) <= 0.0)
            .collect();
        let stuck = folded.iter().filter(|t| t.iter().all(|&v| state.fixed[v as usize] || held.contains(&v))).count();
        tracing::debug!(
            "warp: {} folded of {} live faces, {stuck} with every corner held; {} held",
            folded.len(),
            state.live_faces().count(),
            held.len()
        );
    }
    Err(Error::Numerical("feature alignment left folded triangles that could not be undone".into()))
}

/// Untangles the live mesh of `state` at once; returns the vertices it moved (0 if it failed).
fn untangle(state: &mut ParamState, held: &[u32]) -> Result<usize> {
    let mut local = vec![u32::MAX; state.pos.len()];
    let mut ids = Vec::new();
    let tris: Vec<[u32; 3]> = state
        .live_faces()
        .map(|t| {
            t.map(|v| {
                if local[v as usize] == u32::MAX {
                    local[v as usize] = ids.len() as u32;
                    ids.push(v);
                }
                local[v as usize]
            })
        })
        .collect();
    let mesh = crate::mesh::Mesh::from_triangles(ids.iter().map(|&v| state.pos[v as usize]).collect(), &tris)
        .map_err(|e| Error::Internal(format!("warp: live base mesh invalid: {e}")))?;
    let mut uv: Vec<Uv> = ids.iter().map(|&v| state.uv[v as usize]).collect();
    let keep: Vec<bool> = ids.iter().map(|&v| state.fixed[v as usize] || held.contains(&v)).collect();
    let r = crate::crossparam::foldover_free::foldover_free(&mesh, &mut uv, &keep, 1.0, &Default::default());
    if !r.valid {
        return Ok(0);
    }
    let mut moved = 0;
    for (&v, &p) in ids.iter().zip(&uv) {
        if state.uv[v as usize] != p {
            state.uv[v as usize] = p;
            moved += 1;
        }
    }
    Ok(moved)
}
