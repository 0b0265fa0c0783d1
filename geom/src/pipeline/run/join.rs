//! The part pairs' maps joined into one map of the whole meshes, measured as a whole.

use crate::error::Result;
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, VertexId};
use crate::metrics::{MetricsOptions, evaluate_map};
use crate::pipeline::common::artifacts::maps_and_meshes as artifacts_of_maps;
use crate::pipeline::common::{Artifact, PairReport};
use crate::pipeline::plan::parts::PartsPlan;
use crate::pipeline::report::{JobReport, MethodOutput, PartsReport};
use crate::pipeline::spec::Method;

/// Joins each part pair's maps into the whole meshes' maps, measured as a whole; each part's
/// artifacts come with a `partK_` prefix.
///
/// # Errors
/// `Internal` when a part's report has no maps; the metrics' errors.
pub fn join(
    plan: &PartsPlan,
    meshes: &[Mesh],
    method: Method,
    samples: usize,
    outputs: Vec<MethodOutput>,
) -> Result<MethodOutput> {
    let [s, t] = meshes else { return Err(crate::Error::Internal("a parts job without two meshes".into())) };
    let mut parts = Vec::with_capacity(outputs.len());
    let mut arts = Vec::new();
    let (mut s2t, mut t2s) = (
        SurfaceMap { face: vec![FaceId(0); s.n_vertices()], bary: vec![[0.0; 3]; s.n_vertices()] },
        SurfaceMap { face: vec![FaceId(0); t.n_vertices()], bary: vec![[0.0; 3]; t.n_vertices()] },
    );
    for (a, (pair, out)) in plan.pairs.iter().zip(outputs).enumerate() {
        let rep = out.report;
        let maps =
            rep.pair().and_then(|p| p.maps.clone()).ok_or_else(|| crate::Error::Internal("a part's maps".into()))?;
        let ([sv, tv], [sf, tf]) = (&pair.vertices, &pair.faces);
        for (i, &v) in sv.iter().enumerate() {
            s2t.face[v as usize] = FaceId(tf[maps.s2t.face[i].idx()]);
            s2t.bary[v as usize] = maps.s2t.bary[i];
        }
        for (i, &v) in tv.iter().enumerate() {
            t2s.face[v as usize] = FaceId(sf[maps.t2s.face[i].idx()]);
            t2s.bary[v as usize] = maps.t2s.bary[i];
        }
        arts.extend(out.artifacts.into_iter().map(|x| Artifact { name: format!("part{a}_{}", x.name), ..x }));
        parts.push(rep);
    }
    let mo = MetricsOptions { samples, ..Default::default() };
    let (on_target, on_source) = (s2t.embed(s, t)?, t2s.embed(t, s)?);
    let anchors: Vec<(VertexId, VertexId)> =
        plan.rows.iter().map(|r| (VertexId(r[0] as u32), VertexId(r[1] as u32))).collect();
    let back_anchors: Vec<(VertexId, VertexId)> = anchors.iter().map(|&(a, b)| (b, a)).collect();
    let m1 = evaluate_map(s, t, &on_target, Some(&anchors), None, &mo)?;
    let m2 = evaluate_map(t, s, &on_source, Some(&back_anchors), None, &mo)?;
    arts.extend(artifacts_of_maps(&s2t, &t2s, &on_target, &on_source));
    let pair =
        PairReport::new(method.name(), plan.rows.len(), (s, t), (m1, m2), Default::default()).with_maps(s2t, t2s);
    let report = JobReport::Parts(Box::new(PartsReport { pair, part_pairs: plan.part_pairs.clone(), parts }));
    Ok(MethodOutput { report, artifacts: arts })
}
