//! Feature curves on closed surfaces with handles (genus g ≥ 1; Carner et al. section 3.4 with
//! section 3.2's basis): the double cover along `n` curves has genus `2g + n − 1`, and its
//! σ-symmetric cut is the canonical basis through the base vertex plus the genus-0 chain.
//!
//! On each mesh the canonical basis is searched with the curves as walls
//! ([`canonical_basis_avoiding`]), so the loops meet them nowhere and the disk `D` it cuts holds
//! every curve inside. `D` is a genus-0 surface with one boundary loop (the 4g-gon
//! `a1 b1 a1⁻¹ b1⁻¹ …`), so [`feature_cut`] opens it along the slits and a chain
//! `F1 → … → Fn → corner` (`Fn` the curve nearest the base, [`chain_order_to_base`]), arriving
//! at the base copy that starts side 0 on the source and side `shift` on the target (τ). The loop side is then split at the base's copies into
//! `4g` sides ([`SideKind::Basis`]), so the shared circle puts the polygon's corners at the same
//! angles on both meshes and each loop's two copies on arcs of the same size, laid out by arc
//! length from opposite ends: the two copies of a loop point are mirror images, as on the
//! 4g-gon. The rest is the genus-0 feature map on the circle (curve alignment, anchor warp,
//! composition, boundary snapping), through the basis's refinement.

use super::basis::{CanonicalBasisOptions, CanonicalBasisResult, canonical_basis_avoiding};
use super::feature_cut::{FeatureCutResult, Side, SideKind, chain_order_to_base, feature_cut};
use super::features::{Curve, CurveKind, doubled_genus};
use crate::error::{Error, InputError, Result};
use crate::mesh::cut::CutMesh;
use crate::mesh::{Mesh, VertexId};

/// One mesh's basis (with the curves on its refinement) and the disk cut along it.
struct Handles {
    basis: CanonicalBasisResult,
    curves: Vec<Vec<VertexId>>,
}

/// Both bases, searched with the curves as walls and refined alike (the one found earlier is
/// searched again up to the other's attempt, as in [`super::map::homology_map`]).
///
/// # Errors
/// As [`canonical_basis_avoiding`].
fn both_bases(
    meshes: [&Mesh; 2],
    bases: [VertexId; 2],
    index: [usize; 2],
    curves: [&[Curve]; 2],
    max_subdivisions: Option<usize>,
    min_attempt: usize,
) -> Result<[Handles; 2]> {
    let side = |k: usize, min_attempt: usize| -> Result<Handles> {
        let mut o = CanonicalBasisOptions { basis_index: index[k], min_attempt, ..Default::default() };
        if let Some(m) = max_subdivisions {
            o.max_subdivisions = m;
        }
        let avoid: Vec<Vec<VertexId>> = curves[k].iter().map(|c| c.vertices.clone()).collect();
        let (basis, curves) = canonical_basis_avoiding(meshes[k], bases[k], &o, &avoid)?;
        Ok(Handles { basis, curves })
    };
    let (s, t) = std::thread::scope(|sc| {
        let h = sc.spawn(|| side(1, min_attempt));
        (side(0, min_attempt), h.join())
    });
    let (mut s, mut t) = (s?, t.map_err(|_| Error::Internal("target basis thread panicked".into()))??);
    for _ in 0..3 {
        let (a, b) = (s.basis.attempt, t.basis.attempt);
        if a == b {
            break;
        }
        if a < b {
            s = side(0, b)?;
        } else {
            t = side(1, a)?;
        }
    }
    Ok([s, t])
}

/// The cut of one mesh: its basis disk opened along the curves and the chain, which arrives at
/// the base copy starting polygon side `corner`; returned with `orig` into the basis's
/// refinement, curves and links in its vertex ids, and the loop side split into `4g` sides.
///
/// # Errors
/// As [`feature_cut`]; `Internal` when the split does not give `4g` sides.
fn handle_cut(h: &Handles, order: &[(usize, bool)], corner: usize) -> Result<FeatureCutResult> {
    let b = &h.basis;
    let d = &b.disk;
    let mut copy = vec![u32::MAX; b.refined.mesh.n_vertices()];
    for (v, o) in d.orig.iter().enumerate() {
        if !d.mesh.is_boundary_vertex(VertexId::from_idx(v)) {
            copy[o.idx()] = v as u32;
        }
    }
    let in_disk: Vec<Curve> = h
        .curves
        .iter()
        .map(|c| {
            let vertices = c.iter().map(|v| VertexId(copy[v.idx()])).collect::<Vec<_>>();
            if vertices.iter().any(|v| v.0 == u32::MAX) {
                return Err(Error::Internal("feature handles: a curve touches a basis loop".into()));
            }
            Ok(Curve { vertices, kind: CurveKind::Open })
        })
        .collect::<Result<_>>()?;
    let start = b.walk[b.corners[corner % b.corners.len()]];
    let mut fc = feature_cut(&d.mesh, &in_disk, order, None, Some(start))?;
    let n = in_disk.len();
    // Everything back in the refinement's ids.
    let up = |v: &VertexId| d.orig[v.idx()];
    fc.disk = CutMesh { orig: fc.disk.orig.iter().map(up).collect(), mesh: fc.disk.mesh };
    fc.curves.truncate(n);
    for c in &mut fc.curves {
        c.vertices = c.vertices.iter().map(up).collect();
    }
    for l in &mut fc.links {
        *l = l.iter().map(up).collect();
    }
    fc.base = up(&fc.base);
    fc.sides = split_loop_side(&fc, n, b.base, b.corners.len())?;
    fc.doubled_genus = doubled_genus(b.genus(), n);
    Ok(fc)
}

/// `fc.sides` with side `Curve(loop_index)` (the polygon's boundary, from the pinned corner)
/// split at every copy of `base` into `Basis(0..m)`.
///
/// # Errors
/// `Internal` when the loop side does not split into `m` sides.
fn split_loop_side(fc: &FeatureCutResult, loop_index: usize, base: VertexId, m: usize) -> Result<Vec<Side>> {
    let w = &fc.walk;
    let at = |i: usize| fc.disk.orig[w[i % w.len()].idx()];
    let pos = |i: usize| fc.disk.mesh.position(w[i % w.len()]);
    let mut out = Vec::with_capacity(fc.sides.len() + m);
    for s in &fc.sides {
        if s.kind != SideKind::Curve(loop_index) {
            out.push(*s);
            continue;
        }
        let end = s.start + s.edges;
        let mut breaks: Vec<usize> = (s.start..end).filter(|&i| at(i) == base).collect();
        if breaks.first() != Some(&s.start) || breaks.len() != m || at(end) != base {
            return Err(Error::Internal(format!(
                "feature handles: the polygon side has {} base copies, not {m}",
                breaks.len()
            )));
        }
        breaks.push(end);
        for (j, p) in breaks.windows(2).enumerate() {
            let length = (p[0]..p[1]).map(|i| (pos(i + 1) - pos(i)).norm()).sum();
            out.push(Side { start: p[0], edges: p[1] - p[0], kind: SideKind::Basis(j), length });
        }
    }
    Ok(out)
}

/// What the handle cuts add to a feature map.
#[derive(Debug, Clone)]
pub struct HandleCuts {
    pub source: CanonicalBasisResult,
    pub target: CanonicalBasisResult,
    /// Polygon sides τ shifts by.
    pub side_shift: usize,
}

/// How [`handle_cuts`] chooses the homotopy class and refines.
#[derive(Debug, Clone, Copy, Default)]
pub struct HandleCutOptions {
    /// Basis index on the source and on the target.
    pub basis: [usize; 2],
    /// τ, as in [`super::map::HomologyMapOptions::rotation`].
    pub rotation: usize,
    /// Subdivision rounds allowed (`None`: the basis search's default).
    pub max_subdivisions: Option<usize>,
}

/// Both cuts, the chain's order and the bases.
#[derive(Debug, Clone)]
pub struct HandleCutResult {
    pub source: FeatureCutResult,
    pub target: FeatureCutResult,
    pub order: Vec<(usize, bool)>,
    pub handles: HandleCuts,
}

/// Cuts both meshes for a feature map with handles: bases at `bases` avoiding the curves, the
/// chain order, and both cuts (the target's chain at the side τ shifts side 0 to).
///
/// # Errors
/// `InputError::TopologyMismatch` when the genera differ; as [`canonical_basis_avoiding`] and
/// [`feature_cut`].
pub fn handle_cuts(
    meshes: [&Mesh; 2],
    curves: [&[Curve]; 2],
    bases: [VertexId; 2],
    o: &HandleCutOptions,
) -> Result<HandleCutResult> {
    if curves.iter().flat_map(|c| c.iter()).any(|c| c.kind != CurveKind::Open) {
        return Err(InputError::TopologyMismatch(
            "boundary loops on a surface with handles are not supported: close the holes or map genus 0".into(),
        )
        .into());
    }
    // A chain that finds no room (a curve behind a neck of the disk one vertex wide, which one
    // link closes) is retried on the next subdivision round, which widens every neck.
    let rounds = o.max_subdivisions.unwrap_or(CanonicalBasisOptions::default().max_subdivisions);
    let mut round = 0;
    loop {
        let min_attempt = round * super::basis::ATTEMPTS_PER_ROUND;
        match cuts_at(meshes, curves, bases, o, min_attempt) {
            Err(e) if round < rounds && matches!(e, Error::Input(InputError::Features(_))) => round += 1,
            // The chain's vertex ids are the cut disk's: say where the search ran instead.
            Err(Error::Input(InputError::Features(m))) => {
                return Err(InputError::Features(format!(
                    "{m} (in the disk the canonical basis cuts, after {round} subdivisions; another base vertex, i.e. first anchor, or basis index may leave room)"
                ))
                .into());
            }
            r => return r,
        }
    }
}

/// [`handle_cuts`] with bases accepted from search `min_attempt` on.
fn cuts_at(
    meshes: [&Mesh; 2],
    curves: [&[Curve]; 2],
    bases: [VertexId; 2],
    o: &HandleCutOptions,
    min_attempt: usize,
) -> Result<HandleCutResult> {
    let [s, t] = both_bases(meshes, bases, o.basis, curves, o.max_subdivisions, min_attempt)?;
    let g = s.basis.genus();
    if g != t.basis.genus() {
        return Err(InputError::TopologyMismatch(format!("source genus {g}, target genus {}", t.basis.genus())).into());
    }
    let shift = if g == 1 { o.rotation % 4 } else { 4 * (o.rotation % g) };
    // The chain's order from the curves in the disks (same positions as the meshes).
    let as_curves = |h: &Handles| -> Vec<Curve> {
        h.curves.iter().map(|c| Curve { vertices: c.clone(), kind: CurveKind::Open }).collect()
    };
    let (cs, ct) = (as_curves(&s), as_curves(&t));
    let order = chain_order_to_base([&s.basis.refined.mesh, &t.basis.refined.mesh], [&cs, &ct], bases);
    let (sc, tc) = std::thread::scope(|sc| {
        let h = sc.spawn(|| handle_cut(&t, &order, shift));
        (handle_cut(&s, &order, 0), h.join())
    });
    let (sc, tc) = (sc?, tc.map_err(|_| Error::Internal("target cut thread panicked".into()))??);
    let handles = HandleCuts { source: s.basis, target: t.basis, side_shift: shift };
    Ok(HandleCutResult { source: sc, target: tc, order, handles })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::topology;

    /// Two short curves on a torus: the cut is a disk whose boundary reads the chain, the
    /// commutator, and the chain back; the polygon's four sides each carry a loop copy, and the
    /// curves lie on the boundary.
    #[test]
    fn a_torus_with_two_curves_is_cut_into_one_disk_with_the_commutator_inside_the_chain() {
        let t = shapes::torus(32, 16, 1.0, 0.35);
        let curve =
            |a: u32| Curve { vertices: vec![VertexId(a), VertexId(a + 1), VertexId(a + 2)], kind: CurveKind::Open };
        // Row-major (32 around, 16 across): two curves along one ring, away from vertex 0.
        let cs = [curve(16 * 8 + 4), curve(16 * 20 + 4)];
        let r = handle_cuts([&t, &t], [&cs, &cs], [VertexId(0), VertexId(0)], &HandleCutOptions::default()).unwrap();
        for c in [&r.source, &r.target] {
            assert_eq!(topology::euler_characteristic(&c.disk.mesh), 1);
            assert_eq!(c.doubled_genus, 3);
            let kinds: Vec<SideKind> = c.sides.iter().map(|s| s.kind).collect();
            let basis: Vec<SideKind> = kinds.iter().copied().filter(|k| matches!(k, SideKind::Basis(_))).collect();
            assert_eq!(basis, (0..4).map(SideKind::Basis).collect::<Vec<_>>());
            // F1 L1 F2 L2 [a b a⁻¹ b⁻¹] L2⁻¹ F2⁻¹ L1⁻¹ F1⁻¹.
            assert_eq!(kinds.len(), 12);
            assert_eq!(kinds[..4], [SideKind::Curve(0), SideKind::Link(0), SideKind::Curve(1), SideKind::Link(1)]);
            let on_boundary = |v: VertexId| {
                (0..c.disk.mesh.n_vertices())
                    .map(VertexId::from_idx)
                    .any(|d| c.disk.orig[d.idx()] == v && c.disk.mesh.is_boundary_vertex(d))
            };
            assert!(c.curves.iter().flat_map(|k| &k.vertices).all(|&v| on_boundary(v)));
        }
        assert_eq!(r.handles.side_shift, 0);
    }
}
