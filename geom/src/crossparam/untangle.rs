//! Untangling what the one-vertex repairs leave folded, by re-embedding a whole region.
//!
//! A fold whose vertices must all move together (a cluster squeezed by the patch maps and
//! turned over) defeats [`super::visible::repair_flips`], which tries one vertex at a time.
//! Here the folded faces with `k` rings of faces around them form a source disk `R`; the target
//! faces under `R`'s images, with rings around them, form a target disk `D`, which is flattened
//! bijectively onto the unit circle (mean-value weights, Floater 2003). `R`'s boundary and
//! anchors keep their images (read in `D`'s chart); its interior is re-embedded by Tutte's
//! method with the source's own mean-value weights (Floater's theorem: a convex-combination
//! map whose boundary polygon is convex is an embedding), then lifted back through the chart
//! onto the target. This is the "local re-parameterization" remedy for folds of Schreiner et
//! al. 2004 and Kraevoy & Sheffer 2004, section 5. Since `R`'s boundary polygon need not be
//! convex, the current images and the Tutte embedding are both repaired in the plane
//! ([`super::planar_untangle`]; [`super::foldover_free`] for tangles the local moves cannot
//! free, a bounded number of times per call, and as a lower-distortion variant of their
//! result), with and without the anchors'
//! rings spread as in the source, and a candidate counts only if every face of `R` keeps the
//! chart's orientation. The candidate
//! with the fewest evaluator-counted flips on `R` and the ring around it is kept if that is
//! fewer than before; otherwise `R` grows by two rings and the step is retried.

use super::foldover_free::{FoldoverFreeOptions, foldover_free};
use super::planar_untangle::{kernel_sweeps, signed_area, spread_ring, untangle_planar};
use super::visible::{evaluator_folded, fold_suspects, unit_normals};
use crate::error::Result;
use crate::linalg::{FixedBoundarySystem, Weights};
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, P3, V3, VertexId};
use crate::metrics::SurfaceIndex;
use crate::param::{BoundaryShape, DiskParamOptions, Uv, disk_boundary, parameterize_disk};
use crate::planar::locate::Grid;
use crate::topology::SurfacePoint;
use serde::{Deserialize, Serialize};

/// Options for [`untangle`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct UntangleOptions {
    /// Largest ring count around a fold (the region starts at 2 rings and grows by 2).
    pub max_rings: usize,
    /// Face rings added around the images to make the target chart.
    pub chart_rings: usize,
    /// Passes over the remaining folds.
    pub passes: usize,
    /// Region re-embeddings tried at most (a bound on the time spent on hopeless folds).
    pub max_attempts: usize,
    /// Runs of the global untangler ([`foldover_free`], the costliest step) from a tangle the
    /// local moves could not free, at most, over all attempts: a sweep case (7k vertices, 42
    /// hopeless folds) spent most of its 22 s in them for nothing (git show 32d23d1:bench/NOTES.md).
    pub max_global: usize,
}

impl Default for UntangleOptions {
    fn default() -> Self {
        Self { max_rings: 10, chart_rings: 3, passes: 3, max_attempts: 40, max_global: 32 }
    }
}

/// What [`untangle`] did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct UntangleResult {
    /// Evaluator-counted folded faces before and after.
    pub folded_before: usize,
    pub folded_after: usize,
    /// Regions re-embedded.
    pub regions: usize,
}

/// New images: source vertex, target face, barycentric coordinates.
type Moves = Vec<(VertexId, FaceId, [f64; 3])>;

/// A re-embedding with its judged folds and energy, and the images and nearest faces after it.
struct Candidate {
    folds: usize,
    energy: f64,
    pos: Vec<P3>,
    near: Vec<FaceId>,
    moves: Moves,
}

/// Evaluator's flip rule for face `f` of `source` with images `pos` lying nearest to faces
/// `near`: the image faces against the target at its corners' faces and its centroid's.
fn folded(source: &Mesh, tn: &[V3], index: &SurfaceIndex, f: FaceId, pos: &[P3], near: &[FaceId]) -> bool {
    let tri = source.face(f);
    evaluator_folded(tri.map(|w| pos[w.idx()]), tri.map(|w| near[w.idx()]), tn, index)
}

/// Faces within `rings` vertex-rings of `seed`.
fn grow(mesh: &Mesh, seed: &[FaceId], rings: usize) -> Vec<FaceId> {
    let mut inside = vec![false; mesh.n_faces()];
    let mut out: Vec<FaceId> = Vec::new();
    for &f in seed {
        if !std::mem::replace(&mut inside[f.idx()], true) {
            out.push(f);
        }
    }
    let mut start = 0;
    for _ in 0..rings {
        let end = out.len();
        for i in start..end {
            for v in mesh.face(out[i]) {
                for g in mesh.vertex_faces(v) {
                    if !std::mem::replace(&mut inside[g.idx()], true) {
                        out.push(g);
                    }
                }
            }
        }
        start = end;
    }
    out
}

/// The faces as a mesh of their own, with the parent vertex of each local vertex; `None`
/// unless it is a topological disk.
fn disk_of(mesh: &Mesh, faces: &[FaceId]) -> Option<(Mesh, Vec<VertexId>)> {
    let mut local = std::collections::HashMap::new();
    let mut parent = Vec::new();
    let tris: Vec<[u32; 3]> = faces
        .iter()
        .map(|&f| {
            mesh.face(f).map(|v| {
                *local.entry(v).or_insert_with(|| {
                    parent.push(v);
                    (parent.len() - 1) as u32
                })
            })
        })
        .collect();
    let pos = parent.iter().map(|&v| mesh.position(v)).collect();
    let m = Mesh::from_triangles(pos, &tris).ok()?;
    disk_boundary(&m).ok()?;
    Some((m, parent))
}

/// `faces` plus every component of the rest of the surface except the largest (holes that
/// rings of faces around a thin part leave), so that the result can be a disk.
fn fill_holes(mesh: &Mesh, faces: &[FaceId]) -> Vec<FaceId> {
    let mut label = vec![u32::MAX; mesh.n_faces()];
    for &f in faces {
        label[f.idx()] = 0;
    }
    let mut comps: Vec<Vec<FaceId>> = Vec::new();
    for s in 0..mesh.n_faces() {
        if label[s] != u32::MAX {
            continue;
        }
        let id = comps.len() as u32 + 1;
        label[s] = id;
        let mut comp = vec![FaceId::from_idx(s)];
        let mut i = 0;
        while i < comp.len() {
            for g in mesh.face_neighbors(comp[i]) {
                if label[g.idx()] == u32::MAX {
                    label[g.idx()] = id;
                    comp.push(g);
                }
            }
            i += 1;
        }
        comps.push(comp);
    }
    let largest = comps.iter().enumerate().max_by_key(|(_, c)| c.len()).map_or(usize::MAX, |(i, _)| i);
    let mut out = faces.to_vec();
    for (i, c) in comps.into_iter().enumerate() {
        if i != largest {
            out.extend(c);
        }
    }
    out
}

/// For debug-level tracing: how tangled the current images of a region are in its chart.
fn chart_state(rmesh: &Mesh, rb: &[VertexId], uv: &[Uv], held: &[bool], sign: f64) -> String {
    let inv = |f: usize| signed_area(rmesh.face(FaceId::from_idx(f)).map(|v| uv[v.idx()])) * sign <= 0.0;
    let all_held = |f: usize| rmesh.face(FaceId::from_idx(f)).iter().all(|v| held[v.idx()]);
    let n_inv = (0..rmesh.n_faces()).filter(|&f| inv(f)).count();
    let n_inv_held = (0..rmesh.n_faces()).filter(|&f| inv(f) && all_held(f)).count();
    let area: f64 = (0..rb.len())
        .map(|i| {
            let (a, b) = (uv[rb[i].idx()], uv[rb[(i + 1) % rb.len()].idx()]);
            a[0] * b[1] - a[1] * b[0]
        })
        .sum::<f64>()
        / 2.0;
    format!("inverted {n_inv} (all corners held {n_inv_held}), boundary {} encloses {area:.3e}", rb.len())
}

/// Re-embeds the source region `faces` inside a chart of the target. Returns candidate new
/// images of its free interior vertices (parent ids), each a valid embedding in the chart:
/// the current images with inverted stars moved into their kernels (the least change), the
/// Tutte embedding with the same repair, and either with the rings of held interior vertices
/// spread; each also minimized by the foldover-free energy. Empty when none is valid.
fn reembed(
    source: &Mesh,
    target: &Mesh,
    map: &SurfaceMap,
    is_fixed: &[bool],
    faces: &[FaceId],
    chart_rings: usize,
    global_left: &mut usize,
) -> Vec<Moves> {
    let why = |m: &str| {
        if tracing::enabled!(tracing::Level::DEBUG) {
            tracing::debug!("untangle:   {} faces: {m}", faces.len());
        }
    };
    let Some((rmesh, rparent)) = disk_of(source, faces) else {
        why("region not a disk");
        return Vec::new();
    };
    // The target chart: the faces under the images, with rings around them, as a disk.
    let seed: Vec<FaceId> = rparent.iter().map(|v| map.face[v.idx()]).collect();
    let Some((dmesh, dfaces)) = (chart_rings..chart_rings + 3).find_map(|k| {
        let df = fill_holes(target, &grow(target, &seed, k));
        disk_of(target, &df).map(|(m, _)| (m, df))
    }) else {
        why("chart not a disk");
        return Vec::new();
    };
    let opts = DiskParamOptions { weights: Weights::MeanValue, boundary: BoundaryShape::Circle };
    let Ok(chart) = parameterize_disk(&dmesh, &opts) else { return Vec::new() };
    let dtris: Vec<[u32; 3]> = (0..dmesh.n_faces()).map(|f| dmesh.face(FaceId::from_idx(f)).map(|v| v.0)).collect();
    let sign = signed_area(dtris[0].map(|v| chart.uv[v as usize])).signum();
    let dlocal: std::collections::HashMap<FaceId, usize> = dfaces.iter().enumerate().map(|(i, &f)| (f, i)).collect();
    // Chart position of every image in R.
    let uv_of = |v: VertexId| -> Option<Uv> {
        let lf = *dlocal.get(&map.face[v.idx()])?;
        let b = map.bary[v.idx()];
        let t = dtris[lf].map(|w| chart.uv[w as usize]);
        Some([0, 1].map(|k| b[0] * t[0][k] + b[1] * t[1][k] + b[2] * t[2][k]))
    };
    let Ok(rb) = disk_boundary(&rmesh) else { return Vec::new() };
    let mut is_held = vec![false; rmesh.n_vertices()];
    for v in &rb {
        is_held[v.idx()] = true;
    }
    let anchors: Vec<VertexId> = (0..rmesh.n_vertices())
        .map(VertexId::from_idx)
        .filter(|v| !is_held[v.idx()] && is_fixed[rparent[v.idx()].idx()])
        .collect();
    for v in &anchors {
        is_held[v.idx()] = true;
    }
    if is_held.iter().all(|&h| h) {
        return Vec::new();
    }
    let Some(current) = (0..rmesh.n_vertices()).map(|v| uv_of(rparent[v])).collect::<Option<Vec<Uv>>>() else {
        why("image outside the chart");
        return Vec::new();
    };
    if tracing::enabled!(tracing::Level::DEBUG) {
        why(&chart_state(&rmesh, &rb, &current, &is_held, sign));
    }
    let held_vs: Vec<VertexId> = (0..rmesh.n_vertices()).map(VertexId::from_idx).filter(|v| is_held[v.idx()]).collect();
    let tutte = FixedBoundarySystem::new(&rmesh, &held_vs)
        .ok()
        .and_then(|mut sys| sys.factor(&rmesh, Weights::MeanValue).ok()?.solve::<2>(&|v| current[v.idx()]).ok());
    let grid = Grid::new(&chart.uv, &dtris);
    let mut out = Vec::new();
    for start in std::iter::once(Some(current.clone())).chain(std::iter::once(tutte)).flatten() {
        for spread in [false, true] {
            if spread && anchors.is_empty() {
                continue;
            }
            let mut uv = start.clone();
            let mut held = is_held.clone();
            if spread {
                for &h in &anchors {
                    spread_ring(&rmesh, h, &mut uv, &mut held, sign);
                }
            }
            let init = uv.clone();
            let local = kernel_sweeps(&rmesh, &mut uv, &held, sign) || {
                uv.clone_from(&init);
                untangle_planar(&rmesh, &mut uv, &held, sign)
            };
            let mut sols = Vec::new();
            if local {
                sols.push(uv.clone());
            } else {
                uv.clone_from(&init);
            }
            // The global untangler (the costliest): from the tangle when the local moves fail,
            // while such runs are left, else from their valid result, as a lower-distortion
            // second candidate (a valid chart embedding can still lift to a face the evaluator
            // counts as flipped across a crease; kitten -> rocker arm needs it).
            let from_tangle = !local;
            if !from_tangle || *global_left > 0 {
                if from_tangle {
                    *global_left -= 1;
                }
                if foldover_free(&rmesh, &mut uv, &held, sign, &FoldoverFreeOptions::default()).valid {
                    sols.push(uv);
                }
            }
            if sols.is_empty() {
                why(if spread { "no valid embedding (rings spread)" } else { "no valid embedding" });
            }
            for uv in sols {
                // Every face of R must keep the chart's orientation.
                if !(0..rmesh.n_faces())
                    .all(|f| signed_area(rmesh.face(FaceId::from_idx(f)).map(|v| uv[v.idx()])) * sign > 0.0)
                {
                    continue;
                }
                out.push(
                    (0..rmesh.n_vertices())
                        .filter(|&v| !is_held[v])
                        .map(|v| {
                            let (lf, b) = grid.locate(&chart.uv, &dtris, uv[v]);
                            (rparent[v], dfaces[lf as usize], b)
                        })
                        .collect(),
                );
            }
        }
    }
    out
}

/// Re-embeds regions around faces the evaluator counts as folded; `fixed` images never move,
/// nor do the source's boundary vertices.
///
/// Polls `stop` before each region it re-embeds.
///
/// # Errors
/// `Error::Internal` if the target's index cannot be built; `Error::Cancelled` when `stop` is.
pub fn untangle(
    source: &Mesh,
    target: &Mesh,
    map: &mut SurfaceMap,
    fixed: &[VertexId],
    opts: &UntangleOptions,
    stop: &dyn crate::progress::Progress,
) -> Result<UntangleResult> {
    if opts.max_attempts == 0 {
        return Ok(UntangleResult::default());
    }
    let n = source.n_vertices();
    let mut pos: Vec<P3> = (0..n).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    let tn = unit_normals(target);
    // Cheap screen (against the faces the corners lie on), then the evaluator's rule.
    let suspects = fold_suspects(source, map, &pos, &tn);
    let mut rep = UntangleResult::default();
    if suspects.is_empty() {
        return Ok(rep);
    }
    let index = SurfaceIndex::new(target)?;
    let mut near: Vec<FaceId> = map.face.clone();
    for &f in &suspects {
        for w in source.face(f) {
            near[w.idx()] = index.query(&pos[w.idx()]).face;
        }
    }
    let mut folds: Vec<FaceId> =
        suspects.into_iter().filter(|&f| folded(source, &tn, &index, f, &pos, &near)).collect();
    rep.folded_before = folds.len();
    let mut is_fixed = vec![false; n];
    for v in fixed {
        is_fixed[v.idx()] = true;
    }
    for (v, f) in is_fixed.iter_mut().enumerate() {
        *f |= source.is_boundary_vertex(VertexId::from_idx(v));
    }
    // Symmetric Dirichlet energy of faces (a degenerate image counts as very large).
    let scale = (source.area() / target.area().max(f64::MIN_POSITIVE)).sqrt();
    let stretch = |faces: &[FaceId], pos: &[P3]| -> f64 {
        faces
            .iter()
            .map(|&f| {
                super::smooth::SourceFrame::new(source.face_points(f))
                    .and_then(|fr| fr.energy(source.face(f).map(|w| pos[w.idx()]), scale))
                    .unwrap_or(1e30)
            })
            .sum()
    };
    let count = |faces: &[FaceId], pos: &[P3], near: &[FaceId]| {
        faces.iter().filter(|&&f| folded(source, &tn, &index, f, pos, near)).count()
    };
    let mut attempts = 0;
    let mut global_left = opts.max_global;
    // Seeds whose every region size failed are not tried again in later passes.
    let mut hopeless: std::collections::HashSet<FaceId> = std::collections::HashSet::new();
    for _ in 0..opts.passes {
        let mut progress = false;
        for &f in &folds.clone() {
            if hopeless.contains(&f) || !folded(source, &tn, &index, f, &pos, &near) {
                continue;
            }
            let mut fixed_here = false;
            for rings in (2..=opts.max_rings).step_by(2) {
                stop.check()?;
                if attempts >= opts.max_attempts {
                    break;
                }
                attempts += 1;
                let region = fill_holes(source, &grow(source, &[f], rings));
                let judged = grow(source, &region, 1);
                let before = count(&judged, &pos, &near);
                let mut best: Option<Candidate> = None;
                let cands = reembed(source, target, map, &is_fixed, &region, opts.chart_rings, &mut global_left);
                let nc = cands.len();
                let mut afters = Vec::new();
                for moved in cands {
                    let (mut p2, mut n2) = (pos.clone(), near.clone());
                    for &(v, tf, b) in &moved {
                        p2[v.idx()] = SurfacePoint::Face { face: tf, bary: b }.position(target);
                        n2[v.idx()] = index.query(&p2[v.idx()]).face;
                    }
                    let after = count(&judged, &p2, &n2);
                    afters.push(after);
                    let e = stretch(&judged, &p2);
                    if after < before && best.as_ref().is_none_or(|b| (after, e) < (b.folds, b.energy)) {
                        best = Some(Candidate { folds: after, energy: e, pos: p2, near: n2, moves: moved });
                    }
                }
                if tracing::enabled!(tracing::Level::DEBUG) {
                    tracing::debug!(
                        "untangle: seed {} rings {rings}: {} faces, {nc} candidates, folds {before} -> {afters:?}",
                        f.0,
                        region.len()
                    );
                }
                if let Some(c) = best {
                    for (v, tf, b) in c.moves {
                        map.face[v.idx()] = tf;
                        map.bary[v.idx()] = b;
                    }
                    pos = c.pos;
                    near = c.near;
                    rep.regions += 1;
                    progress = true;
                    fixed_here = true;
                    break;
                }
            }
            if !fixed_here && attempts < opts.max_attempts {
                hopeless.insert(f);
            }
        }
        // Re-embedding can leave a fold beside the one it removed: look everywhere again.
        folds = (0..source.n_faces())
            .map(FaceId::from_idx)
            .filter(|&f| folded(source, &tn, &index, f, &pos, &near))
            .collect();
        if !progress || folds.is_empty() {
            break;
        }
    }
    // A region can fold faces just outside the judged ring only through its boundary, which
    // does not move; recount everything that was suspect or moved.
    rep.folded_after =
        (0..source.n_faces()).map(FaceId::from_idx).filter(|&f| folded(source, &tn, &index, f, &pos, &near)).count();
    Ok(rep)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    /// A cluster of images on a sphere mirrored through a plane (a fold several vertices deep,
    /// which no single-vertex move undoes) is re-embedded: no folded face is left, and the
    /// anchor keeps its image.
    #[test]
    fn a_mirrored_cluster_is_unfolded() {
        let s = shapes::icosphere(3);
        let centre = s.position(VertexId(0)).coords;
        let anchor = VertexId(11);
        let pos: Vec<P3> = s
            .positions()
            .iter()
            .map(|p| {
                // Reflect the cap around vertex 0 across the plane through the centre axis.
                if (p.coords - centre).norm() < 0.35 {
                    let axis = V3::new(-centre.y, centre.x, 0.0).normalize();
                    P3::from(p.coords - axis * 2.0 * p.coords.dot(&axis))
                } else {
                    *p
                }
            })
            .collect();
        let mut map = SurfaceMap::from_positions(&pos, &s, None).unwrap();
        let anchor_at = map.position(anchor, &s);
        let r =
            untangle(&s, &s, &mut map, &[anchor], &UntangleOptions::default(), &crate::progress::NoProgress).unwrap();
        assert!(r.folded_before > 3, "{r:?}");
        assert_eq!(r.folded_after, 0, "{r:?}");
        assert!(r.regions >= 1);
        assert!((map.position(anchor, &s) - anchor_at).norm() < 1e-12);
    }
}
