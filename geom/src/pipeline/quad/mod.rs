//! `quad`: the job over N meshes. Partition -> consistent parameterization ->
//! uniform or adaptive remesh -> geometry images and normal maps -> morphs -> metrics, with
//! progress, cancellation and per-stage timings.

use crate::error::{Error, Result};
use crate::io::{self, Format};
use crate::mesh::{Mesh, P3};
use crate::metrics::hausdorff;
use crate::pipeline::common::{Artifact, Clock};
use crate::pipeline::spec::quad_spec::{MorphDomain, QuadSpec};
use crate::progress::{Progress, Stage};
use crate::quad::consistent::{ConsistentOptions, ConsistentResult, consistent_parameterization};
use crate::quad::remesh::{RemeshGrid, sample_uniform, sample_with_normals, uniform_grid};
use crate::quad::stretch::PatchSoup;
use crate::quad::surface::{PatchSurface, QuadSurface};
use crate::quad::{PartitionOptions, QuadLayout, QuadParamOptions, adaptive, morph, tri_quads};
use crate::topology;
use serde::Serialize;
use serde_json::json;

/// One patch of one model.
#[derive(Debug, Clone, Serialize)]
pub struct PatchReport {
    pub vertices: usize,
    pub base_vertices: usize,
    /// Normalized L2 / L∞ stretch of the mean-value map of the whole patch (the start) and of
    /// the final map.
    pub stretch_mv: [f64; 2],
    pub stretch: [f64; 2],
    pub flipped_uv: usize,
    /// Triangles with zero parameter area (left out of the stretch; only the `voronoi` layout's
    /// refinement can leave them, with all three corners on one side of a triangle).
    pub flat_uv: usize,
    pub warp_events: usize,
    pub warp_repaired: usize,
}

/// One model of a `quad` job.
#[derive(Debug, Clone, Serialize)]
pub struct ModelReport {
    pub vertices: usize,
    pub faces: usize,
    pub subdivisions: usize,
    pub patches: Vec<PatchReport>,
    /// Stretch over all patches together (mean-value start, final).
    pub stretch_mv: [f64; 2],
    pub stretch: [f64; 2],
    /// Remesh against the original, sampled both ways as the shared evaluator does.
    pub psnr_db: f64,
    /// Symmetric Hausdorff distance and RMS, divided by the original's bbox diagonal.
    pub hausdorff: f64,
    pub rms: f64,
}

/// What a `quad` job measured (also written as `metrics.json`).
#[derive(Debug, Clone, Serialize)]
pub struct QuadReport {
    pub method: &'static str,
    pub models: usize,
    pub level: u32,
    pub adaptive_epsilon: Option<f64>,
    pub patches: usize,
    pub feature_points: usize,
    /// Largest distance between a feature's (u, v) on any model and the common one.
    pub feature_uv_error: f64,
    pub remesh_vertices: usize,
    pub remesh_faces: usize,
    pub remesh_quads: usize,
    pub per_model: Vec<ModelReport>,
    pub timings_ms: Vec<(String, f64)>,
}

/// The remesh connectivity and every model's positions on it.
pub struct Remeshes {
    pub faces: Vec<[u32; 3]>,
    pub quads: usize,
    pub positions: Vec<Vec<P3>>,
    /// The uniform grid behind it (the wavelet morph needs one).
    pub grid: Option<RemeshGrid>,
}

/// A `quad` job's quads on every model, whatever built them, and what the build measured.
pub struct Built<'a> {
    pub layout: QuadLayout,
    pub surfaces: Vec<Box<dyn QuadSurface + 'a>>,
    /// Per model: patch reports, stretch (start, final), partition subdivisions.
    pub patches: Vec<Vec<PatchReport>>,
    pub stretch: Vec<([f64; 2], [f64; 2])>,
    pub subdivisions: Vec<usize>,
    /// Per model: `param_<i>.obj`.
    pub params: Vec<Vec<u8>>,
    pub feature_points: usize,
    pub feature_uv_error: f64,
}

/// The genus-0 build: partition, consistent parameterization, feature alignment.
fn build_genus0<'a>(cp: &'a ConsistentResult) -> Result<Built<'a>> {
    let mut feature_uv_error: f64 = 0.0;
    for model in &cp.models {
        for (p, patch) in model.partition.patches.iter().enumerate() {
            for &(k, v) in &patch.features {
                let (fp, t) = cp.features[k];
                let q = model.patches[p].uv[v.idx()];
                let e = if fp == p { ((q[0] - t[0]).powi(2) + (q[1] - t[1]).powi(2)).sqrt() } else { f64::INFINITY };
                feature_uv_error = feature_uv_error.max(e);
            }
        }
    }
    let mut b = Built {
        layout: cp.layout.clone(),
        surfaces: Vec::new(),
        patches: Vec::new(),
        stretch: Vec::new(),
        subdivisions: Vec::new(),
        params: Vec::new(),
        feature_points: cp.features.len(),
        feature_uv_error,
    };
    for model in &cp.models {
        let uvs: Vec<&[[f64; 2]]> = model.patches.iter().map(|p| p.uv.as_slice()).collect();
        b.surfaces.push(Box::new(PatchSurface::new(&model.partition.patches, uvs)));
        let mut reports = Vec::new();
        let mut soup = PatchSoup::default();
        for (p, r) in model.patches.iter().enumerate() {
            let pm = &model.partition.patches[p].mesh;
            reports.push(PatchReport {
                vertices: pm.n_vertices(),
                base_vertices: r.base_vertices,
                stretch_mv: [r.stretch_mv.0, r.stretch_mv.1],
                stretch: [r.stretch_final.0, r.stretch_final.1],
                flipped_uv: r.flipped,
                flat_uv: 0,
                warp_events: model.warp[p].events,
                warp_repaired: model.warp[p].repaired,
            });
            soup.add(pm.positions(), &pm.face_indices(), &r.uv_mv, &r.uv);
        }
        let (s_mv, s) = soup.stretch();
        b.patches.push(reports);
        b.stretch.push(([s_mv.0, s_mv.1], [s.0, s.1]));
        b.subdivisions.push(model.partition.subdivisions);
        let parts: Vec<(&Mesh, &[[f64; 2]])> =
            model.partition.patches.iter().zip(&model.patches).map(|(p, r)| (&p.mesh, r.uv.as_slice())).collect();
        b.params.push(io::write_obj_uv_patches(&parts));
    }
    Ok(b)
}

/// The higher-genus build: the `voronoi` layout's triangles, three quads each.
fn build_tri(tq: &tri_quads::TriQuads, rows: usize) -> Built<'_> {
    let mut b = Built {
        layout: tq.layout.clone(),
        surfaces: Vec::new(),
        patches: Vec::new(),
        stretch: Vec::new(),
        subdivisions: Vec::new(),
        params: Vec::new(),
        feature_points: rows.saturating_sub(4),
        // Every anchor is a quad corner on every model.
        feature_uv_error: 0.0,
    };
    for m in &tq.models {
        b.surfaces.push(Box::new(m));
        b.patches.push(
            m.params
                .iter()
                .zip(&m.stretch)
                .map(|(p, (s0, s1))| {
                    let inj = crate::param::check_injective(&p.local, &p.uv);
                    PatchReport {
                        vertices: p.local.n_vertices(),
                        base_vertices: 0,
                        stretch_mv: [s0.0, s0.1],
                        stretch: [s1.0, s1.1],
                        flipped_uv: inj.flipped,
                        flat_uv: inj.degenerate,
                        warp_events: 0,
                        warp_repaired: 0,
                    }
                })
                .collect(),
        );
        b.stretch.push(([m.total.0.0, m.total.0.1], [m.total.1.0, m.total.1.1]));
        b.subdivisions.push(0);
        let parts: Vec<(&Mesh, &[[f64; 2]])> = m.params.iter().map(|p| (&p.local, p.uv.as_slice())).collect();
        b.params.push(io::write_obj_uv_patches(&parts));
    }
    b
}

/// Runs a `quad` job over `meshes`.
///
/// # Errors
/// Input errors of the spec and meshes, layout conflicts, numerical failures, `Cancelled`.
pub fn run(spec: &QuadSpec, meshes: &[Mesh], progress: &mut dyn Progress) -> Result<(QuadReport, Vec<Artifact>)> {
    let mut clock = Clock::start();
    let summaries: Vec<_> = meshes.iter().map(topology::summary).collect();
    let rows = spec.check(&summaries)?;
    let o = &spec.options;
    clock.lap("setup");
    let refs: Vec<&Mesh> = meshes.iter().collect();
    let cp;
    let tq;
    let built = if summaries[0].genus == 0 {
        let copts = ConsistentOptions {
            partition: PartitionOptions::default(),
            param: QuadParamOptions { base_interior: o.base_vertices, ..Default::default() },
        };
        cp = consistent_parameterization(&refs, &rows, &copts, progress)?;
        build_genus0(&cp)?
    } else {
        tq = tri_quads::tri_quads(&refs, &rows, progress)?;
        build_tri(&tq, rows.len())
    };
    clock.lap("parameterize");
    progress.check()?;
    progress.report(Stage::Remesh, 0.0);
    let rm = remesh_all(&built, o.level, o.adaptive_epsilon, meshes)?;
    clock.lap("remesh");
    let mut arts = Vec::new();
    let image_level = o.image_level.unwrap_or(o.level.min(8));
    if image_level > 0 {
        progress.check()?;
        progress.report(Stage::Images, 0.0);
        arts.extend(geometry_images(&built, image_level)?);
        clock.lap("images");
    }
    progress.check()?;
    progress.report(Stage::Metrics, 0.0);
    let mut per_model = Vec::with_capacity(meshes.len());
    for (m, mesh) in meshes.iter().enumerate() {
        progress.check()?;
        progress.report(Stage::Metrics, m as f64 / meshes.len() as f64);
        per_model.push(model_report(&built, m, mesh, &rm, o.metric_samples)?);
    }
    clock.lap("metrics");
    progress.report(Stage::Morph, 0.0);
    arts.extend(mesh_artifacts(&built, &rm)?);
    arts.extend(morph_artifacts(spec, &rm)?);
    clock.lap("artifacts");
    let report = QuadReport {
        method: "quad",
        models: meshes.len(),
        level: o.level,
        adaptive_epsilon: o.adaptive_epsilon,
        patches: built.layout.patches.len(),
        feature_points: built.feature_points,
        feature_uv_error: built.feature_uv_error,
        remesh_vertices: rm.positions[0].len(),
        remesh_faces: rm.faces.len(),
        remesh_quads: rm.quads,
        per_model,
        timings_ms: clock.finish(),
    };
    progress.report(Stage::Done, 1.0);
    Ok((report, arts))
}

/// Uniform remeshes at `level`, or adaptive ones (consistent over the models) below `epsilon`.
///
/// # Errors
/// `Internal` on a layout mismatch.
pub fn remesh_all(b: &Built, level: u32, epsilon: Option<f64>, meshes: &[Mesh]) -> Result<Remeshes> {
    let surfs: Vec<&dyn QuadSurface> = b.surfaces.iter().map(|s| s.as_ref() as &dyn QuadSurface).collect();
    if let Some(eps) = epsilon {
        let r = adaptive::adaptive_remesh(&b.layout, &surfs, meshes, eps, level)?;
        return Ok(Remeshes { faces: r.faces, quads: r.quads, positions: r.positions, grid: None });
    }
    let grid = uniform_grid(&b.layout, level)?;
    let positions = surfs.iter().map(|s| sample_uniform(&grid, *s)).collect::<Result<Vec<_>>>()?;
    Ok(Remeshes { faces: grid.faces.clone(), quads: grid.faces.len() / 2, positions, grid: Some(grid) })
}

fn model_report(b: &Built, m: usize, mesh: &Mesh, rm: &Remeshes, samples: usize) -> Result<ModelReport> {
    let remesh = Mesh::from_triangles(rm.positions[m].clone(), &rm.faces)
        .map_err(|e| Error::Internal(format!("remesh {m} is not a valid mesh: {e}")))?;
    let h = hausdorff(&remesh, mesh, samples, (1, 2))?;
    let diag = mesh.bbox_diagonal();
    Ok(ModelReport {
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        subdivisions: b.subdivisions[m],
        patches: b.patches[m].clone(),
        stretch_mv: b.stretch[m].0,
        stretch: b.stretch[m].1,
        psnr_db: 20.0 * (1.0 / (h.rms / diag).max(1e-300)).log10(),
        hausdorff: h.hausdorff / diag,
        rms: h.rms / diag,
    })
}

fn mesh_artifacts(b: &Built, rm: &Remeshes) -> Result<Vec<Artifact>> {
    let mut arts = Vec::new();
    for (m, pos) in rm.positions.iter().enumerate() {
        let mesh = Mesh::from_triangles(pos.clone(), &rm.faces)
            .map_err(|e| Error::Internal(format!("remesh {m} is not a valid mesh: {e}")))?;
        arts.push(Artifact {
            name: format!("remesh_{m}.obj"),
            content_type: "model/obj",
            bytes: io::write(&mesh, Format::Obj),
        });
        arts.push(Artifact { name: format!("param_{m}.obj"), content_type: "model/obj", bytes: b.params[m].clone() });
    }
    Ok(arts)
}

/// One geometry image (positions quantized to 16 bits in the model's bounding box) and one
/// normal map per quad and model, and `geometry_images.json` with the boxes to dequantize.
fn geometry_images(b: &Built, level: u32) -> Result<Vec<Artifact>> {
    let grid = uniform_grid(&b.layout, level)?;
    let side = (grid.n + 1) as u32;
    let mut arts = Vec::new();
    let mut boxes = Vec::new();
    for (m, surf) in b.surfaces.iter().enumerate() {
        let (pos, nor) = sample_with_normals(&grid, surf.as_ref())?;
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &pos {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let q = |x: f64, k: usize| {
            let span = (hi[k] - lo[k]).max(f64::MIN_POSITIVE);
            (((x - lo[k]) / span).clamp(0.0, 1.0) * 65535.0).round() as u16
        };
        for (p, nd) in grid.node.iter().enumerate() {
            // Image rows top to bottom = v from 1 down to 0.
            let mut gi = Vec::with_capacity(nd.len());
            let mut nm = Vec::with_capacity(nd.len());
            for j in (0..side as usize).rev() {
                for i in 0..side as usize {
                    let v = nd[j * side as usize + i] as usize;
                    gi.push([0, 1, 2].map(|k| q(pos[v][k], k)));
                    nm.push([0, 1, 2].map(|k| (((nor[v][k] + 1.0) * 0.5).clamp(0.0, 1.0) * 65535.0).round() as u16));
                }
            }
            arts.push(Artifact {
                name: format!("geometry_{m}_patch{p}.png"),
                content_type: "image/png",
                bytes: io::write_rgb16(side, side, &gi)?,
            });
            arts.push(Artifact {
                name: format!("normal_{m}_patch{p}.png"),
                content_type: "image/png",
                bytes: io::write_rgb16(side, side, &nm)?,
            });
        }
        boxes.push(json!({"model": m, "bbox_min": lo, "bbox_max": hi}));
    }
    let doc = json!({
        "level": level,
        "size": side,
        "patches": b.layout.patches.len(),
        "encoding": "16-bit RGB; position = bbox_min + pixel / 65535 * (bbox_max - bbox_min); normal = 2 * pixel / 65535 - 1; row 0 is v = 1",
        "models": boxes,
    });
    arts.push(Artifact {
        name: "geometry_images.json".into(),
        content_type: "application/json",
        bytes: serde_json::to_vec_pretty(&doc).map_err(|e| Error::Internal(e.to_string()))?,
    });
    Ok(arts)
}

fn morph_artifacts(spec: &QuadSpec, rm: &Remeshes) -> Result<Vec<Artifact>> {
    let mo = &spec.options.morph;
    let targets: Vec<(String, Vec<P3>)> =
        rm.positions[1..].iter().enumerate().map(|(k, p)| (format!("model_{}", k + 1), p.clone())).collect();
    let mut arts = vec![Artifact {
        name: "morph.glb".into(),
        content_type: "model/gltf-binary",
        bytes: io::write_glb(&rm.positions[0], &rm.faces, &targets),
    }];
    let obj = |pos: Vec<P3>| -> Result<Vec<u8>> {
        let m =
            Mesh::from_triangles(pos, &rm.faces).map_err(|e| Error::Internal(format!("morph frame invalid: {e}")))?;
        Ok(io::write(&m, Format::Obj))
    };
    if mo.frames > 0 {
        let coefs: Option<Vec<morph::Coefficients>> = match (mo.domain, &rm.grid) {
            (MorphDomain::Wavelet, Some(g)) => Some(rm.positions.iter().map(|p| morph::analyze(g, p)).collect()),
            (MorphDomain::Wavelet, None) => {
                return Err(crate::InputError::Spec(
                    "the wavelet morph needs uniform remeshing (no adaptive_epsilon)".into(),
                )
                .into());
            }
            _ => None,
        };
        for f in 0..mo.frames {
            let t = if mo.frames == 1 { 0.0 } else { f as f64 / (mo.frames - 1) as f64 };
            let pos = match (&coefs, &rm.grid) {
                (Some(c), Some(g)) => morph::wavelet_morph(g, c, t, &mo.schedule),
                _ => morph::spatial(&rm.positions, t, mo.interpolation),
            };
            arts.push(Artifact { name: format!("morph_{f:03}.obj"), content_type: "model/obj", bytes: obj(pos)? });
        }
    }
    for (k, w) in mo.weights.iter().enumerate() {
        arts.push(Artifact {
            name: format!("blend_{k}.obj"),
            content_type: "model/obj",
            bytes: obj(morph::blend(&rm.positions, w))?,
        });
    }
    Ok(arts)
}
