//! Meshes in several parts (eyes, teeth beside a head): the parts pair up through the anchors,
//! each pair is mapped by the job's method on its own, and the maps are joined into one map of
//! the whole meshes, measured as a whole. A part with no anchor, or anchors that pair one part
//! with two, is a typed error naming the part.

use super::anchor_spec::{AnchorRow, id_rows};
use super::common::artifacts::maps_and_meshes as artifacts_of_maps;
use super::common::{Artifact, PairReport, json_artifact};
use super::spec::JobSpec;
use super::{JobReport, run_job};
use crate::error::{InputError, Result};
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, VertexId};
use crate::metrics::{MetricsOptions, evaluate_map};
use crate::progress::Progress;
use crate::topology::{self, components};
use serde::Serialize;

/// The whole pair's metrics and each part pair's own report.
#[derive(Debug, Clone, Serialize)]
pub struct PartsReport {
    #[serde(flatten)]
    pub pair: PairReport,
    /// `[source part, target part]` per mapped pair, in source part order.
    pub part_pairs: Vec<[usize; 2]>,
    pub parts: Vec<JobReport>,
}

/// One connected component as a mesh of its own.
struct Part {
    mesh: Mesh,
    /// Local vertex -> whole vertex.
    vertices: Vec<u32>,
    /// Local face -> whole face.
    faces: Vec<u32>,
}

fn split(m: &Mesh) -> Result<(Vec<Part>, Vec<u32>)> {
    let c = components(m);
    let mut vlabel = vec![0u32; m.n_vertices()];
    let mut parts: Vec<(Vec<u32>, Vec<u32>)> = vec![(Vec::new(), Vec::new()); c.count];
    for (f, tri) in m.faces().iter().enumerate() {
        parts[c.face_label[f] as usize].1.push(f as u32);
        for v in tri {
            vlabel[v.idx()] = c.face_label[f];
        }
    }
    for v in 0..m.n_vertices() {
        parts[vlabel[v] as usize].0.push(v as u32);
    }
    let mut local = vec![0u32; m.n_vertices()];
    let mut out = Vec::with_capacity(c.count);
    for (vs, fs) in parts {
        for (i, &v) in vs.iter().enumerate() {
            local[v as usize] = i as u32;
        }
        let pos = vs.iter().map(|&v| m.positions()[v as usize]).collect();
        let tris: Vec<[u32; 3]> = fs.iter().map(|&f| m.faces()[f as usize].map(|v| local[v.idx()])).collect();
        out.push(Part { mesh: Mesh::from_triangles(pos, &tris)?, vertices: vs, faces: fs });
    }
    Ok((out, vlabel))
}

fn describe(side: &str, k: usize, p: &Part) -> String {
    let s = topology::summary(&p.mesh);
    format!("{side} part {k} ({} vertices, genus {}, first vertex {})", s.vertices, s.genus, p.vertices[0])
}

/// Runs a pair job part by part when either mesh has several parts; `None` otherwise.
///
/// # Errors
/// `InputError::Anchors` naming a part without anchors or paired twice; the method's errors.
pub fn run(spec: &JobSpec, meshes: &[Mesh], progress: &mut dyn Progress) -> Result<Option<(JobReport, Vec<Artifact>)>> {
    let ([s, t], Some(rows)) = (meshes, anchor_rows(spec)) else { return Ok(None) };
    if topology::components(s).count == 1 && topology::components(t).count == 1 {
        return Ok(None);
    }
    let rows = id_rows(rows)?;
    if let Some((i, r)) =
        rows.iter().enumerate().find(|(_, r)| r[0] >= s.n_vertices() as u64 || r[1] >= t.n_vertices() as u64)
    {
        return Err(InputError::Anchors(format!(
            "anchor {i}: [{}, {}] is out of range (source {} vertices, target {})",
            r[0],
            r[1],
            s.n_vertices(),
            t.n_vertices()
        ))
        .into());
    }
    let ((sp, sl), (tp, tl)) = (split(s)?, split(t)?);
    if sp.len() != tp.len() {
        return Err(InputError::TopologyMismatch(format!(
            "the source has {} parts, the target {}: parts map one to one",
            sp.len(),
            tp.len()
        ))
        .into());
    }
    let mut partner = vec![usize::MAX; sp.len()];
    let mut back = vec![usize::MAX; tp.len()];
    for r in &rows {
        let (a, b) = (sl[r[0] as usize] as usize, tl[r[1] as usize] as usize);
        if (partner[a] != usize::MAX && partner[a] != b) || (back[b] != usize::MAX && back[b] != a) {
            return Err(InputError::Anchors(format!(
                "anchors pair {} with more than one target part (or a target part with two): each part's anchors must lie on one partner",
                describe("source", a, &sp[a])
            ))
            .into());
        }
        (partner[a], back[b]) = (b, a);
    }
    if let Some(a) = partner.iter().position(|&b| b == usize::MAX) {
        return Err(InputError::Anchors(format!(
            "{} has no anchor: give each part its own anchors",
            describe("source", a, &sp[a])
        ))
        .into());
    }
    let mut parts = Vec::with_capacity(sp.len());
    let mut arts = Vec::new();
    let (mut s2t, mut t2s) = (
        SurfaceMap { face: vec![FaceId(0); s.n_vertices()], bary: vec![[0.0; 3]; s.n_vertices()] },
        SurfaceMap { face: vec![FaceId(0); t.n_vertices()], bary: vec![[0.0; 3]; t.n_vertices()] },
    );
    for (a, &b) in partner.iter().enumerate() {
        let (ps, pt) = (&sp[a], &tp[b]);
        let (mut ls, mut lt) = (vec![u64::MAX; s.n_vertices()], vec![u64::MAX; t.n_vertices()]);
        ps.vertices.iter().enumerate().for_each(|(i, &v)| ls[v as usize] = i as u64);
        pt.vertices.iter().enumerate().for_each(|(i, &v)| lt[v as usize] = i as u64);
        let local: Vec<[u64; 2]> = rows
            .iter()
            .filter(|r| sl[r[0] as usize] as usize == a)
            .map(|r| [ls[r[0] as usize], lt[r[1] as usize]])
            .collect();
        // `boundaries` rows (open parts) in the part's own numbering.
        let mut bounds = Vec::new();
        for (i, r) in boundary_rows(spec).iter().enumerate() {
            let (Some(&ps_l), Some(&pt_l)) = (sl.get(r[0] as usize), lt.get(r[1] as usize)) else { continue };
            if ps_l as usize != a {
                continue;
            }
            if pt_l == u64::MAX {
                return Err(InputError::Anchors(format!(
                    "boundaries row {i} pairs a loop of source part {a} with a loop outside its partner part"
                ))
                .into());
            }
            bounds.push([ls[r[0] as usize], pt_l]);
        }
        let sub = with_anchors(spec, AnchorRow::ids(local), bounds);
        let (rep, part_arts) = run_job(&sub, &[ps.mesh.clone(), pt.mesh.clone()], progress)?;
        let maps =
            rep.pair().and_then(|p| p.maps.clone()).ok_or_else(|| crate::Error::Internal("a part's maps".into()))?;
        for (i, &v) in ps.vertices.iter().enumerate() {
            s2t.face[v as usize] = FaceId(pt.faces[maps.s2t.face[i].idx()]);
            s2t.bary[v as usize] = maps.s2t.bary[i];
        }
        for (i, &v) in pt.vertices.iter().enumerate() {
            t2s.face[v as usize] = FaceId(ps.faces[maps.t2s.face[i].idx()]);
            t2s.bary[v as usize] = maps.t2s.bary[i];
        }
        arts.extend(part_arts.into_iter().map(|x| Artifact { name: format!("part{a}_{}", x.name), ..x }));
        parts.push(rep);
    }
    let samples = match spec {
        JobSpec::Voronoi(x) | JobSpec::Greedy(x) => x.options.metric_samples,
        JobSpec::Homology(x) => x.options.metric_samples,
        JobSpec::Spherical(x) => x.options.metric_samples,
        JobSpec::Auto(x) => x.options.metric_samples,
        JobSpec::Quad(_) => 100_000,
    };
    let mo = MetricsOptions { samples, ..Default::default() };
    let (on_target, on_source) = (s2t.embed(s, t)?, t2s.embed(t, s)?);
    let anchors: Vec<(VertexId, VertexId)> =
        rows.iter().map(|r| (VertexId(r[0] as u32), VertexId(r[1] as u32))).collect();
    let back_anchors: Vec<(VertexId, VertexId)> = anchors.iter().map(|&(a, b)| (b, a)).collect();
    let m1 = evaluate_map(s, t, &on_target, Some(&anchors), None, &mo)?;
    let m2 = evaluate_map(t, s, &on_source, Some(&back_anchors), None, &mo)?;
    arts.extend(artifacts_of_maps(&s2t, &t2s, &on_target, &on_source));
    let pair =
        PairReport::new(spec.method().name(), rows.len(), (s, t), (m1, m2), Default::default()).with_maps(s2t, t2s);
    let part_pairs = partner.iter().enumerate().map(|(a, &b)| [a, b]).collect();
    let report = JobReport::Parts(Box::new(PartsReport { pair, part_pairs, parts }));
    arts.push(json_artifact("metrics.json", &report)?);
    Ok(Some((report, arts)))
}

fn anchor_rows(spec: &JobSpec) -> Option<&[AnchorRow]> {
    match spec {
        JobSpec::Voronoi(s) | JobSpec::Greedy(s) => Some(&s.anchors),
        JobSpec::Homology(s) if s.features.is_empty() => Some(&s.anchors),
        _ => None,
    }
}

fn boundary_rows(spec: &JobSpec) -> &[[u64; 2]] {
    match spec {
        JobSpec::Voronoi(s) | JobSpec::Greedy(s) => &s.boundaries,
        _ => &[],
    }
}

fn with_anchors(spec: &JobSpec, anchors: Vec<AnchorRow>, boundaries: Vec<[u64; 2]>) -> JobSpec {
    let mut s = spec.clone();
    match &mut s {
        JobSpec::Voronoi(x) | JobSpec::Greedy(x) => {
            (x.anchors, x.boundaries, x.options.transfer) = (anchors, boundaries, Vec::new());
            x.options.inverse_morph = false;
        }
        JobSpec::Homology(x) => {
            (x.anchors, x.options.transfer) = (anchors, Vec::new());
            x.options.inverse_morph = false;
        }
        JobSpec::Spherical(x) => {
            (x.anchors, x.options.transfer) = (anchors, Vec::new());
            x.options.inverse_morph = false;
        }
        JobSpec::Auto(x) => {
            (x.anchors, x.options.transfer) = (anchors, Vec::new());
            x.options.inverse_morph = false;
        }
        JobSpec::Quad(_) => {}
    }
    s
}
