//! The spec of a `quad` job over N meshes (`surfmap remesh`, the server's N-mesh jobs):
//! `{"method": "quad", "anchors": [[v_1, ..., v_N], ...], "options": {...}}` (the `quad` variant
//! of [`crate::pipeline::JobSpec`]), validated against the meshes before any work starts. The first four anchor rows are the partition points, the
//! rest (and `options.feature_anchors`) are feature points.

use crate::error::{InputError, Result};
use crate::mesh::VertexId;
use crate::pipeline::spec::limits::{MAX_ANCHORS, MAX_MODELS};
pub use crate::quad::morph::{Interpolation, LevelSchedule};
use crate::topology;
use serde::{Deserialize, Serialize};

/// Where the morph interpolates.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "snake_case")]
pub enum MorphDomain {
    #[default]
    Spatial,
    /// Lifting-wavelet coefficients, each level on its own schedule.
    Wavelet,
}

/// Morph outputs: `morph.glb` always; OBJ frames when `frames > 0`; one OBJ per weight vector.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct MorphOptions {
    /// OBJ frames `morph_000.obj`, … over t in [0, 1] through the models in order.
    pub frames: usize,
    pub interpolation: Interpolation,
    pub domain: MorphDomain,
    /// Wavelet schedules, coarsest level first; missing levels get the default (finer levels
    /// start later and blend faster).
    pub schedule: Vec<LevelSchedule>,
    /// Multi-target blends: each a weight per model, written as `blend_<k>.obj`.
    pub weights: Vec<Vec<f64>>,
}

/// Options of a `quad` job. Every field has a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct QuadOptions {
    /// Uniform remeshing level: `(2^level + 1)²` samples per patch.
    pub level: u32,
    /// Adaptive remeshing: refine a quad while its normalized plane-fit error exceeds this
    /// (consistently over the models); `None` for uniform remeshing.
    pub adaptive_epsilon: Option<f64>,
    /// Extra feature rows `[v_1, ..., v_N]` besides anchor rows 5 and on.
    pub feature_anchors: Vec<Vec<u64>>,
    pub morph: MorphOptions,
    /// Interior vertices kept in each patch's base mesh.
    pub base_vertices: usize,
    /// Geometry images and normal maps at this level (`None`: `min(level, 8)`); 0 disables them.
    pub image_level: Option<u32>,
    /// Surface samples per direction for PSNR / Hausdorff.
    pub metric_samples: usize,
}

impl Default for QuadOptions {
    fn default() -> Self {
        Self {
            level: 6,
            adaptive_epsilon: None,
            feature_anchors: Vec::new(),
            morph: MorphOptions::default(),
            base_vertices: 32,
            image_level: None,
            metric_samples: 100_000,
        }
    }
}

/// A `quad` job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct QuadSpec {
    pub anchors: Vec<Vec<u64>>,
    #[serde(default)]
    pub options: QuadOptions,
}

impl QuadSpec {
    /// Checks the spec against the models' summaries: 1..=16 connected closed meshes of one
    /// genus, rows one vertex per model, in range, no vertex used twice on one model.
    /// Returns all rows (partition points first, then features) as vertex ids.
    ///
    /// # Errors
    /// `InputError::TopologyMismatch`, `InputError::Anchors`, `InputError::Spec`.
    pub fn check(&self, summaries: &[topology::Summary]) -> Result<Vec<Vec<VertexId>>> {
        let n = summaries.len();
        if !(1..=MAX_MODELS).contains(&n) {
            return Err(InputError::Spec(format!("a quad job takes 1 to {MAX_MODELS} meshes, got {n}")).into());
        }
        for (m, s) in summaries.iter().enumerate() {
            if s.components != 1 || s.boundary_loops != 0 {
                return Err(InputError::TopologyMismatch(format!(
                    "method quad partitions closed connected surfaces; mesh {m} has {} components and {} boundary loops (methods voronoi and greedy map open meshes and meshes in several parts)",
                    s.components, s.boundary_loops
                ))
                .into());
            }
            if s.genus != summaries[0].genus {
                return Err(InputError::TopologyMismatch(format!(
                    "genus mismatch: mesh 0 has genus {}, mesh {m} genus {}",
                    summaries[0].genus, s.genus
                ))
                .into());
            }
        }
        self.options.check_ranges(n)?;
        let o = &self.options;
        let rows: Vec<&Vec<u64>> = self.anchors.iter().chain(&o.feature_anchors).collect();
        if self.anchors.len() < 4 {
            return Err(InputError::Anchors(format!(
                "need 4 partition points (the first 4 anchor rows), got {} rows",
                self.anchors.len()
            ))
            .into());
        }
        if summaries[0].genus > 0 && rows.len() < 6 {
            return Err(InputError::Anchors(format!(
                "genus {} needs at least 6 anchor rows for its triangle layout, got {}",
                summaries[0].genus,
                rows.len()
            ))
            .into());
        }
        if rows.len() > MAX_ANCHORS {
            return Err(
                InputError::Anchors(format!("{} anchor rows exceed the limit {}", rows.len(), MAX_ANCHORS)).into()
            );
        }
        let mut seen = vec![std::collections::HashMap::new(); n];
        let mut out = Vec::with_capacity(rows.len());
        for (r, row) in rows.iter().enumerate() {
            if row.len() != n {
                return Err(
                    InputError::Anchors(format!("anchor row {r} has {} entries for {n} meshes", row.len())).into()
                );
            }
            let mut ids = Vec::with_capacity(n);
            for (m, &v) in row.iter().enumerate() {
                if v >= summaries[m].id_count() as u64 {
                    return Err(InputError::Anchors(format!(
                        "anchor row {r}: vertex {v} is out of range for mesh {m} ({} vertices)",
                        summaries[m].vertices
                    ))
                    .into());
                }
                if let Some(j) = seen[m].insert(v, r) {
                    return Err(
                        InputError::Anchors(format!("anchor rows {j} and {r} repeat vertex {v} of mesh {m}")).into()
                    );
                }
                ids.push(VertexId(v as u32));
            }
            out.push(ids);
        }
        Ok(out)
    }
}
