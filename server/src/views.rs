//! The JSON shapes of the REST API (also the OpenAPI schemas), built from store records.

use crate::error::ErrorBody;
use serde::{Deserialize, Serialize};
use surfmap_store::{ArtifactRef, JobRecord};
use utoipa::ToSchema;

/// An uploaded mesh.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct MeshView {
    /// sha256 of the bytes; use it as `source` or `target` of a job.
    pub id: String,
    pub format: String,
    pub size_bytes: i64,
    /// The `surfmap inspect` summary (vertices, faces, genus, boundary loops, bbox, area...).
    #[schema(value_type = Object)]
    pub summary: serde_json::Value,
    pub warnings: Vec<String>,
}

/// One artifact of a succeeded job.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct ArtifactView {
    pub name: String,
    pub content_type: String,
    pub size: u64,
    pub sha256: String,
    pub url: String,
}

/// Links of a job.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct JobLinks {
    #[serde(rename = "self")]
    pub self_: String,
    pub events: String,
    pub artifacts: String,
    pub cancel: String,
}

/// A job as clients see it.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct JobView {
    pub id: String,
    /// queued | running | succeeded | failed | cancelled
    pub state: String,
    pub stage: String,
    /// 0 to 1.
    pub progress: f64,
    pub attempts: i64,
    pub max_attempts: i64,
    pub method: String,
    /// The job spec as validated (with every default filled in): submit it again with the
    /// same meshes to retry.
    #[schema(value_type = Object)]
    pub spec: serde_json::Value,
    /// The job's meshes in the spec's order (source, target for a pair job).
    pub meshes: Vec<String>,
    /// The first and the last of `meshes`.
    pub source: String,
    pub target: String,
    pub cancel_requested: bool,
    /// The worker holding the lease, or the one that finished the job.
    pub worker: Option<String>,
    pub created_at_ms: i64,
    pub updated_at_ms: i64,
    pub started_at_ms: Option<i64>,
    pub finished_at_ms: Option<i64>,
    pub error: Option<ErrorBody>,
    /// The metrics report of a succeeded job (the same as `metrics.json`).
    #[schema(value_type = Option<Object>)]
    pub result: Option<serde_json::Value>,
    pub artifacts: Vec<ArtifactView>,
    pub links: JobLinks,
}

/// A page of jobs, newest first.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct JobPage {
    pub jobs: Vec<JobView>,
    /// Pass as `cursor` for the next page; absent on the last page.
    pub next_cursor: Option<String>,
}

/// The artifacts of a job.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
pub struct ArtifactList {
    pub artifacts: Vec<ArtifactView>,
}

/// `POST /v1/jobs` with JSON.
#[derive(Debug, Serialize, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
pub struct SubmitJob {
    /// Mesh id (sha256) from `POST /v1/meshes` (pair jobs).
    #[serde(default)]
    pub source: Option<String>,
    #[serde(default)]
    pub target: Option<String>,
    /// Mesh ids in the order of the spec's anchor columns (source, target for a pair job);
    /// instead of `source` and `target`.
    #[serde(default)]
    #[schema(min_items = 1, max_items = 16)]
    pub meshes: Option<Vec<String>>,
    /// Exactly the spec `surfmap map --spec` (or `surfmap remesh --spec`) takes:
    /// `{"method", "anchors", "options"}`.
    #[schema(value_type = SpecOutline)]
    pub spec: serde_json::Value,
}

/// `POST /v1/jobs` as the document describes it: a pair job or an N-mesh job (the handler
/// reads [`SubmitJob`] and names the missing or extra field).
#[derive(Debug, Deserialize, ToSchema)]
#[serde(untagged)]
#[allow(dead_code)]
pub enum SubmitJobRequest {
    Pair(PairJobRequest),
    Meshes(MeshesJobRequest),
}

/// A pair job (`voronoi`, `greedy`, `homology`).
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
pub struct PairJobRequest {
    /// Mesh id (sha256) from `POST /v1/meshes`.
    source: String,
    target: String,
    #[schema(value_type = SpecOutline)]
    spec: serde_json::Value,
}

/// A job on a list of meshes: any method (`quad` takes 1 to 16; pair methods take source,
/// target).
#[derive(Debug, Deserialize, ToSchema)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)]
pub struct MeshesJobRequest {
    /// Mesh ids in the order of the spec's anchor columns (source, target for a pair job).
    #[schema(min_items = 1, max_items = 16)]
    meshes: Vec<String>,
    #[schema(value_type = SpecOutline)]
    spec: serde_json::Value,
}

/// The outline of a job spec as the document describes it; the full form (every option and
/// its range) is in the README. Checked against the meshes after they are found.
#[derive(Debug, ToSchema)]
#[allow(dead_code)]
pub struct SpecOutline {
    /// voronoi | greedy | homology | quad | spherical | auto; left out, `auto`: the service
    /// picks the pair method that fits the meshes, and `metrics.json`'s `auto` says which and why.
    #[schema(pattern = "^(voronoi|greedy|homology|quad|spherical|auto)$")]
    method: Option<String>,
    /// Rows: `[source, target]` vertex ids for pair jobs (or `{"source": [x, y, z], "target":
    /// [x, y, z]}`, or `{"source": {"face": f, "bary": [u, v, w]}, "target": ...}` surface
    /// points); one id per mesh for `quad`.
    #[schema(value_type = Vec<Object>)]
    anchors: Vec<serde_json::Value>,
    /// `homology`: corresponding feature curves.
    #[schema(value_type = Option<Vec<Object>>)]
    features: Option<Vec<serde_json::Value>>,
    /// The method's options (README).
    #[schema(value_type = Option<Object>)]
    options: Option<serde_json::Value>,
}

pub fn artifact_view(job: &str, a: &ArtifactRef) -> ArtifactView {
    ArtifactView {
        name: a.name.clone(),
        content_type: a.content_type.clone(),
        size: a.size,
        sha256: a.sha256.clone(),
        url: format!("/v1/jobs/{job}/artifacts/{}", a.name),
    }
}

pub fn job_view(j: &JobRecord) -> JobView {
    let base = format!("/v1/jobs/{}", j.id);
    JobView {
        id: j.id.clone(),
        state: j.state.as_str().to_string(),
        stage: j.stage.clone(),
        progress: j.progress,
        attempts: j.attempts,
        max_attempts: j.max_attempts,
        method: j.method.clone(),
        spec: serde_json::from_str(&j.spec).unwrap_or(serde_json::Value::Null),
        meshes: j.meshes.clone(),
        source: j.source.clone(),
        target: j.target.clone(),
        cancel_requested: j.cancel_requested,
        worker: j.lease_owner.clone(),
        created_at_ms: j.created_at,
        updated_at_ms: j.updated_at,
        started_at_ms: j.started_at,
        finished_at_ms: j.finished_at,
        error: j
            .error_code
            .as_ref()
            .map(|c| ErrorBody { code: c.clone(), message: j.error_message.clone().unwrap_or_default() }),
        result: j.result.as_deref().and_then(|r| serde_json::from_str(r).ok()),
        artifacts: j.artifacts.iter().map(|a| artifact_view(&j.id, a)).collect(),
        links: JobLinks {
            events: format!("{base}/events"),
            artifacts: format!("{base}/artifacts"),
            cancel: format!("{base}/cancel"),
            self_: base,
        },
    }
}
