//! `homology` without feature curves: the class (named, or the natural search's candidates)
//! -> canonical bases -> fundamental domains -> maps through the 4g-gon -> anchor snapping ->
//! relaxation -> metrics -> artifacts (bases and domains included).

use crate::pipeline::common::inverse::InversePair;
use crate::pipeline::common::meta_mesh::{MetaMeshStats, loops_json, meta_outputs, planar_obj};
use crate::pipeline::common::relax::{FinishedPair, finish_pair};
use crate::pipeline::common::{Artifact, Clock, PairReport, artifacts, both, json_artifact};
pub mod class;
pub mod features;

use crate::error::{Error, Result};
use crate::homology::HomologyMapResult;
use crate::homology::map::{class_map, map_between};
use crate::homology::matching::{reference_frame, reference_h1};
use crate::homology::sides::{SideDomain, Sides};
use crate::mesh::{Mesh, VertexId};
use crate::pipeline::spec::HomologySpec;
use crate::pipeline::spec::RelaxOptions;
use crate::progress::{Progress, Stage};
use class::{CandidateReport, ClassPlan, Relaxed, candidate_reports};
use serde::Serialize;
use serde_json::json;

/// What a `homology` job measured (`metrics.json`).
#[derive(Debug, Clone, Serialize)]
pub struct HomologyMapReport {
    #[serde(flatten)]
    pub pair: PairReport,
    pub homology: HomologyReport,
}

/// What a `homology` job adds to `metrics.json`.
#[derive(Debug, Clone, Serialize)]
pub struct HomologyReport {
    pub genus: usize,
    pub basis: [usize; 2],
    pub rotation: usize,
    /// Polygon sides τ shifts by.
    pub side_shift: usize,
    /// Whether the source domain was warped onto the anchors (constrained mean-value map).
    pub anchor_warp: bool,
    /// Genus 1: whether the maps went through the two flat tori (`homology::flat`); false when
    /// either is not bijective, or when their map folded after relaxation and the 4g-gons' did
    /// better.
    pub flat_torus: bool,
    /// Induced map on H1 (`a1, b1, …`), column `j` the image of source loop `j`.
    pub h1: Vec<Vec<i32>>,
    /// The same map read in the reference bases (basis 0 on each mesh), when other bases were
    /// used or a matching was asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h1_reference: Option<Vec<Vec<i32>>>,
    /// With no class named: every class found, best first (the chosen one, the others
    /// relaxed, then the rest by stretch before relaxation).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub candidates: Option<Vec<CandidateReport>>,
    /// Base vertices (the first anchor pair).
    pub base: [u32; 2],
    /// Subdivision rounds the bases needed.
    pub subdivisions: [usize; 2],
    /// Loop lengths on each mesh.
    pub loop_lengths: [Vec<f64>; 2],
    /// Meta-mesh vertices, faces and edge crossings, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub meta_mesh: Option<MetaMeshStats>,
}

/// Runs a `homology` job.
///
/// # Errors
/// Input errors for a spec that does not fit the meshes; `Numerical` when a basis or domain
/// cannot be built; `Cancelled`.
pub fn run(
    spec: &HomologySpec,
    source: &Mesh,
    target: &Mesh,
    progress: &mut dyn Progress,
) -> Result<(HomologyMapReport, Vec<Artifact>)> {
    let mut clock = Clock::start();
    let pairs = spec.validate(source, target)?;
    let o = &spec.options;
    clock.lap("setup");
    progress.report(Stage::Basis, 0.0);
    // Bases and domains are built once and kept: the natural search composes every pair of
    // them, and the relaxation rebuilds the classes it chose from the same ones.
    let sides = (Sides::new(source, pairs[0].0, None, 0), Sides::new(target, pairs[0].1, None, 0));
    let plan = ClassPlan::new(o.class_choice(), (&sides.0, &sides.1), &pairs, progress)?;
    clock.lap("classes");
    // Each class in the plan is built and relaxed in turn: the close ones all, the others while
    // none is fold-free; the least folded, then least stretched, stands.
    let mut relaxed: Vec<Relaxed> = Vec::new();
    let mut best: Option<(usize, HomologyMapResult, FinishedPair)> = None;
    for (i, &(basis, rotation)) in plan.tries.iter().enumerate() {
        let (r, f) = relax_class((&sides.0, &sides.1), &pairs, basis, rotation, &o.relax(), progress)?;
        let out = Relaxed::of(&f);
        tracing::debug!(?basis, rotation, flips = ?out.flips, l2 = ?out.l2_stretch, "homology class relaxed");
        relaxed.push(out);
        if best.as_ref().is_none_or(|(b, ..)| out.better_than(&relaxed[*b])) {
            best = Some((i, r, f));
        }
        if i + 1 >= plan.compare && relaxed.iter().any(|r| r.flips == [0, 0]) {
            break;
        }
    }
    let (chosen, r, f) = best.ok_or_else(|| Error::Internal("homology: no class to relax".into()))?;
    let (f, inverted) = InversePair { source, target, pairs: &pairs }.repair_finished(f, &o.relax(), progress)?;
    let (basis, rotation) = plan.tries[chosen];
    // The induced map read in the reference bases (basis 0 on each mesh): the search's, or
    // computed when other bases were used or a matching was asked for.
    let h1_reference = if let Some(c) = plan.candidates.get(chosen) {
        Some(c.h1_reference.clone())
    } else if plan.want.is_some() || basis != [0, 0] {
        let (fs, ft) = both(|| reference_frame(target, pairs[0].1), || reference_frame(source, pairs[0].0))?;
        let (fs, ft) = (fs?, ft?);
        Some(reference_h1((source, target), (&fs.1, &ft.1), (&r.source.basis, &r.target.basis), &r.h1)?)
    } else {
        None
    };
    if let (Some(w), Some(got)) = (&plan.want, &h1_reference)
        && got != w
    {
        return Err(Error::Numerical(format!(
            "matching: the bases refined for the map induce {got:?} instead of {w:?}"
        )));
    }
    let candidates = (!plan.candidates.is_empty()).then(|| candidate_reports(&plan, &relaxed, chosen));
    clock.lap("smooth_metrics");
    progress.check()?;
    let g = r.source.basis.genus();
    let len = |sd: &SideDomain| -> Vec<f64> {
        let m = &sd.basis.refined.mesh;
        sd.basis
            .loops
            .iter()
            .map(|l| l.windows(2).map(|w| (m.position(w[1]) - m.position(w[0])).norm()).sum())
            .collect()
    };
    let mut arts = artifacts::maps_and_meshes(&f.s2t, &f.t2s, &f.on_target, &f.on_source);
    let mut meta = None;
    let mut morph = None;
    if o.meta_mesh {
        progress.report(Stage::MetaMesh, 0.0);
        let angle = std::f64::consts::TAU * r.side_shift as f64 / (4 * g) as f64;
        let built = crate::homology::overlay::meta_mesh(&r.source, &r.target, angle);
        let (stats, m) = meta_outputs(built, o.dihedral_threshold_deg, &mut arts);
        meta = Some(stats);
        morph = m;
        clock.lap("meta_mesh");
    }
    let report_h = HomologyReport {
        genus: g,
        basis,
        rotation,
        side_shift: r.side_shift,
        anchor_warp: r.warped,
        flat_torus: r.flat,
        h1: r.h1.clone(),
        h1_reference,
        candidates,
        base: [pairs[0].0.0, pairs[0].1.0],
        subdivisions: [r.source.basis.subdivisions, r.target.basis.subdivisions],
        loop_lengths: [len(&r.source), len(&r.target)],
        meta_mesh: meta,
    };
    // The meta-mesh morph (every detail of both); `morph.glb` of the source is added by
    // `run_job` for every pair method.
    arts.extend(morph);
    arts.push(json_artifact("basis_source.json", &basis_json(&r.source))?);
    arts.push(json_artifact("basis_target.json", &basis_json(&r.target))?);
    arts.push(planar_obj("domain_source.obj", &r.source.domain.uv, &r.source.basis.disk.mesh)?);
    arts.push(planar_obj("domain_target.obj", &r.target.domain.uv, &r.target.basis.disk.mesh)?);
    clock.lap("artifacts");
    let pair = PairReport {
        inverted,
        ..PairReport::new("homology", pairs.len(), (source, target), (f.m1, f.m2), f.smoothing)
    };
    let mut report = HomologyMapReport { pair: pair.with_maps(f.s2t, f.t2s), homology: report_h };
    report.pair.timings_ms = clock.finish();
    progress.report(Stage::Done, 1.0);
    Ok((report, arts))
}

/// One class built and relaxed. A genus-1 class goes through the flat tori first; if that map
/// folds after relaxation, the squares' map of the same bases is relaxed too and the better
/// stands (between different shapes the flat tori can differ more than the squares' interiors
/// do).
fn relax_class(
    (s, t): (&Sides<'_>, &Sides<'_>),
    pairs: &[(VertexId, VertexId)],
    basis: [usize; 2],
    rotation: usize,
    relax: &RelaxOptions,
    progress: &mut dyn Progress,
) -> Result<(HomologyMapResult, FinishedPair)> {
    // The sides carry no stretch reweighting: reweighting each domain on its own lowers each
    // map's stretch but raised the composed map's folds on every different-shape pair
    // measured (git show 32d23d1:bench/NOTES.md).
    let (source, target) = (s.mesh(), t.mesh());
    let anchors = &pairs[1..];
    let finish = |r: &HomologyMapResult, progress: &mut dyn Progress| {
        finish_pair(source, target, (&r.source_to_target, &r.target_to_source), pairs, (&[], &[]), relax, progress)
    };
    let r = class_map(s, t, basis, rotation, anchors)?;
    progress.check()?;
    let f = finish(&r, progress)?;
    if !r.flat || Relaxed::of(&f).flips == [0, 0] {
        return Ok((r, f));
    }
    let sq = map_between(source, target, r.source.clone(), r.target.clone(), rotation, anchors, true)?;
    progress.check()?;
    let g = finish(&sq, progress)?;
    Ok(if Relaxed::of(&g).better_than(&Relaxed::of(&f)) { (sq, g) } else { (r, f) })
}

/// Loops as 3D polylines (a1, b1, …) on the basis's refinement, the intersection matrix and the
/// boundary word.
fn basis_json(sd: &SideDomain) -> serde_json::Value {
    let b = &sd.basis;
    json!({
        "genus": b.genus(),
        "base_vertex": b.base.0,
        "loops": loops_json(b),
        "intersection": b.intersection,
        "word": b.word_text(),
        "subdivisions": b.subdivisions,
        "disk_euler_characteristic": crate::topology::euler_characteristic(&b.disk.mesh),
    })
}
