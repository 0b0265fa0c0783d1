//! Consistent parameterization of N models (Yu & Chuang, section 3.1 steps 1–2): partition
//! every model by the same four partition points, build every patch's base embedding, move
//! corresponding feature points to their average (u, v) by the foldover-free warp, then refine
//! each patch coarse to fine with the features frozen. Corresponding features end at the same
//! (u, v) exactly, in the same patch on every model, or the job stops with a typed error.

use super::layout::QuadLayout;
use super::partition::{PartitionOptions, PartitionResult, partition_genus0_sided};
use super::patch_param::{PatchParamResult, QuadParamOptions, base_embedding, coarse_to_fine};
use super::warp::{WarpResult, align_features};
use crate::error::{InputError, Result};
use crate::mesh::{Mesh, VertexId};
use crate::param::Uv;
use crate::progress::Progress;

/// Options of [`consistent_parameterization`].
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ConsistentOptions {
    pub partition: PartitionOptions,
    pub param: QuadParamOptions,
}

/// One model's partition and patch parameterizations.
#[derive(Debug, Clone)]
pub struct ModelParam {
    pub partition: PartitionResult,
    pub patches: Vec<PatchParamResult>,
    /// Per patch: the feature alignment's events and repairs.
    pub warp: Vec<WarpResult>,
}

/// Output of [`consistent_parameterization`].
#[derive(Debug, Clone)]
pub struct ConsistentResult {
    pub layout: QuadLayout,
    pub models: Vec<ModelParam>,
    /// Per feature: its patch and its common (u, v).
    pub features: Vec<(usize, Uv)>,
}

/// Parameterizes `meshes` consistently; `rows[r][m]` is anchor row `r` on model `m`, the
/// first four rows being the partition points and the rest feature points.
///
/// # Errors
/// `InputError::Anchors` for fewer than four rows or rows of the wrong width,
/// `InputError::LayoutConflict` when a feature falls in different patches on different models,
/// partition and parameterization errors, `Cancelled`.
pub fn consistent_parameterization(
    meshes: &[&Mesh],
    rows: &[Vec<VertexId>],
    opts: &ConsistentOptions,
    progress: &mut dyn Progress,
) -> Result<ConsistentResult> {
    if rows.len() < 4 {
        return Err(InputError::Anchors(format!("need 4 partition points, got {} anchor rows", rows.len())).into());
    }
    if let Some((r, row)) = rows.iter().enumerate().find(|(_, row)| row.len() != meshes.len()) {
        return Err(InputError::Anchors(format!(
            "anchor row {r} has {} entries for {} meshes",
            row.len(),
            meshes.len()
        ))
        .into());
    }
    let layout = QuadLayout::genus0();
    let mut partitions: Vec<PartitionResult> = Vec::with_capacity(meshes.len());
    let mut want: Option<Vec<usize>> = None;
    for (m, mesh) in meshes.iter().enumerate() {
        progress.check()?;
        progress.report(crate::progress::Stage::Partition, m as f64 / meshes.len() as f64);
        let points = [rows[0][m], rows[1][m], rows[2][m], rows[3][m]];
        let features: Vec<VertexId> = rows[4..].iter().map(|r| r[m]).collect();
        let part =
            partition_genus0_sided(mesh, points, &features, want.as_deref(), &opts.partition).map_err(|e| match e {
                crate::Error::Input(InputError::LayoutConflict(msg)) => {
                    InputError::LayoutConflict(format!("model {m}: {msg}")).into()
                }
                e => e,
            })?;
        if want.is_none() {
            // Model 0 decides which patch each feature belongs to.
            let mut w = vec![0; features.len()];
            for (p, patch) in part.patches.iter().enumerate() {
                for &(k, _) in &patch.features {
                    w[k] = p;
                }
            }
            want = Some(w);
        }
        partitions.push(part);
    }
    // Each feature's patch, the same on every model.
    let n_features = rows.len() - 4;
    let mut feature_patch = vec![usize::MAX; n_features];
    for (m, part) in partitions.iter().enumerate() {
        for (p, patch) in part.patches.iter().enumerate() {
            for &(k, _) in &patch.features {
                if m == 0 {
                    feature_patch[k] = p;
                } else if feature_patch[k] != p {
                    return Err(InputError::LayoutConflict(format!(
                        "feature point {k} lies in patch {} on model 0 but in patch {p} on model {m}",
                        feature_patch[k]
                    ))
                    .into());
                }
            }
        }
    }
    let mut models: Vec<ModelParam> = partitions
        .into_iter()
        .map(|partition| ModelParam { partition, patches: Vec::new(), warp: Vec::new() })
        .collect();
    let mut features = vec![(0usize, [0.0; 2]); n_features];
    for p in 0..layout.patches.len() {
        let mut bases = Vec::with_capacity(models.len());
        for model in &models {
            progress.check()?;
            bases.push(base_embedding(&model.partition.patches[p], &opts.param)?);
        }
        // Average (u, v) of each feature of this patch over the models.
        let mut targets: Vec<(usize, Uv)> = Vec::new();
        for &(k, _) in &models[0].partition.patches[p].features {
            let mut avg = [0.0; 2];
            for (model, base) in models.iter().zip(&bases) {
                let v = local_feature(&model.partition.patches[p], k)?;
                let q = base.state.uv[v.idx()];
                avg = [avg[0] + q[0], avg[1] + q[1]];
            }
            let n = models.len() as f64;
            targets.push((k, [avg[0] / n, avg[1] / n]));
            features[k] = (p, [avg[0] / n, avg[1] / n]);
        }
        for (m, (model, mut base)) in models.iter_mut().zip(bases).enumerate() {
            let patch = &model.partition.patches[p];
            let mut moves = Vec::with_capacity(targets.len());
            for &(k, t) in &targets {
                moves.push((local_feature(patch, k)?.0, t));
            }
            let warp = align_features(&mut base.state, patch.corners.map(|c| c.0), &moves).map_err(|e| match e {
                crate::Error::Numerical(msg) => crate::Error::Numerical(format!(
                    "model {m}, patch {p}: {msg} while moving the feature points of anchor rows {:?} to their common (u, v); \
                     their positions relative to the partition loop differ too much between the models: \
                     move a partition point or drop one of these feature points",
                    targets.iter().map(|&(k, _)| k + 4).collect::<Vec<_>>()
                )),
                e => e,
            })?;
            let frozen: Vec<VertexId> = moves.iter().map(|&(v, _)| VertexId(v)).collect();
            let r = coarse_to_fine(patch, base, &frozen, &opts.param, progress)?;
            model.patches.push(r);
            model.warp.push(warp);
        }
    }
    Ok(ConsistentResult { layout, models, features })
}

fn local_feature(patch: &super::partition::PatchMesh, k: usize) -> Result<VertexId> {
    patch
        .features
        .iter()
        .find(|&&(j, _)| j == k)
        .map(|&(_, v)| v)
        .ok_or_else(|| crate::Error::Internal(format!("feature {k} missing from its patch")))
}
