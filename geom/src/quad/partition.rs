//! Consistent partition of a genus-0 mesh into two quad patches (Yu & Chuang, section 3.2):
//! shortest edge paths p0 -> p1 -> p2 -> p3 -> p0 between the four partition points, each kept
//! vertex-disjoint from the ones before (so the loop is simple and cannot cross itself), cut the
//! closed surface into two disks. Edges between two loop vertices that are not loop edges
//! (chords) are split first, so no patch triangle has all three corners on its boundary, which
//! the unit square would flatten. Refinement only adds edge midpoints: the surface is unchanged.

use super::layout::{QuadLayout, SQUARE};
use crate::error::{Error, InputError, Result};
use crate::geodesic::{VertexDijkstraOptions, vertex_dijkstra};
use crate::mesh::cut::{cut_along, path_edges};
use crate::mesh::refine::Refined;
use crate::mesh::{FaceId, Mesh, VertexId};
use crate::param::{Uv, disk_boundary};
use crate::topology::components;

/// Options of [`partition_genus0`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartitionOptions {
    /// Global midpoint subdivisions allowed when the four paths cannot be kept disjoint.
    pub max_subdivisions: usize,
}

impl Default for PartitionOptions {
    fn default() -> Self {
        Self { max_subdivisions: 2 }
    }
}

/// One quad patch of one model, as its own disk mesh.
#[derive(Debug, Clone)]
pub struct PatchMesh {
    pub mesh: Mesh,
    /// Per local vertex: its vertex in the refined model.
    pub parent: Vec<VertexId>,
    /// Per local vertex: its fixed unit-square position if it is on the patch boundary (by arc
    /// length along the layout curve, the same fractions on both patches that share it).
    pub boundary_uv: Vec<Option<Uv>>,
    /// Local ids of the four corners.
    pub corners: [VertexId; 4],
    /// (feature index, local vertex) of the feature points inside this patch.
    pub features: Vec<(usize, VertexId)>,
}

/// A model cut into the patches of [`QuadLayout::genus0`].
#[derive(Debug, Clone)]
pub struct PartitionResult {
    /// The model after chord splits and subdivisions (a geometric no-op).
    pub refined: Refined,
    /// The layout curves as vertex paths of the refined model.
    pub curves: Vec<Vec<VertexId>>,
    pub patches: Vec<PatchMesh>,
    /// Global subdivisions that were needed.
    pub subdivisions: usize,
}

/// Partitions a closed genus-0 mesh by four partition points; `features` stay off the loop.
///
/// # Errors
/// `InputError::Anchors` for repeated points, `InputError::LayoutConflict` when disjoint paths
/// cannot be found even after subdivision.
pub fn partition_genus0(
    mesh: &Mesh,
    points: [VertexId; 4],
    features: &[VertexId],
    opts: &PartitionOptions,
) -> Result<PartitionResult> {
    partition_genus0_sided(mesh, points, features, None, opts)
}

/// [`partition_genus0`] with the patch each feature must fall in (`want[k]` = 0 or 1, as
/// on another model): curves that pass a feature on the wrong side are re-traced around it
/// ([`super::sides::reroute`]).
///
/// # Errors
/// As [`partition_genus0`]; `LayoutConflict` when a feature cannot be brought to its side.
pub fn partition_genus0_sided(
    mesh: &Mesh,
    points: [VertexId; 4],
    features: &[VertexId],
    want: Option<&[usize]>,
    opts: &PartitionOptions,
) -> Result<PartitionResult> {
    for (i, p) in points.iter().enumerate() {
        if p.idx() >= mesh.n_vertices() {
            return Err(
                InputError::OutOfRange { what: "partition point", index: p.idx(), count: mesh.n_vertices() }.into()
            );
        }
        if points[..i].contains(p) || features.contains(p) {
            return Err(InputError::Anchors(format!("partition point {i} (vertex {}) is used twice", p.0)).into());
        }
    }
    let mut refined = Refined::identity(mesh);
    let mut stuck = None;
    for round in 0..=opts.max_subdivisions {
        let traced = trace_loop(&refined.mesh, points, features)?;
        let found = match (traced, want) {
            (traced, None) => traced,
            (Some(curves), Some(w)) => match fix_sides(&refined.mesh, curves.clone(), features, w)? {
                Ok(curves) => Some(curves),
                Err(k) => {
                    stuck = Some(k);
                    super::separate::separating_loop(&refined.mesh, points, features, w, Some(&curves))?
                }
            },
            (None, Some(w)) => super::separate::separating_loop(&refined.mesh, points, features, w, None)?,
        };
        if let Some(curves) = found {
            tracing::debug!(
                "partition: round {round}, loop of {} vertices",
                curves.iter().map(Vec::len).sum::<usize>()
            );
            return finish(refined, curves, points, features, round);
        }
        if round < opts.max_subdivisions {
            refined = refined.subdivide()?;
        }
    }
    let side = |p: usize| if p == 0 { "patch 0, left of p0->p1" } else { "patch 1, right of p0->p1" };
    Err(InputError::LayoutConflict(match (stuck, want) {
        (Some(k), Some(w)) => format!(
            "feature point {k} (anchor row {}, vertex {}) must lie in {} as on the first model, but no loop \
             through the partition points p0->p1->p2->p3->p0 keeps it there with every other feature on its \
             side (after {} subdivisions); move that feature point or a partition point",
            k + 4,
            features[k].0,
            side(w[k]),
            opts.max_subdivisions
        ),
        _ => format!(
            "the partition points cannot be joined by disjoint paths p0->p1->p2->p3->p0 that stay a vertex \
             away from every feature point (after {} subdivisions); move a partition point",
            opts.max_subdivisions
        ),
    })
    .into())
}

/// Re-traces curves until every feature lies in its wanted patch; `Err(k)` names a feature
/// that could not be brought to its side.
fn fix_sides(
    mesh: &Mesh,
    mut curves: Vec<Vec<VertexId>>,
    features: &[VertexId],
    want: &[usize],
) -> Result<std::result::Result<Vec<Vec<VertexId>>, usize>> {
    let mut last = 0;
    for _ in 0..2 * features.len() + 1 {
        let left = super::sides::left_faces(mesh, &curves)?;
        let wrong =
            (0..features.len()).find(|&k| super::sides::vertex_left(mesh, &left, features[k]) != (want[k] == 0));
        let Some(k) = wrong else { return Ok(Ok(curves)) };
        last = k;
        match super::sides::reroute(mesh, &curves, features[k], features)? {
            Some(c) => curves = c,
            None => {
                tracing::debug!("feature {k} at vertex {} cannot be re-routed to its side", features[k].0);
                return Ok(Err(k));
            }
        }
    }
    Ok(Err(last))
}

/// The four paths, or `None` when one is walled off by the ones before.
fn trace_loop(mesh: &Mesh, points: [VertexId; 4], features: &[VertexId]) -> Result<Option<Vec<Vec<VertexId>>>> {
    let mut blocked = super::sides::feature_rings(mesh, features);
    for v in points {
        blocked[v.idx()] = true;
    }
    let mut curves = Vec::with_capacity(4);
    for k in 0..4 {
        let (a, b) = (points[k], points[(k + 1) % 4]);
        let opts = VertexDijkstraOptions { target: Some(b), blocked: Some(&blocked), ..Default::default() };
        let r = vertex_dijkstra(mesh, &[(a, 0.0)], &opts)?;
        let Some(path) = r.path_to(b) else { return Ok(None) };
        for v in &path {
            blocked[v.idx()] = true;
        }
        curves.push(path);
    }
    Ok(Some(curves))
}

fn finish(
    refined: Refined,
    curves: Vec<Vec<VertexId>>,
    points: [VertexId; 4],
    features: &[VertexId],
    subdivisions: usize,
) -> Result<PartitionResult> {
    // Split chords: interior edges with both ends on the loop.
    let mut on_loop = vec![false; refined.mesh.n_vertices()];
    for c in &curves {
        for v in c {
            on_loop[v.idx()] = true;
        }
    }
    let loop_edges = path_edges(&refined.mesh, &curves)?;
    let chords: Vec<[VertexId; 2]> = (0..refined.mesh.n_edges())
        .filter(|&e| !loop_edges[e])
        .map(|e| refined.mesh.edge_vertices(crate::EdgeId::from_idx(e)))
        .filter(|[a, b]| on_loop[a.idx()] && on_loop[b.idx()])
        .collect();
    let refined = refined.split_edges(&chords)?;
    let mesh = &refined.mesh;
    let cut_flags = path_edges(mesh, &curves)?;
    let cut = cut_along(mesh, &cut_flags)?;
    let comps = components(&cut.mesh);
    if comps.count != 2 {
        return Err(Error::Internal(format!("the partition loop left {} pieces, not 2", comps.count)));
    }
    // Patch 0 lies left of p0 -> p1 (faces are counter-clockwise seen from outside).
    let h = mesh
        .find_halfedge(curves[0][0], curves[0][1])
        .ok_or_else(|| Error::Internal("first loop edge has no half-edge".into()))?;
    let first = comps.face_label[h.face().idx()];
    // Arc-length fraction of every loop vertex along its curve (corners excepted).
    let mut frac = vec![(u32::MAX, 0.0); mesh.n_vertices()];
    for (c, path) in curves.iter().enumerate() {
        let mut cum = vec![0.0; path.len()];
        for i in 1..path.len() {
            cum[i] = cum[i - 1] + (mesh.position(path[i]) - mesh.position(path[i - 1])).norm();
        }
        let total = cum[path.len() - 1].max(f64::MIN_POSITIVE);
        for i in 1..path.len() - 1 {
            frac[path[i].idx()] = (c as u32, cum[i] / total);
        }
    }
    let layout = QuadLayout::genus0();
    let mut patches = Vec::with_capacity(2);
    for (pi, pl) in layout.patches.iter().enumerate() {
        let label = if pi == 0 { first } else { 1 - first };
        let corners = pl.corners.map(|c| points[c as usize]);
        patches.push(extract_patch(mesh, &cut, &comps.face_label, label, corners, pl, &frac, features)?);
    }
    Ok(PartitionResult { refined, curves, patches, subdivisions })
}

#[allow(clippy::too_many_arguments)]
fn extract_patch(
    mesh: &Mesh,
    cut: &crate::mesh::cut::CutMesh,
    face_label: &[u32],
    label: u32,
    corners: [VertexId; 4],
    pl: &super::layout::QuadPatchLayout,
    frac: &[(u32, f64)],
    features: &[VertexId],
) -> Result<PatchMesh> {
    let mut local = vec![u32::MAX; cut.mesh.n_vertices()];
    let mut parent = Vec::new();
    let mut tris = Vec::new();
    for (f, &l) in face_label.iter().enumerate() {
        if l != label {
            continue;
        }
        let t = cut.mesh.face(FaceId::from_idx(f)).map(|v| {
            if local[v.idx()] == u32::MAX {
                local[v.idx()] = parent.len() as u32;
                parent.push(cut.orig[v.idx()]);
            }
            local[v.idx()]
        });
        tris.push(t);
    }
    let pos = parent.iter().map(|&v| mesh.position(v)).collect();
    let pmesh = Mesh::from_triangles(pos, &tris).map_err(|e| Error::Internal(format!("patch mesh invalid: {e}")))?;
    let find = |v: VertexId| parent.iter().position(|&p| p == v).map(VertexId::from_idx);
    let local_corners = corners.map(find);
    let [Some(c0), Some(c1), Some(c2), Some(c3)] = local_corners else {
        return Err(Error::Internal("a patch misses one of its corners".into()));
    };
    let lc = [c0, c1, c2, c3];
    let mut lp = disk_boundary(&pmesh)?;
    let start = lp.iter().position(|&v| v == c0).ok_or_else(|| Error::Internal("corner 0 off the boundary".into()))?;
    lp.rotate_left(start);
    let mut boundary_uv = vec![None; parent.len()];
    let mut k = 0usize;
    for &v in &lp {
        if let Some(j) = lc.iter().position(|&c| c == v) {
            if j != k && !(j == k + 1 && k < 3) {
                return Err(Error::Internal(format!("patch corners out of order on its boundary ({k} then {j})")));
            }
            k = j;
            boundary_uv[v.idx()] = Some(SQUARE[j]);
            continue;
        }
        let (c, t) = frac[parent[v.idx()].idx()];
        let side = pl.sides[k];
        if c != side.curve {
            return Err(Error::Internal(format!("boundary vertex on curve {c}, expected curve {}", side.curve)));
        }
        let s = if side.reversed { 1.0 - t } else { t };
        let (a, b) = (SQUARE[k], SQUARE[(k + 1) % 4]);
        boundary_uv[v.idx()] = Some([a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1])]);
    }
    if k != 3 {
        return Err(Error::Internal(format!("patch boundary passes {} corners, not 4", k + 1)));
    }
    let features =
        features.iter().enumerate().filter_map(|(i, &f)| find(f).map(|l| (i, l))).collect::<Vec<(usize, VertexId)>>();
    Ok(PatchMesh { mesh: pmesh, parent, boundary_uv, corners: lc, features })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::topology::euler_characteristic;

    use crate::mesh::shapes::extreme_vertex as extreme;

    #[test]
    fn sphere_splits_into_two_quads_with_fixed_square_boundaries() {
        let m = shapes::icosphere(3);
        let pts = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, -1.0, 0.0]].map(|d| extreme(&m, d));
        let r = partition_genus0(&m, pts, &[], &Default::default()).unwrap();
        assert_eq!(r.patches.len(), 2);
        let total: usize = r.patches.iter().map(|p| p.mesh.n_faces()).sum();
        assert_eq!(total, r.refined.mesh.n_faces(), "the patches cover the surface once");
        for p in &r.patches {
            assert_eq!(euler_characteristic(&p.mesh), 1, "a disk");
            for (k, c) in p.corners.iter().enumerate() {
                assert_eq!(p.boundary_uv[c.idx()], Some(SQUARE[k]));
            }
            // Every boundary vertex is on the square's boundary, every interior one is free.
            for v in 0..p.mesh.n_vertices() {
                let b = p.mesh.is_boundary_vertex(VertexId::from_idx(v));
                assert_eq!(b, p.boundary_uv[v].is_some());
                if let Some([u, w]) = p.boundary_uv[v] {
                    assert!(u == 0.0 || u == 1.0 || w == 0.0 || w == 1.0);
                }
            }
            // No triangle with three boundary corners (it would be flat in the square).
            for t in p.mesh.faces() {
                assert!(t.iter().any(|v| p.boundary_uv[v.idx()].is_none()));
            }
        }
    }

    #[test]
    fn a_feature_is_brought_to_the_wanted_side() {
        let m = shapes::icosphere(4);
        let pts = [[1.0, 0.0, 0.1], [0.0, 1.0, 0.0], [-1.0, 0.0, -0.1], [0.0, -1.0, 0.0]].map(|d| extreme(&m, d));
        let f = extreme(&m, [0.3, 0.3, 1.0]);
        let r = partition_genus0(&m, pts, &[f], &Default::default()).unwrap();
        let side = r.patches.iter().position(|p| !p.features.is_empty()).unwrap();
        let r2 = partition_genus0_sided(&m, pts, &[f], Some(&[1 - side]), &Default::default()).unwrap();
        assert_eq!(r2.patches[1 - side].features.len(), 1, "rerouted around the feature");
        assert!(r2.patches[side].features.is_empty());
    }
}
