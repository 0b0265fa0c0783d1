//! Maps between two surfaces that carry corresponding feature curves (boundary loops included
//! on genus 0): both cut by [`feature_cut`] (through the canonical basis on surfaces with
//! handles, [`super::feature_handles`]), both mapped onto the unit circle with the same arcs
//! ([`feature_domain`]), composed both ways. Every feature lands on its partner exactly (both
//! are the same arc of the circle), and the composition of two bijections is one.

use super::compose::{Planar, locate_all, warp_interior};
use super::curve_align::{CurveAlignOptions, align_fractions, arc_fractions, loop_rotation};
use super::feature_cut::{FeatureCutResult, chain_order, feature_cut};
use super::feature_domain::{FeatureDomainResult, feature_domain, shared_arcs};
use super::feature_handles::{HandleCutOptions, HandleCuts, handle_cuts};
use super::features::{Curve, CurveKind};
use crate::error::{InputError, Result};
use crate::map::SurfaceMap;
use crate::mesh::refine::Refined;
use crate::mesh::{Mesh, P3, VertexId};

/// One mesh's cut and domain.
#[derive(Debug, Clone)]
pub struct FeatureSide {
    pub cut: FeatureCutResult,
    pub domain: FeatureDomainResult,
    /// The refinement the cut lives on (surfaces with handles); `None`: the mesh itself.
    pub refined: Option<Refined>,
}

impl FeatureSide {
    pub fn planar(&self) -> Planar<'_> {
        Planar { disk: &self.cut.disk, uv: &self.domain.uv, refined: self.refined.as_ref() }
    }

    /// The mesh the cut's vertex ids refer to: the refinement, or `mesh` itself.
    pub fn cut_mesh<'a>(&'a self, mesh: &'a Mesh) -> &'a Mesh {
        self.refined.as_ref().map_or(mesh, |r| &r.mesh)
    }
}

/// How the two domains are built.
#[derive(Debug, Clone, Copy, Default)]
pub struct FeatureMapOptions {
    /// Stretch-reweighting rounds of each domain (0 = the plain mean-value map).
    pub stretch_iterations: usize,
    /// Align the target's curve sides to the source's vertex by vertex
    /// ([`super::curve_align`]) and turn an unlisted boundary loop to match; `None` places both
    /// by arc length from their own chain arrivals.
    pub align: Option<CurveAlignOptions>,
    /// Surfaces with handles: basis index on each mesh, rotation τ and subdivision rounds, as in
    /// [`super::map::HomologyMapOptions`]; the first anchor pair is the base.
    pub basis: [usize; 2],
    pub rotation: usize,
    pub max_subdivisions: Option<usize>,
}

/// Maps both ways and what produced them.
#[derive(Debug, Clone)]
pub struct FeatureMapResult {
    pub source_to_target: SurfaceMap,
    pub target_to_source: SurfaceMap,
    /// Whether the source domain was warped to put interior anchors on their partners.
    pub warped: bool,
    pub source: FeatureSide,
    pub target: FeatureSide,
    /// The chain's order: given curve index, entered at its last vertex.
    pub order: Vec<(usize, bool)>,
    /// The canonical bases, on surfaces with handles.
    pub handles: Option<HandleCuts>,
}

/// Maps `source` onto `target` so that `source_curves[i]` lands on `target_curves[i]`.
/// A boundary anchor pair fixes where an unlisted boundary loop starts; otherwise an interior
/// anchor pair starts the chain when that loop is the only curve.
///
/// # Errors
/// `InputError::Features` when the curves do not correspond; as [`feature_cut`] and
/// [`feature_domain`].
pub fn feature_map(
    source: &Mesh,
    target: &Mesh,
    source_curves: &[Curve],
    target_curves: &[Curve],
    anchors: &[(VertexId, VertexId)],
    o: &FeatureMapOptions,
) -> Result<FeatureMapResult> {
    if source_curves.len() != target_curves.len() {
        return Err(InputError::Features(format!(
            "{} source curves against {} target curves",
            source_curves.len(),
            target_curves.len()
        ))
        .into());
    }
    for (i, (a, b)) in source_curves.iter().zip(target_curves).enumerate() {
        if a.kind != b.kind {
            return Err(InputError::Features(format!(
                "feature {i} is {} on the source but {} on the target",
                kind_name(a.kind),
                kind_name(b.kind)
            ))
            .into());
        }
    }
    let (genus, target_genus) = (crate::topology::summary(source).genus, crate::topology::summary(target).genus);
    if genus != target_genus {
        return Err(InputError::TopologyMismatch(format!("source genus {genus}, target genus {target_genus}")).into());
    }
    if genus > 0 {
        let &(bs, bt) = anchors.first().ok_or_else(|| {
            InputError::Anchors(
                "a surface with handles needs an anchor pair: the first is the basis's base vertex".into(),
            )
        })?;
        if source_curves.iter().any(|c| c.vertices.contains(&bs))
            || target_curves.iter().any(|c| c.vertices.contains(&bt))
        {
            return Err(InputError::Anchors(format!(
                "the first anchor pair ({}, {}) is the base vertex of both canonical bases and must not lie on a feature curve",
                bs.0, bt.0
            ))
            .into());
        }
        let ho = HandleCutOptions { basis: o.basis, rotation: o.rotation, max_subdivisions: o.max_subdivisions };
        let h = handle_cuts([source, target], [source_curves, target_curves], [bs, bt], &ho)?;
        let refined = [Some(h.handles.source.refined.clone()), Some(h.handles.target.refined.clone())];
        return compose_cuts(source, target, h.source, h.target, h.order, refined, Some(h.handles), anchors, o);
    }
    let order = chain_order([source, target], [source_curves, target_curves]);
    // The first anchor pair with both ends on the boundary starts an unlisted boundary loop.
    let on_boundary = anchors.iter().find(|(a, b)| source.is_boundary_vertex(*a) && target.is_boundary_vertex(*b));
    let interior = anchors.iter().find(|(a, b)| !source.is_boundary_vertex(*a) && !target.is_boundary_vertex(*b));
    let (sc, tc) = std::thread::scope(|sc| {
        let h =
            sc.spawn(|| feature_cut(target, target_curves, &order, interior.map(|a| a.1), on_boundary.map(|a| a.1)));
        (feature_cut(source, source_curves, &order, interior.map(|a| a.0), on_boundary.map(|a| a.0)), h.join())
    });
    let sc = sc?;
    let mut tc = tc.map_err(|_| crate::Error::Internal("feature cut thread panicked".into()))??;
    // An unlisted boundary loop starts where the chain arrives, on each mesh by its own shortest
    // path; on a deformed copy the two arrivals can be several vertices apart, which turns the
    // whole loop. When the loops' corner angles say by how much, the target's loop is started
    // (and arrived at) there instead.
    let unlisted = sc.curves.len() > source_curves.len() && tc.curves.len() > target_curves.len();
    if o.align.is_some() && on_boundary.is_none() && unlisted {
        let (sl, tl) = (&sc.curves[sc.curves.len() - 1].vertices, &tc.curves[tc.curves.len() - 1].vertices);
        if let Some(r) = loop_rotation(source, sl, target, tl) {
            tc = feature_cut(target, target_curves, &order, interior.map(|a| a.1), Some(tl[r]))?;
        }
    }
    compose_cuts(source, target, sc, tc, order, [None, None], None, anchors, o)
}

/// Both cuts on the circle with shared arcs (the target's curve sides aligned to the source's),
/// the anchor warp, and the maps both ways.
///
/// # Errors
/// As [`feature_domain`] and [`warp_interior`].
#[allow(clippy::too_many_arguments)]
fn compose_cuts(
    source: &Mesh,
    target: &Mesh,
    sc: FeatureCutResult,
    tc: FeatureCutResult,
    order: Vec<(usize, bool)>,
    refined: [Option<Refined>; 2],
    handles: Option<HandleCuts>,
    anchors: &[(VertexId, VertexId)],
    o: &FeatureMapOptions,
) -> Result<FeatureMapResult> {
    let arcs = shared_arcs(&sc, &tc)?;
    let it = o.stretch_iterations;
    let tf = match &o.align {
        Some(a) => align_fractions(&sc, &tc, a),
        None => arc_fractions(&tc),
    };
    let (sd, td) = (feature_domain(&sc, &arcs, &arc_fractions(&sc), it)?, feature_domain(&tc, &arcs, &tf, it)?);
    let [rs, rt] = refined;
    let mut s = FeatureSide { cut: sc, domain: sd, refined: rs };
    let t = FeatureSide { cut: tc, domain: td, refined: rt };
    let id = |p| p;
    let warped = warp_interior(&s.cut.disk, &mut s.domain.uv, &s.cut.walk, &t.planar(), anchors, &id)?;
    if warped {
        s.domain.injectivity = super::domain::exact_orientation(&s.cut.disk.mesh, &s.domain.uv);
    }
    let mut source_to_target = locate_all(source.n_vertices(), &s.planar(), &t.planar(), &id);
    let mut target_to_source = locate_all(target.n_vertices(), &t.planar(), &s.planar(), &id);
    snap_boundary(&mut source_to_target, &s, &t, target)?;
    snap_boundary(&mut target_to_source, &t, &s, source)?;
    Ok(FeatureMapResult { source_to_target, target_to_source, warped, source: s, target: t, order, handles })
}

/// Angle of a point of the circle in `[0, 2π)`.
pub(crate) fn angle(p: [f64; 2]) -> f64 {
    let a = p[1].atan2(p[0]);
    if a < 0.0 { a + std::f64::consts::TAU } else { a }
}

/// Places every vertex whose disk copy lies on the circle exactly on the other disk's boundary
/// polygon, by angle: the point between the two boundary vertices whose angles enclose it, at
/// the fraction of the angle (angles increase along every side on both disks, and side ends
/// share their angles, so junctions land on junctions, every curve vertex on its partner curve,
/// and a vertex aligned with a partner vertex exactly on it). A grid search would clamp such
/// points into whichever triangle is least outside, which need not be the one on the chord.
///
/// # Errors
/// `Internal` when a boundary edge of the disk is no edge of the mesh.
fn snap_boundary(map: &mut SurfaceMap, from: &FeatureSide, to: &FeatureSide, to_mesh: &Mesh) -> Result<()> {
    let to_mesh = to.cut_mesh(to_mesh);
    let walk = &to.cut.walk;
    let th: Vec<f64> = walk.iter().map(|v| angle(to.domain.uv[v.idx()])).collect();
    let disk = &from.cut.disk;
    let mut done = vec![false; map.face.len()];
    for &v in &from.cut.walk {
        let o = disk.orig[v.idx()];
        // Vertices a refinement added are no vertices of the mesh the map is for.
        if o.idx() >= done.len() || std::mem::replace(&mut done[o.idx()], true) {
            continue;
        }
        let a = angle(from.domain.uv[v.idx()]);
        // Last walk vertex at or before `a` (the base, at angle 0, is first).
        let i = th.partition_point(|&x| x <= a).max(1) - 1;
        let (a0, a1) = (th[i], if i + 1 < th.len() { th[i + 1] } else { std::f64::consts::TAU });
        let u = if a1 > a0 { ((a - a0) / (a1 - a0)).clamp(0.0, 1.0) } else { 0.0 };
        let (p, q) = (to.cut.disk.orig[walk[i].idx()], to.cut.disk.orig[walk[(i + 1) % walk.len()].idx()]);
        let h = to_mesh
            .find_halfedge(p, q)
            .or_else(|| to_mesh.find_halfedge(q, p))
            .ok_or_else(|| crate::Error::Internal(format!("disk boundary {}-{} is no edge", p.0, q.0)))?;
        let f = h.face();
        let mut b = [0.0; 3];
        for (k, c) in to_mesh.face(f).iter().enumerate() {
            if *c == p {
                b[k] += 1.0 - u;
            } else if *c == q {
                b[k] += u;
            }
        }
        let (f, b) = match &to.refined {
            Some(r) => r.to_original(f, b),
            None => (f, b),
        };
        map.face[o.idx()] = f;
        map.bary[o.idx()] = b;
    }
    Ok(())
}

fn kind_name(k: CurveKind) -> &'static str {
    match k {
        CurveKind::Open => "an open curve",
        CurveKind::Boundary => "a boundary loop",
    }
}

/// Largest distance from the image of a vertex of `from_curves[i]` to the polyline
/// `to_curves[i]` on `to`, relative to `to`'s bounding-box diagonal.
pub fn feature_error(map: &SurfaceMap, to: &Mesh, from_curves: &[Curve], to_curves: &[Curve]) -> f64 {
    let mut worst: f64 = 0.0;
    for (a, b) in from_curves.iter().zip(to_curves) {
        let pts: Vec<P3> = b.vertices.iter().map(|&v| to.position(v)).collect();
        let closed = b.kind == CurveKind::Boundary;
        let segs = if closed { pts.len() } else { pts.len() - 1 };
        for &v in &a.vertices {
            let p = map.position(v, to);
            let d = (0..segs)
                .map(|k| segment_distance(&p, &pts[k], &pts[(k + 1) % pts.len()]))
                .fold(f64::INFINITY, f64::min);
            worst = worst.max(d);
        }
    }
    worst / to.bbox_diagonal().max(f64::MIN_POSITIVE)
}

fn segment_distance(p: &P3, a: &P3, b: &P3) -> f64 {
    let ab = b - a;
    let t = ((p - a).dot(&ab) / ab.norm_squared().max(f64::MIN_POSITIVE)).clamp(0.0, 1.0);
    (p - (a + ab * t)).norm()
}

#[cfg(test)]
mod tests {
    use super::super::feature_cut::{SideKind, feature_cut};
    use super::super::features::tests::sphere_curves;
    use super::super::features::validate_curve;
    use super::*;
    use crate::mesh::shapes;
    use crate::topology;

    #[test]
    fn a_sphere_with_three_features_opens_into_a_mirrored_word() {
        let s = shapes::icosphere(3);
        let c = sphere_curves(&s);
        let order: Vec<(usize, bool)> = (0..3).map(|i| (i, false)).collect();
        let cut = feature_cut(&s, &c, &order, None, None).unwrap();
        assert_eq!(topology::euler_characteristic(&cut.disk.mesh), 1);
        assert_eq!((cut.links.len(), cut.sides.len(), cut.doubled_genus), (2, 10, 2));
        let k: Vec<SideKind> = cut.sides.iter().map(|s| s.kind).collect();
        assert_eq!(
            &k[..5],
            &[SideKind::Curve(0), SideKind::Link(0), SideKind::Curve(1), SideKind::Link(1), SideKind::Curve(2)]
        );
        for i in 0..10 {
            assert_eq!(k[i], k[9 - i], "side {i} comes back mirrored");
            assert!((cut.sides[i].length - cut.sides[9 - i].length).abs() < 1e-12);
        }
    }

    #[test]
    fn a_disk_starts_at_a_boundary_anchor_or_links_to_an_interior_one() {
        let g = shapes::grid(8);
        let b = feature_cut(&g, &[], &[], None, Some(VertexId(4))).unwrap();
        assert_eq!((b.links.len(), b.sides.len(), b.base), (0, 1, VertexId(4)));
        let i = feature_cut(&g, &[], &[], Some(VertexId(40)), None).unwrap();
        assert_eq!((i.links.len(), i.sides.len(), i.base), (1, 3, VertexId(40)));
        assert!(feature_cut(&g, &[], &[], None, None).unwrap_err().to_string().contains("needs an anchor"));
        let closed = shapes::icosphere(1);
        assert!(feature_cut(&closed, &[], &[], None, None).unwrap_err().to_string().contains("no handle"));
        let t = shapes::torus(12, 8, 1.0, 0.3);
        let f = validate_curve(&t, &[0, 1], "f").unwrap();
        assert!(feature_cut(&t, &[f], &[(0, false)], None, None).unwrap_err().to_string().contains("genus 1"));
    }

    #[test]
    fn features_map_onto_their_partners_and_the_domains_do_not_fold() {
        let s = shapes::icosphere(3);
        let pos: Vec<P3> = s.positions().iter().map(|p| P3::new(1.6 * p.x, p.y + 0.2 * p.x * p.x, 0.8 * p.z)).collect();
        let t = s.with_positions(pos).unwrap();
        let c = sphere_curves(&s);
        let r = feature_map(&s, &t, &c, &c, &[], &FeatureMapOptions::default()).unwrap();
        for side in [&r.source, &r.target] {
            assert!(side.domain.injectivity.is_injective());
            assert!(side.domain.residual < 1e-9, "residual {}", side.domain.residual);
        }
        assert!(feature_error(&r.source_to_target, &t, &c, &c) < 1e-12);
        assert!(feature_error(&r.target_to_source, &s, &c, &c) < 1e-12);
        // Curve ends are junctions: they land exactly on their partners.
        for cv in &c {
            for v in [cv.vertices[0], cv.vertices[cv.vertices.len() - 1]] {
                assert!((r.source_to_target.position(v, &t) - t.position(v)).norm() < 1e-12);
            }
        }
    }
}
