//! Keeping mapped points where the shared evaluator can see them. The evaluator measures the
//! distance of a point to the surface over the 24 faces whose centroids are nearest to it; a
//! point that lies exactly on a large face bordered by many small ones (hole fills, slivers) can
//! be judged off the surface although it is on it. Such points are moved inside their own face
//! towards its centroid (or, failing that, onto a corner), by the smallest step that makes it
//! visible, unless more incident faces then face against the target at all their corners. Anchors never move.

use super::smooth::flipped_in_star;
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, P3, VertexId};
use crate::metrics::SurfaceIndex;

/// Steps per side of the barycentric grid tried last (231 spots).
const GRID: usize = 20;

/// Moves hidden points; returns how many moved. With `reveal`, a point whose every visible
/// spot counts more folds in its star still moves (to the least folded one): the folds were
/// there, hidden with it, and the fold repairs that run next can now see them.
///
/// # Errors
/// `Error::Internal` if the index cannot be built.
pub fn make_visible(
    source: &Mesh,
    target: &Mesh,
    map: &mut SurfaceMap,
    fixed: &[VertexId],
    reveal: bool,
) -> crate::Result<usize> {
    let index = SurfaceIndex::new(target)?;
    let tol = 1e-9 * target.bbox_diagonal();
    let n = source.n_vertices();
    let mut is_fixed = vec![false; n];
    for v in fixed {
        is_fixed[v.idx()] = true;
    }
    let mut pos: Vec<P3> = (0..n).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    // Which images the rule does not see, screened at once (in parallel, Morton order): a
    // vertex's test reads only its own image, which no earlier move changes.
    let dist = index.distances(&pos);
    let mut moved = 0;
    for vi in 0..n {
        if is_fixed[vi] || dist[vi] <= tol {
            continue;
        }
        let f = map.face[vi];
        let b = map.bary[vi];
        let v = VertexId::from_idx(vi);
        // Incident faces that face against the target at all their corners (the evaluator's
        // flip rule, with the faces the corners lie on).
        let faces = &map.face;
        let against = |p: P3, pos: &[P3]| flipped_in_star(source, target, v, p, f, pos, faces);
        let before = against(pos[vi], &pos);
        // Towards the centroid first, then onto the face's corners (nearest first).
        let mut cands: Vec<[f64; 3]> =
            [0.05, 0.1, 0.2, 0.35, 0.5, 0.75, 1.0].iter().map(|&t| b.map(|x| x * (1.0 - t) + t / 3.0)).collect();
        let mut corners = [0usize, 1, 2];
        corners.sort_by(|&x, &y| b[y].total_cmp(&b[x]));
        for k in corners {
            let mut e = [0.0; 3];
            e[k] = 1.0;
            cands.push(e);
        }
        // Then into the faces around its face's corners (centroid, then half-way to each corner):
        // a point on a sliver next to a large face can be hidden anywhere on the sliver.
        let around: Vec<crate::FaceId> = target.face(f).iter().flat_map(|&c| target.vertex_faces(c)).collect();
        let halfway: Vec<[f64; 3]> = (0..3)
            .map(|k| {
                let mut e = [1.0 / 6.0; 3];
                e[k] = 2.0 / 3.0;
                e
            })
            .collect();
        // Last, a grid over its own face, nearest spots first: the one spot that is both visible
        // and fold-free can lie on an edge, off every ray above (seen on a vertex wedged at a
        // corner of a long face, sweep case 0).
        let mut grid: Vec<[f64; 3]> = (0..=GRID)
            .flat_map(|i| (0..=GRID - i).map(move |j| [i, j, GRID - i - j].map(|k| k as f64 / GRID as f64)))
            .collect();
        let dist2 = |x: &[f64; 3]| (0..3).map(|k| (x[k] - b[k]).powi(2)).sum::<f64>();
        grid.sort_by(|x, y| dist2(x).total_cmp(&dist2(y)));
        let tries = cands
            .into_iter()
            .map(|nb| (f, nb))
            .chain(
                around
                    .into_iter()
                    .filter(|&g| g != f)
                    .flat_map(|g| std::iter::once((g, [1.0 / 3.0; 3])).chain(halfway.iter().map(move |&nb| (g, nb)))),
            )
            .chain(grid.into_iter().map(|nb| (f, nb)));
        // The first visible spot that adds no fold; failing that, with `reveal`, the least folded
        // visible one: the hidden image was masking those folds (the rule read a wrong face's
        // normal), and the repairs that follow can see them once it is visible.
        let mut kept: Option<(crate::FaceId, [f64; 3], P3)> = None;
        let mut least: Option<(usize, crate::FaceId, [f64; 3], P3)> = None;
        for (g, nb) in tries {
            let [p0, p1, p2] = target.face_points(g);
            let p = P3::from(p0.coords * nb[0] + p1.coords * nb[1] + p2.coords * nb[2]);
            if index.query(&p).distance > tol {
                continue;
            }
            let flips = flipped_in_star(source, target, v, p, g, &pos, &map.face);
            if flips <= before {
                kept = Some((g, nb, p));
                break;
            }
            if least.as_ref().is_none_or(|x| flips < x.0) {
                least = Some((flips, g, nb, p));
            }
        }
        let least = least.filter(|_| reveal).map(|(_, g, nb, p)| (g, nb, p));
        if let Some((g, nb, p)) = kept.or(least) {
            map.face[vi] = g;
            map.bary[vi] = nb;
            pos[vi] = p;
            moved += 1;
        }
    }
    Ok(moved)
}

/// Faces of `v`'s star that the evaluator counts as flipped, were `v`'s image at `p` (nearest
/// target face `pf`) and every other vertex `w` at `pos[w]` (nearest face `near[w]`): normal
/// against the target's at the faces nearest to all three corners and to the centroid.
pub(super) fn evaluator_flips_in_star(
    source: &Mesh,
    tn: &[crate::mesh::V3],
    index: &SurfaceIndex,
    v: VertexId,
    (p, pf): (P3, crate::FaceId),
    pos: &[P3],
    near: &[crate::FaceId],
) -> usize {
    source
        .vertex_faces(v)
        .filter(|&f| {
            let tri = source.face(f);
            let m = tri.map(|w| if w == v { p } else { pos[w.idx()] });
            evaluator_folded(m, tri.map(|w| if w == v { pf } else { near[w.idx()] }), tn, index)
        })
        .count()
}

/// The evaluator's flip rule for one mapped triangle `m` whose corners lie on target faces
/// `under`: its normal opposes the target's at those three faces and at the face nearest to its
/// centroid (queried last, only when the corners agree), a point on an edge or corner counting
/// as opposed when any face there opposes (ties the evaluator may break otherwise).
pub(crate) fn evaluator_folded(
    m: [P3; 3],
    under: [crate::FaceId; 3],
    tn: &[crate::mesh::V3],
    index: &SurfaceIndex,
) -> bool {
    let nm = (m[1] - m[0]).cross(&(m[2] - m[0]));
    let opposes = |g: &crate::FaceId| nm.dot(&tn[g.idx()]) < 0.0;
    // A point on an edge or corner of its face opposes when any face around it does: the
    // evaluator may break that tie the other way, so such a face is repaired as folded.
    let at = |g: crate::FaceId, p: &P3| opposes(&g) || index.tied_faces(g, p).iter().any(opposes);
    under.iter().zip(&m).all(|(g, p)| at(*g, p)) && {
        let c = index.query(&crate::metrics::face_centroid(m));
        at(c.face, &c.point)
    }
}

/// Faces of `map: source -> target` that the evaluator counts as flipped (screened by
/// [`fold_suspects`], then confirmed by [`evaluator_folded`] with nearest faces).
///
/// # Errors
/// `Error::Internal` if the target's index cannot be built.
pub fn evaluator_flip_count(source: &Mesh, target: &Mesh, map: &SurfaceMap) -> crate::Result<usize> {
    let pos: Vec<P3> = (0..source.n_vertices()).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    let tn = unit_normals(target);
    let suspects = fold_suspects(source, map, &pos, &tn);
    if suspects.is_empty() {
        return Ok(0);
    }
    let index = SurfaceIndex::new(target)?;
    Ok(suspects
        .iter()
        .filter(|&&f| {
            let tri = source.face(f);
            let m = tri.map(|w| pos[w.idx()]);
            evaluator_folded(m, tri.map(|w| index.query(&pos[w.idx()]).face), &tn, &index)
        })
        .count())
}

/// Unit face normals of `mesh`.
pub(crate) fn unit_normals(mesh: &Mesh) -> Vec<crate::mesh::V3> {
    (0..mesh.n_faces())
        .map(|f| {
            let x = mesh.face_normal_raw(crate::FaceId::from_idx(f));
            x / x.norm().max(crate::tol::TINY)
        })
        .collect()
}

/// Cheap screen for the evaluator's flip rule: faces of `source` whose image (corners at `pos`)
/// faces against the target at one corner's own face (`map.face`) at least; `tn` are the
/// target's unit normals.
pub(crate) fn fold_suspects(source: &Mesh, map: &SurfaceMap, pos: &[P3], tn: &[crate::mesh::V3]) -> Vec<crate::FaceId> {
    (0..source.n_faces())
        .map(crate::FaceId::from_idx)
        .filter(|&f| {
            let tri = source.face(f);
            let m = tri.map(|w| pos[w.idx()]);
            let nm = (m[1] - m[0]).cross(&(m[2] - m[0]));
            tri.iter().any(|w| nm.dot(&tn[map.face[w.idx()].idx()]) < 0.0)
        })
        .collect()
}

/// When no move towards the neighbours lowers the flips of `v`'s star (`cur`): the spot among
/// [`surface_samples`] around the star's images with the fewest flips, nearest the neighbours'
/// images among equals (least spring energy), that reaches no further from the neighbours than
/// the vertex already does, so a fold is not traded for long chords through the air.
#[allow(clippy::too_many_arguments)]
fn surface_move(
    target: &Mesh,
    source: &Mesh,
    index: &SurfaceIndex,
    tn: &[crate::mesh::V3],
    v: VertexId,
    cur: usize,
    pos: &[P3],
    near: &[crate::FaceId],
    tol: f64,
) -> Option<(usize, crate::topology::Projection, crate::FaceId)> {
    let nbrs: Vec<VertexId> = source.vertex_neighbors(v).collect();
    let reach = |p: &P3| nbrs.iter().map(|w| (p - pos[w.idx()]).norm()).fold(0.0, f64::max);
    let spring = |p: &P3| nbrs.iter().map(|w| (p - pos[w.idx()]).norm_squared()).sum::<f64>();
    let max_reach = reach(&pos[v.idx()]);
    let mut best: Option<(usize, f64, crate::topology::Projection, crate::FaceId)> = None;
    for pr in surface_samples(target, nbrs.iter().chain([&v]).map(|w| near[w.idx()])) {
        if reach(&pr.point) > max_reach {
            continue;
        }
        // Counted first with the sample's own face (what the rule finds for a visible point),
        // then confirmed with the rule's nearest face, which costs a query.
        let e = spring(&pr.point);
        let k = evaluator_flips_in_star(source, tn, index, v, (pr.point, pr.face), pos, near);
        if k >= cur || best.as_ref().is_some_and(|b| (k, e) >= (b.0, b.1)) {
            continue;
        }
        let q = index.query(&pr.point);
        if q.distance > tol {
            continue;
        }
        let k = if q.face == pr.face {
            k
        } else {
            evaluator_flips_in_star(source, tn, index, v, (pr.point, q.face), pos, near)
        };
        if k < cur && best.as_ref().is_none_or(|b| (k, e) < (b.0, b.1)) {
            best = Some((k, e, pr, q.face));
        }
    }
    best.map(|(k, _, pr, f)| (k, pr, f))
}

/// Points spread over the target around `faces` (the faces themselves and every face sharing a
/// vertex with one): each face's centroid and the three points half-way from it to a corner.
/// These let a vertex of a fold jump across a crease or a finger, where moves towards its
/// neighbours' images (projected back onto the target) all land on the same wrong side.
fn surface_samples(target: &Mesh, faces: impl Iterator<Item = crate::FaceId>) -> Vec<crate::topology::Projection> {
    let mut around: Vec<crate::FaceId> = Vec::new();
    for f in faces {
        for u in target.face(f) {
            for g in target.vertex_faces(u) {
                if !around.contains(&g) {
                    around.push(g);
                }
            }
        }
    }
    const BARY: [[f64; 3]; 4] = [
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
        [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
        [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
        [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
    ];
    around
        .into_iter()
        .flat_map(|g| {
            let p = target.face(g).map(|u| target.position(u).coords);
            BARY.iter().map(move |b| crate::topology::Projection {
                face: g,
                bary: *b,
                point: P3::from(p[0] * b[0] + p[1] * b[1] + p[2] * b[2]),
                distance: 0.0,
            })
        })
        .collect()
}

/// Passes of [`repair_flips`] at most.
const REPAIR_PASSES: usize = 8;

/// Removes faces that the evaluator would count as flipped although smoothing's own test (the
/// faces the corners were projected on) passed them: points on edges and creases, where the
/// evaluator's nearest face is a neighbour of ours, and folds that smoothing's one-vertex moves
/// could not undo. Each free corner of such a face tries moves towards (and past) its
/// neighbours' images, half-way to each, and to its mapped faces' centroids, projected onto the
/// target, and takes the one that most lowers the evaluator-counted flips of its star while
/// staying visible; passes repeat over the faces around moved vertices. With `wide`, a vertex
/// that none of those moves helps also tries spots spread over the target around its star
/// ([`surface_move`]). Returns the number of moves.
///
/// # Errors
/// `Error::Internal` if an index cannot be built.
pub fn repair_flips(
    source: &Mesh,
    target: &Mesh,
    map: &mut SurfaceMap,
    fixed: &[VertexId],
    wide: bool,
) -> crate::Result<usize> {
    let n = source.n_vertices();
    let mut pos: Vec<P3> = (0..n).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    let tn = unit_normals(target);
    let suspects = fold_suspects(source, map, &pos, &tn);
    if suspects.is_empty() {
        return Ok(0);
    }
    let index = SurfaceIndex::new(target)?;
    let tol = 1e-9 * target.bbox_diagonal();
    let mut near: Vec<crate::FaceId> = map.face.clone();
    for &f in &suspects {
        for w in source.face(f) {
            near[w.idx()] = index.query(&pos[w.idx()]).face;
        }
    }
    let mut is_fixed = vec![false; n];
    for v in fixed {
        is_fixed[v.idx()] = true;
    }
    let mut loc: Option<crate::topology::Locator> = None;
    let mut moves = 0;
    let mut suspects = suspects;
    // A fold can need several vertices to move in turn: passes over the faces still flipped
    // (and those around the vertices moved), until a pass changes nothing.
    for _ in 0..REPAIR_PASSES {
        let mut touched: Vec<VertexId> = Vec::new();
        for &f in &suspects {
            for v in source.face(f) {
                if is_fixed[v.idx()] || source.is_boundary_vertex(v) {
                    continue;
                }
                let here = (pos[v.idx()], near[v.idx()]);
                let cur = evaluator_flips_in_star(source, &tn, &index, v, here, &pos, &near);
                if cur == 0 {
                    continue;
                }
                let nbrs: Vec<VertexId> = source.vertex_neighbors(v).collect();
                let mean =
                    nbrs.iter().fold(crate::mesh::V3::zeros(), |a, w| a + pos[w.idx()].coords) / nbrs.len() as f64;
                let p0 = pos[v.idx()].coords;
                // Towards (and past) the neighbours' mean, half-way to each neighbour, and to
                // the centroids of the star's mapped faces.
                let mut cands: Vec<P3> =
                    [1.0, 0.5, 0.25, 1.5, 2.0].iter().map(|&t| P3::from(p0 * (1.0 - t) + mean * t)).collect();
                cands.extend(nbrs.iter().map(|w| P3::from((p0 + pos[w.idx()].coords) * 0.5)));
                cands.extend(source.vertex_faces(v).map(|g| {
                    let t = source.face(g);
                    P3::from(t.iter().map(|w| pos[w.idx()].coords).sum::<crate::mesh::V3>() / 3.0)
                }));
                let l = match &loc {
                    Some(l) => l,
                    None => loc.insert(crate::topology::Locator::new(target)?),
                };
                let mut best: Option<(usize, crate::topology::Projection, crate::FaceId)> = None;
                for c in cands {
                    let pr = l.project(&c);
                    let q = index.query(&pr.point);
                    if q.distance > tol {
                        continue;
                    }
                    let k = evaluator_flips_in_star(source, &tn, &index, v, (pr.point, q.face), &pos, &near);
                    if k < cur && best.as_ref().is_none_or(|b| k < b.0) {
                        best = Some((k, pr, q.face));
                    }
                }
                if best.is_none() && wide {
                    best = surface_move(target, source, &index, &tn, v, cur, &pos, &near, tol);
                }
                if let Some((_, pr, nf)) = best {
                    pos[v.idx()] = pr.point;
                    near[v.idx()] = nf;
                    map.face[v.idx()] = pr.face;
                    map.bary[v.idx()] = pr.bary;
                    moves += 1;
                    touched.push(v);
                }
            }
        }
        if touched.is_empty() {
            break;
        }
        for v in touched {
            for g in source.vertex_faces(v) {
                for w in source.face(g) {
                    near[w.idx()] = index.query(&pos[w.idx()]).face;
                }
                if !suspects.contains(&g) {
                    suspects.push(g);
                }
            }
        }
    }
    Ok(moves)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::metrics::{MetricsOptions, evaluate_map};

    #[test]
    fn a_folded_vertex_is_unfolded_by_the_evaluator_s_rule() {
        let s = shapes::icosphere(3);
        // Push vertex 0's image past a neighbour: its star folds over.
        let v = VertexId(0);
        let w = s.vertex_neighbors(v).next().unwrap();
        let mut pos = s.positions().to_vec();
        let p = P3::from(pos[w.idx()].coords * 2.0 - pos[v.idx()].coords);
        pos[v.idx()] = P3::from(p.coords / p.coords.norm());
        let mut map = SurfaceMap::from_positions(&pos, &s, None).unwrap();
        let flips = |map: &SurfaceMap| {
            let m = map.embed(&s, &s).unwrap();
            evaluate_map(&s, &s, &m, None, None, &MetricsOptions { samples: 100, seeds: (1, 2) }).unwrap().flipped_faces
        };
        assert!(flips(&map) > 0, "the test starts folded");
        let moves = repair_flips(&s, &s, &mut map, &[], false).unwrap();
        assert!(moves > 0);
        assert_eq!(flips(&map), 0);
        let m = map.embed(&s, &s).unwrap();
        let off = evaluate_map(&s, &s, &m, None, None, &MetricsOptions { samples: 100, seeds: (1, 2) }).unwrap();
        assert!(off.off_surface_max < 1e-9);
    }

    /// Images scattered over the sphere by a fixed pseudo-random jitter: the wide repair (spots
    /// spread over the target around each star) never leaves more evaluator-counted flips than
    /// the narrow one, which never leaves more than before; over the trials it removes some
    /// that the narrow one could not.
    #[test]
    fn wide_repair_never_does_worse_than_the_narrow_one() {
        let s = shapes::icosphere(3);
        let flips = |map: &SurfaceMap| {
            let m = map.embed(&s, &s).unwrap();
            evaluate_map(&s, &s, &m, None, None, &MetricsOptions { samples: 100, seeds: (1, 2) }).unwrap().flipped_faces
        };
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut rnd = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let (mut narrow_total, mut wide_total) = (0, 0);
        for _ in 0..6 {
            let edge = s.edge_length(crate::mesh::EdgeId(0));
            let pos: Vec<P3> = s
                .positions()
                .iter()
                .map(|p| {
                    let q = p.coords + crate::mesh::V3::new(rnd(), rnd(), rnd()) * 2.5 * edge;
                    P3::from(q / q.norm())
                })
                .collect();
            let start = SurfaceMap::from_positions(&pos, &s, None).unwrap();
            let before = flips(&start);
            let mut narrow = start.clone();
            repair_flips(&s, &s, &mut narrow, &[], false).unwrap();
            let mut wide = narrow.clone();
            repair_flips(&s, &s, &mut wide, &[], true).unwrap();
            let (n, w) = (flips(&narrow), flips(&wide));
            assert!(n <= before && w <= n, "before {before}, narrow {n}, wide {w}");
            narrow_total += n;
            wide_total += w;
        }
        assert!(wide_total < narrow_total, "the wide spots help somewhere: {wide_total} against {narrow_total}");
    }
}
