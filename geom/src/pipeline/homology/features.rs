//! `run_features`: a `homology` job whose surfaces carry feature curves (boundary loops on
//! genus 0; on closed surfaces with handles through the canonical basis): feature cut -> circle
//! domains -> maps both ways -> anchor snapping -> smoothing with every feature vertex held ->
//! metrics (with the feature error) -> artifacts.

use crate::error::Result;
use crate::homology::CanonicalBasisResult;
use crate::homology::curve_align::CurveAlignOptions;
use crate::homology::feature_cut::{FeatureCutResult, Side, SideKind};
use crate::homology::feature_map::{FeatureMapOptions, FeatureSide, feature_error, feature_map};
use crate::homology::features::{Curve, CurveKind};
use crate::mesh::{Mesh, VertexId};
use crate::pipeline::common::meta_mesh::{MetaMeshStats, loops_json, meta_outputs, planar_obj};
use crate::pipeline::common::relax::finish_pair;
use crate::pipeline::common::{Artifact, Clock, PairReport, artifacts, json_artifact};
use crate::pipeline::spec::{ClassChoice, HomologySpec};
use crate::progress::{Progress, Stage};
use serde::Serialize;
use serde_json::json;

/// What a `homology` job with feature curves or boundaries measured (`metrics.json`).
#[derive(Debug, Clone, Serialize)]
pub struct FeatureMapReport {
    #[serde(flatten)]
    pub pair: PairReport,
    pub features: FeatureReport,
}

/// What a feature job adds to `metrics.json`.
#[derive(Debug, Clone, Serialize)]
pub struct FeatureReport {
    /// Curves mapped (given features, then an unlisted boundary loop).
    pub curves: usize,
    /// Chain order: `[given feature index, entered at its last vertex]`; `F1, F2, …` in the
    /// word and in `basis_*.json` follow it.
    pub order: Vec<(usize, bool)>,
    pub kinds: Vec<CurveKind>,
    /// Genus of the surfaces.
    pub genus: usize,
    /// Genus of the double cover the curves define (`2g + n − 1`).
    pub doubled_genus: usize,
    /// Surfaces with handles: the induced map on H1 in the two canonical bases (column `j` is
    /// the image of source loop `j`), and the polygon sides τ shifts by.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h1: Option<Vec<Vec<i32>>>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub side_shift: Option<usize>,
    /// The cut disk's boundary word, e.g. `F1 L1 F2 F2^-1 L1^-1 F1^-1`.
    pub word: String,
    /// Largest distance of a mapped feature vertex from its partner curve, relative to the
    /// bounding-box diagonal: source→target, target→source.
    pub feature_error: [f64; 2],
    /// Whether the source domain was warped onto interior anchors.
    pub anchor_warp: bool,
    /// Flipped triangles in the two planar domains (0: both maps bijective).
    pub domain_flips: [usize; 2],
    /// Meta-mesh vertices, faces and edge crossings, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub meta_mesh: Option<MetaMeshStats>,
}

/// Whether a `homology` job maps feature curves: it has some, or its meshes have boundaries.
pub fn applies(spec: &HomologySpec, source: &Mesh) -> bool {
    !spec.features.is_empty() || !crate::topology::boundary_loops(source).is_empty()
}

/// Runs a `homology` job with feature curves or boundary loops.
///
/// # Errors
/// Input errors for a spec or curves that do not fit the meshes; `Numerical` when a cut or
/// domain cannot be built; `Cancelled`.
pub fn run(
    spec: &HomologySpec,
    source: &Mesh,
    target: &Mesh,
    progress: &mut dyn Progress,
) -> Result<(FeatureMapReport, Vec<Artifact>)> {
    let mut clock = Clock::start();
    let pairs = &spec.validate(source, target)?;
    let (sc, tc) = spec.curves(source, target)?;
    let curves: (&[Curve], &[Curve]) = (&sc, &tc);
    let o = &spec.options;
    clock.lap("setup");
    progress.report(Stage::FeatureCut, 0.0);
    // Feature curves pin most of the class: with none named it is basis 0 and τ = 0 (the
    // natural-class search is for jobs without curves).
    let (basis, rotation) = match o.class_choice() {
        ClassChoice::Explicit { basis, rotation } => (basis, rotation),
        ClassChoice::Natural | ClassChoice::Matching(_) => ([0, 0], 0),
    };
    let fo = FeatureMapOptions {
        // As in `homology`: no reweighting of the planar domains.
        stretch_iterations: 0,
        align: o.align_curves.then(CurveAlignOptions::default),
        basis,
        rotation,
        max_subdivisions: None,
    };
    let r = feature_map(source, target, curves.0, curves.1, pairs, &fo)?;
    clock.lap("cut_domain_map");
    progress.check()?;
    // Open curves and the chain's junctions stay put; boundary vertices between junctions may
    // slide along the partner boundary (they stay on it).
    // (Cuts on a refinement hold only the mesh's own vertices.)
    let held = |c: &FeatureCutResult, n: usize| -> Vec<VertexId> {
        let open = c.curves.iter().filter(|c| c.kind == CurveKind::Open).flat_map(|c| c.vertices.iter().copied());
        let ends = c.links.iter().flat_map(|l| [l[0], l[l.len() - 1]]);
        let starts = c.curves.iter().map(|c| c.vertices[0]);
        open.chain(ends).chain(starts).filter(|v| v.idx() < n).collect()
    };
    let (hs, ht) = (held(&r.source.cut, source.n_vertices()), held(&r.target.cut, target.n_vertices()));
    let f = finish_pair(
        source,
        target,
        (&r.source_to_target, &r.target_to_source),
        pairs,
        (&hs, &ht),
        &o.relax(),
        progress,
    )?;
    clock.lap("smooth_metrics");
    progress.check()?;
    // The feature error on the meshes' own curves (the cut's may run through a refinement;
    // on genus 0 they add the unlisted boundary loop).
    let (sc, tc) = match &r.handles {
        Some(_) => (curves.0, curves.1),
        None => (&r.source.cut.curves[..], &r.target.cut.curves[..]),
    };
    let mut report_f = FeatureReport {
        curves: r.source.cut.curves.len(),
        order: r.order.clone(),
        kinds: r.source.cut.curves.iter().map(|c| c.kind).collect(),
        genus: r.handles.as_ref().map_or(0, |h| h.source.genus()),
        doubled_genus: r.source.cut.doubled_genus,
        h1: r.handles.as_ref().map(|h| crate::homology::map::induced_h1_for(&h.source, &h.target, rotation)),
        side_shift: r.handles.as_ref().map(|h| h.side_shift),
        word: word(&r.source.cut, r.handles.as_ref().map(|h| &h.source)),
        feature_error: [feature_error(&f.s2t, target, sc, tc), feature_error(&f.t2s, source, tc, sc)],
        anchor_warp: r.warped,
        domain_flips: [r.source.domain.injectivity.flipped, r.target.domain.injectivity.flipped],
        meta_mesh: None,
    };
    let mut arts = artifacts::maps_and_meshes(&f.s2t, &f.t2s, &f.on_target, &f.on_source);
    let mut morph = None;
    if o.meta_mesh {
        progress.report(Stage::MetaMesh, 0.0);
        // On a refinement (same surface, more vertices) when the cut lives on one.
        let (ms, mt) = (r.source.cut_mesh(source), r.target.cut_mesh(target));
        let m = crate::homology::feature_overlay::feature_meta_mesh(&r.source, &r.target, ms, mt);
        let (stats, m) = meta_outputs(m, o.dihedral_threshold_deg, &mut arts);
        report_f.meta_mesh = Some(stats);
        morph = m;
        clock.lap("meta_mesh");
    }
    // The meta-mesh morph; `morph.glb` of the source is added by `run_job`.
    arts.extend(morph);
    let (bs, bt) = (r.handles.as_ref().map(|h| &h.source), r.handles.as_ref().map(|h| &h.target));
    arts.push(json_artifact("basis_source.json", &cut_json(&r.source, source, bs))?);
    arts.push(json_artifact("basis_target.json", &cut_json(&r.target, target, bt))?);
    arts.push(planar_obj("domain_source.obj", &r.source.domain.uv, &r.source.cut.disk.mesh)?);
    arts.push(planar_obj("domain_target.obj", &r.target.domain.uv, &r.target.cut.disk.mesh)?);
    clock.lap("artifacts");
    let pair = PairReport::new("homology", pairs.len(), (source, target), (f.m1, f.m2), f.smoothing);
    let mut report = FeatureMapReport { pair: pair.with_maps(f.s2t, f.t2s), features: report_f };
    report.pair.timings_ms = clock.finish();
    progress.report(Stage::Done, 1.0);
    Ok((report, arts))
}

/// The boundary word: `F` for an open curve, `B` for a boundary arc, `L` for a link, `^-1`
/// when a slit side comes back; the polygon's sides as the basis reads them (`a1 b1 a1^-1 …`).
fn word(c: &FeatureCutResult, basis: Option<&CanonicalBasisResult>) -> String {
    let mut seen = std::collections::HashSet::new();
    let polygon: Vec<String> = basis.map(|b| b.word_text().split(' ').map(String::from).collect()).unwrap_or_default();
    c.sides
        .iter()
        .map(|s: &Side| {
            let (letter, i) = match s.kind {
                SideKind::Curve(i) if c.curves[i].kind == CurveKind::Boundary => ('B', i),
                SideKind::Curve(i) => ('F', i),
                SideKind::Link(i) => ('L', i),
                SideKind::Basis(i) => match polygon.get(i) {
                    Some(text) => return text.clone(),
                    None => ('P', i),
                },
            };
            let inv = if seen.insert(s.kind) || letter == 'B' { "" } else { "^-1" };
            format!("{letter}{}{inv}", i + 1)
        })
        .collect::<Vec<_>>()
        .join(" ")
}

/// Curves and links as 3D polylines, the sides, and the double cover's genus.
fn cut_json(fs: &FeatureSide, mesh: &Mesh, handles: Option<&CanonicalBasisResult>) -> serde_json::Value {
    let c = &fs.cut;
    let mesh = fs.cut_mesh(mesh);
    let poly =
        |v: &[VertexId]| -> Vec<[f64; 3]> { v.iter().map(|&x| mesh.position(x)).map(|p| [p.x, p.y, p.z]).collect() };
    let curves: Vec<_> = c
        .curves
        .iter()
        .enumerate()
        .map(|(i, cv)| json!({"name": format!("F{}", i + 1), "kind": cv.kind, "vertices": cv.vertices.iter().map(|v| v.0).collect::<Vec<_>>(), "points": poly(&cv.vertices)}))
        .collect();
    let links: Vec<_> =
        c.links.iter().enumerate().map(|(i, l)| json!({"name": format!("L{}", i + 1), "points": poly(l)})).collect();
    let basis = handles.map(|b| json!({"loops": loops_json(b), "intersection": b.intersection, "word": b.word_text()}));
    json!({
        "genus": handles.map_or(0, |b| b.genus()),
        "basis": basis,
        "doubled_genus": c.doubled_genus,
        "base_vertex": c.base.0,
        "curves": curves,
        "links": links,
        "sides": c.sides,
        "arc_start_angles": fs.domain.angles,
        "word": word(c, handles),
        "disk_euler_characteristic": crate::topology::euler_characteristic(&c.disk.mesh),
    })
}
