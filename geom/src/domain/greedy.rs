//! The baseline of Kraevoy & Sheffer 2004 (section 3): candidate links between all anchor
//! pairs, ordered by their shortest-path lengths (summed over both meshes, each relative to
//! the square root of its area), are inserted shortest first on both meshes at once. A link is
//! accepted only if it traces on both without crossing existing paths and, on the target, in
//! the sector that the source's rotation prescribes (cyclic order). Traces are not confined to
//! any cluster, and no pair is linked twice. When the list is exhausted the remaining regions
//! are triangulated the same way as the Voronoi method's ([`super::complete`]), so both methods
//! share every step but the choice of paths.

use super::complete::complete;
use super::tracer::{TraceRequest, Tracer};
use super::{LayoutOptions, LayoutStats};
use crate::error::Result;
use crate::geodesic::{VertexDijkstraOptions, vertex_dijkstra};
use crate::progress::Progress;

fn pair_lengths(t: &Tracer) -> Result<Vec<Vec<f64>>> {
    let m = t.mesh();
    let scale = m.area().sqrt().max(f64::MIN_POSITIVE);
    let anchors = t.anchors();
    let mut out = Vec::with_capacity(anchors.len());
    for &a in anchors {
        let d = vertex_dijkstra(m, &[(a, 0.0)], &VertexDijkstraOptions::default())?;
        out.push(anchors.iter().map(|b| d.dist[b.idx()] / scale).collect());
    }
    Ok(out)
}

/// Builds the layouts on both tracers (which must hold the same fixed paths and no others).
///
/// # Errors
/// `InputError::LayoutConflict` when no consistent triangulation is found; `Cancelled`.
pub fn greedy_layout<'m>(
    src: &mut Tracer<'m>,
    tgt: &mut Tracer<'m>,
    chi: i64,
    opts: &LayoutOptions,
    progress: &mut dyn Progress,
) -> Result<LayoutStats> {
    let (ls, lt) = (pair_lengths(src)?, pair_lengths(tgt)?);
    let na = src.anchors().len();
    let mut cand: Vec<(f64, u32, u32)> = Vec::new();
    for i in 0..na {
        for j in i + 1..na {
            let l = ls[i][j] + lt[i][j];
            if l.is_finite() {
                cand.push((l, i as u32, j as u32));
            }
        }
    }
    cand.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut stats = LayoutStats::default();
    let max_paths = 3 * na.max(2);
    for (k, &(_, a, b)) in cand.iter().enumerate() {
        progress.check()?;
        if k % 16 == 0 {
            progress.report(crate::progress::Stage::LayoutGreedy, k as f64 / cand.len().max(1) as f64);
        }
        if src.paths().len() >= max_paths || super::walks::is_complete(src, chi) {
            break;
        }
        if src.is_enclosed(a) || src.is_enclosed(b) || src.linked_by_fixed(a, b) {
            continue;
        }
        let Some(ps) = src.trace(&TraceRequest { a, b, ..Default::default() })? else {
            stats.failed_traces += 1;
            continue;
        };
        let next = src.paths().len() as u32;
        // The sectors the source path would take, among the paths already present.
        let sa = src.sector_for_new(a, &ps.nodes[1]);
        let sb = src.sector_for_new(b, &ps.nodes[ps.nodes.len() - 2]);
        let sector_a = sa.and_then(|after| tgt.sector_after(a, Some(after)));
        let sector_b = sb.and_then(|after| tgt.sector_after(b, Some(after)));
        let Some(pt) = tgt.trace(&TraceRequest { a, b, sector_a, sector_b, ..Default::default() })? else {
            stats.failed_traces += 1;
            continue;
        };
        debug_assert_eq!(next, tgt.paths().len() as u32);
        src.insert(ps)?;
        tgt.insert(pt)?;
    }
    let before = src.paths().len();
    complete(&mut [src, tgt], chi, opts.max_attempts, progress)?;
    stats.triangulation_paths = src.paths().len() - before;
    stats.paths = src.paths().len();
    Ok(stats)
}
