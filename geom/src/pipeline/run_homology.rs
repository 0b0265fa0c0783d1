//! `run_homology`: canonical bases -> fundamental domains -> maps through the 4g-gon -> anchor
//! snapping -> smoothing -> metrics -> artifacts (bases and domains included).

use super::artifacts;
use super::run::{Artifact, Clock, MapReport, both, finish_direction};
use super::spec::JobSpec;
use super::spec::MapOptions;
use crate::crossparam::smooth::SmoothReport;
use crate::domain::LayoutStats;
use crate::error::{Error, Result};
use crate::homology::matching::{MatchingOptions, find_matching, parse_matching, reference_frame, reference_h1};
use crate::homology::prune::{PruneOptions, prune_meta_mesh};
use crate::homology::{HomologyMapOptions, homology_map, map::SideDomain};
use crate::io::{self, Format};
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, P3, VertexId};
use crate::metrics::MapMetrics;
use crate::progress::Progress;
use crate::topology::SurfacePoint;
use serde::Serialize;
use serde_json::json;
use std::time::Instant;

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
    /// Induced map on H1 (`a1, b1, …`), column `j` the image of source loop `j`.
    pub h1: Vec<Vec<i32>>,
    /// The same map read in the reference bases (basis 0 on each mesh), when other bases were
    /// used or a matching was asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub h1_reference: Option<Vec<Vec<i32>>>,
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

/// Size of the meta-mesh (or why it could not be built).
#[derive(Debug, Clone, Serialize)]
pub struct MetaMeshStats {
    pub vertices: usize,
    pub faces: usize,
    pub crossings: usize,
    /// Vertices removed by pruning below `dihedral_threshold_deg`, when asked for.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pruned_vertices: Option<usize>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub error: Option<String>,
}

/// The meta-mesh pair's artifacts (`meta_source.obj`, `meta_target.obj`), pruned below
/// `dihedral_threshold_deg` when set; its statistics, and the morph from one to the other.
/// The meta-mesh is an extra: a merge, pruning or validation that fails is reported in the
/// statistics (`error`, no meta artifacts), and the maps still succeed.
pub(super) fn meta_outputs(
    built: Result<crate::homology::overlay::MetaMeshResult>,
    o: &MapOptions,
    arts: &mut Vec<Artifact>,
) -> (MetaMeshStats, Option<Artifact>) {
    let failed = |e: Error| {
        let stats =
            MetaMeshStats { vertices: 0, faces: 0, crossings: 0, pruned_vertices: None, error: Some(e.to_string()) };
        (stats, None)
    };
    let mut m = match built {
        Ok(m) => m,
        Err(e) => return failed(e),
    };
    let mut pruned = None;
    if let Some(deg) = o.dihedral_threshold_deg {
        match prune_meta_mesh(&m, &PruneOptions { dihedral_threshold_deg: deg }) {
            Ok(p) => {
                pruned = Some(p.removed_vertices);
                m = p.mesh;
            }
            Err(e) => return failed(e),
        }
    }
    let stats = MetaMeshStats {
        vertices: m.on_source.len(),
        faces: m.faces.len(),
        crossings: m.crossings,
        pruned_vertices: pruned,
        error: None,
    };
    match m.meshes() {
        Ok((ms, mt)) => {
            arts.push(Artifact {
                name: "meta_source.obj".into(),
                content_type: "model/obj",
                bytes: io::write(&ms, Format::Obj),
            });
            arts.push(Artifact {
                name: "meta_target.obj".into(),
                content_type: "model/obj",
                bytes: io::write(&mt, Format::Obj),
            });
            (stats, Some(morph_glb(&ms, mt.positions())))
        }
        Err(e) => (MetaMeshStats { error: Some(e.to_string()), ..stats }, None),
    }
}

/// Runs a `homology` job.
///
/// # Errors
/// As [`super::run_map`].
pub fn run_homology(
    spec: &JobSpec,
    source: &Mesh,
    target: &Mesh,
    progress: &mut dyn Progress,
) -> Result<(MapReport, Vec<Artifact>)> {
    let mut clock = Clock(Instant::now(), Vec::new());
    let pairs = spec.validate(source, target)?;
    let (sc, tc) = spec.curves(source, target)?;
    if !sc.is_empty() || !crate::topology::boundary_loops(source).is_empty() {
        return super::run_features::run_features(spec, source, target, &pairs, (&sc, &tc), clock, progress);
    }
    let o = &spec.options;
    clock.lap("setup");
    progress.report(crate::progress::Stage::Basis, 0.0);
    let (mut basis, mut rotation, mut want) = (o.basis, o.rotation, None);
    if let Some(entries) = &o.matching {
        let g = crate::topology::summary(source).genus.max(0) as usize;
        let w = parse_matching(g, entries)?;
        let found = find_matching(source, target, pairs[0], &w, &MatchingOptions::default())?;
        (basis, rotation, want) = (found.basis, found.rotation, Some(w));
        clock.lap("matching");
    }
    let hopts = HomologyMapOptions {
        basis,
        rotation,
        max_subdivisions: None,
        // Off by default: reweighting each domain on its own lowers each map's stretch but
        // raised the composed map's folds on every different-shape pair measured.
        stretch_iterations: o.domain_stretch_iterations,
    };
    let r = homology_map(source, target, pairs[0], &pairs[1..], &hopts)?;
    // The induced map read in the reference bases (basis 0 on each mesh), when the bases used
    // are others or a matching was asked for.
    let h1_reference = if want.is_some() || basis != [0, 0] {
        let (fs, ft) = both(|| reference_frame(target, pairs[0].1), || reference_frame(source, pairs[0].0))?;
        let (fs, ft) = (fs?, ft?);
        Some(reference_h1((source, target), (&fs.1, &ft.1), (&r.source.basis, &r.target.basis), &r.h1)?)
    } else {
        None
    };
    if let (Some(w), Some(got)) = (&want, &h1_reference)
        && got != w
    {
        return Err(Error::Numerical(format!(
            "matching: the bases refined for the map induce {got:?} instead of {w:?}"
        )));
    }
    clock.lap("basis_domain_map");
    progress.check()?;
    let f = finish_pair(source, target, (&r.source_to_target, &r.target_to_source), &pairs, (&[], &[]), o, progress)?;
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
        progress.report(crate::progress::Stage::MetaMesh, 0.0);
        let angle = std::f64::consts::TAU * r.side_shift as f64 / (4 * g) as f64;
        let (stats, m) = meta_outputs(crate::homology::overlay::meta_mesh(&r.source, &r.target, angle), o, &mut arts);
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
        h1: r.h1.clone(),
        h1_reference,
        base: [pairs[0].0.0, pairs[0].1.0],
        subdivisions: [r.source.basis.subdivisions, r.target.basis.subdivisions],
        loop_lengths: [len(&r.source), len(&r.target)],
        meta_mesh: meta,
    };
    // The morph: the meta-mesh from source to target when there is one (every detail of both),
    // else the source mesh to its image on the target.
    arts.push(morph.unwrap_or_else(|| morph_glb(source, f.on_target.positions())));
    arts.push(json_artifact("basis_source.json", &basis_json(&r.source))?);
    arts.push(json_artifact("basis_target.json", &basis_json(&r.target))?);
    arts.push(Artifact { name: "domain_source.obj".into(), content_type: "model/obj", bytes: domain_obj(&r.source)? });
    arts.push(Artifact { name: "domain_target.obj".into(), content_type: "model/obj", bytes: domain_obj(&r.target)? });
    clock.lap("artifacts");
    let mut report = pair_report(spec, pairs.len(), (source, target), (f.m1, f.m2), f.smoothing);
    report.homology = Some(report_h);
    finish_report(&mut report, clock, &mut arts)?;
    progress.report(crate::progress::Stage::Done, 1.0);
    Ok((report, arts))
}

/// Both directions after the domain maps, and what they measured.
pub(super) struct FinishedPair {
    pub s2t: SurfaceMap,
    pub t2s: SurfaceMap,
    pub on_target: Mesh,
    pub on_source: Mesh,
    pub m1: MapMetrics,
    pub m2: MapMetrics,
    pub smoothing: SmoothReport,
}

/// Places the anchors exactly, then smooths both directions (anchors and `fixed` held: source
/// vertices, target vertices), makes them visible, repairs folds and measures.
///
/// # Errors
/// As [`finish_direction`].
pub(super) fn finish_pair(
    source: &Mesh,
    target: &Mesh,
    maps: (&SurfaceMap, &SurfaceMap),
    pairs: &[(VertexId, VertexId)],
    fixed: (&[VertexId], &[VertexId]),
    o: &MapOptions,
    progress: &mut dyn Progress,
) -> Result<FinishedPair> {
    let (mut s2t, mut t2s) = (maps.0.clone(), maps.1.clone());
    for &(s, t) in pairs {
        let (f, b) = SurfacePoint::Vertex { vertex: t }.in_face(target);
        s2t.face[s.idx()] = f;
        s2t.bary[s.idx()] = b;
        let (f, b) = SurfacePoint::Vertex { vertex: s }.in_face(source);
        t2s.face[t.idx()] = f;
        t2s.bary[t.idx()] = b;
    }
    let sa: Vec<VertexId> = pairs.iter().map(|p| p.0).chain(fixed.0.iter().copied()).collect();
    let ta: Vec<VertexId> = pairs.iter().map(|p| p.1).chain(fixed.1.iter().copied()).collect();
    let rev: Vec<(VertexId, VertexId)> = pairs.iter().map(|&(s, t)| (t, s)).collect();
    progress.report(crate::progress::Stage::Smooth, 0.0);
    let mut side = progress.silent();
    let (a, b) = both(
        || finish_direction(target, source, t2s, &ta, &rev, o, &mut side, &mut || {}),
        || finish_direction(source, target, s2t, &sa, pairs, o, progress, &mut || {}),
    )?;
    let ((s2t, r1, on_target, m1), (t2s, r2, on_source, m2)) = (a?, b?);
    Ok(FinishedPair { s2t, t2s, on_target, on_source, m1, m2, smoothing: r1.merge(r2) })
}

/// Adds the total to the timings and writes `metrics.json`.
///
/// # Errors
/// `Internal` if the report does not serialize.
pub(super) fn finish_report(report: &mut MapReport, mut clock: Clock, arts: &mut Vec<Artifact>) -> Result<()> {
    let total: f64 = clock.1.iter().map(|x| x.1).sum();
    clock.1.push(("total".into(), total));
    report.timings_ms = clock.1;
    arts.push(json_artifact(
        "metrics.json",
        &serde_json::to_value(&*report).map_err(|e| Error::Internal(e.to_string()))?,
    )?);
    Ok(())
}

pub(super) fn json_artifact(name: &str, v: &serde_json::Value) -> Result<Artifact> {
    let bytes = serde_json::to_vec_pretty(v).map_err(|e| Error::Internal(e.to_string()))?;
    Ok(Artifact { name: name.into(), content_type: "application/json", bytes })
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

/// A basis's loops as named 3D polylines (`a1`, `b1`, …), on its refinement.
pub(super) fn loops_json(b: &crate::homology::CanonicalBasisResult) -> Vec<serde_json::Value> {
    let m = &b.refined.mesh;
    b.loops
        .iter()
        .enumerate()
        .map(|(i, l)| {
            let name = format!("{}{}", if i % 2 == 0 { 'a' } else { 'b' }, i / 2 + 1);
            let pts: Vec<[f64; 3]> = l.iter().map(|&v| m.position(v)).map(|p| [p.x, p.y, p.z]).collect();
            json!({"name": name, "points": pts})
        })
        .collect()
}

/// The planar 4g-gon as a mesh at z = 0.
fn domain_obj(sd: &SideDomain) -> Result<Vec<u8>> {
    planar_obj(&sd.domain.uv, &sd.basis.disk.mesh)
}

/// `morph.glb`: `base` with one morph target, the same vertices at `to` (glTF 2.0, binary).
pub(super) fn morph_glb(base: &Mesh, to: &[P3]) -> Artifact {
    Artifact {
        name: "morph.glb".into(),
        content_type: "model/gltf-binary",
        bytes: io::write_glb(base.positions(), &base.face_indices(), &[("target".into(), to.to_vec())]),
    }
}

/// A planar domain (`uv` per vertex of `disk`) as an OBJ mesh at z = 0.
pub(super) fn planar_obj(uv: &[crate::param::Uv], disk: &Mesh) -> Result<Vec<u8>> {
    let pos: Vec<P3> = uv.iter().map(|p| P3::new(p[0], p[1], 0.0)).collect();
    let m = Mesh::from_triangles(pos, &disk.face_indices())?;
    Ok(io::write(&m, Format::Obj))
}

/// The report of a one-patch pair job, before its method's own section.
pub(super) fn pair_report(
    spec: &JobSpec,
    anchors: usize,
    meshes: (&Mesh, &Mesh),
    metrics: (MapMetrics, MapMetrics),
    smoothing: SmoothReport,
) -> MapReport {
    MapReport {
        method: spec.method.name(),
        anchors,
        patches: 1,
        source_vertices: meshes.0.n_vertices(),
        target_vertices: meshes.1.n_vertices(),
        layout: LayoutStats::default(),
        source_to_target: metrics.0,
        target_to_source: metrics.1,
        timings_ms: Vec::new(),
        smoothing,
        homology: None,
        features: None,
        global: None,
    }
}
