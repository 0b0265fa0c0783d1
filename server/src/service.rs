//! `JobService`: the operations behind both faces (REST and gRPC). Handlers translate their
//! request into one call here and the answer back; nothing else decides anything.

use crate::error::ApiError;
use crate::views::MeshView;
use futures::Stream;
use geom::io::{Format, ReadOptions};
use geom::mesh::MeshLimits;
use geom::pipeline::JobSpec;
use std::time::Duration;
use surfmap_store::{ArtifactRef, BlobStore, JobFilter, JobRecord, JobState, MeshRecord, NewJob, Store, now_ms};

/// The memory that uploads being read and parsed may hold at once, shared by all requests.
#[derive(Debug, Clone)]
pub struct UploadBudget {
    permits: std::sync::Arc<tokio::sync::Semaphore>,
    total_mib: u32,
}

impl UploadBudget {
    /// A budget of `bytes` (at least 1 MiB).
    pub fn new(bytes: usize) -> UploadBudget {
        let total_mib = u32::try_from((bytes >> 20).max(1)).unwrap_or(u32::MAX >> 4);
        UploadBudget { permits: std::sync::Arc::new(tokio::sync::Semaphore::new(total_mib as usize)), total_mib }
    }

    /// Reserves what an upload of `body` bytes holds while it is read and parsed (the body and
    /// the mesh built from it, about four times the body), before the body is read.
    ///
    /// # Errors
    /// 429 `uploads_busy` with `Retry-After` when concurrent uploads hold the budget.
    pub fn reserve(&self, body: usize) -> Result<tokio::sync::OwnedSemaphorePermit, ApiError> {
        let mib =
            u32::try_from(body.saturating_mul(4).div_ceil(1 << 20).max(1)).unwrap_or(u32::MAX).min(self.total_mib);
        self.permits.clone().try_acquire_many_owned(mib).map_err(|_| {
            ApiError::busy(
                "uploads_busy",
                format!("concurrent uploads hold the server's upload memory ({} MiB); retry shortly", self.total_mib),
                1,
            )
        })
    }
}

/// Sizes and retry policy the service enforces.
#[derive(Debug, Clone)]
pub struct Limits {
    /// Largest request body (mesh uploads, multipart jobs), enforced while streaming.
    pub max_body_bytes: usize,
    /// Largest JSON body (a job with its spec, anchors and features), checked before parsing.
    pub max_json_bytes: usize,
    /// Largest mesh, in vertices (checked from headers before allocation).
    pub max_vertices: u64,
    /// Attempts a job gets before an expired lease fails it.
    pub max_attempts: i64,
    /// How often watchers (SSE, WatchJob) look at the job.
    pub watch_interval: Duration,
    /// Memory budget of one job: a job whose estimate exceeds it is refused at submission.
    pub job_memory_bytes: u64,
    /// Memory that concurrent uploads may hold.
    pub uploads: UploadBudget,
}

impl Default for Limits {
    fn default() -> Self {
        Self {
            max_body_bytes: 256 << 20,
            max_json_bytes: 8 << 20,
            max_vertices: 2_000_000,
            max_attempts: 3,
            watch_interval: Duration::from_millis(200),
            job_memory_bytes: surfmap_worker::DEFAULT_JOB_MEMORY_BYTES,
            uploads: UploadBudget::new(1 << 30),
        }
    }
}

/// The one service both faces call.
#[derive(Debug, Clone)]
pub struct JobService {
    pub store: Store,
    pub blobs: BlobStore,
    pub limits: Limits,
    /// Fires on shutdown: watch streams send the job once more and end.
    pub stopping: crate::stopping::Stopping,
}

/// The methods a job may name, in the order the docs list them.
pub const METHODS: [&str; 6] = geom::pipeline::METHODS;

fn parse_format(hint: Option<&str>) -> Result<Option<Format>, ApiError> {
    Ok(match hint.map(str::to_ascii_lowercase).as_deref() {
        None | Some("") => None,
        Some("obj") => Some(Format::Obj),
        Some("off") => Some(Format::Off),
        Some("ply") => Some(Format::Ply),
        Some("stl") => Some(Format::Stl),
        Some("gltf" | "glb") => Some(Format::Gltf),
        Some(other) => {
            return Err(ApiError::bad_request(
                "unknown_format",
                format!("format {other:?} is not obj, off, ply, stl, gltf or glb"),
            ));
        }
    })
}

/// The format a file name's extension names, as a hint for ambiguous content.
pub fn format_hint(file_name: Option<&str>) -> Option<&'static str> {
    file_name.and_then(|f| Format::from_extension(std::path::Path::new(f))).map(Format::name)
}

/// The pattern of a job id, and so of a page cursor: a lower-case hyphenated UUID.
pub const JOB_ID_PATTERN: &str = "^[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}$";

/// True for a string of [`JOB_ID_PATTERN`].
pub fn is_job_id(s: &str) -> bool {
    s.len() == 36
        && s.bytes().enumerate().all(|(i, b)| match i {
            8 | 13 | 18 | 23 => b == b'-',
            _ => b.is_ascii_digit() || (b'a'..=b'f').contains(&b),
        })
}

/// Filters of a job listing from its request fields (empty = no filter).
///
/// # Errors
/// 400 `invalid_query` for an unknown state, method or a limit out of range; 400
/// `invalid_cursor` for a cursor that is not a job id.
pub fn job_filter(state: &str, method: &str, cursor: &str, limit: i64) -> Result<JobFilter, ApiError> {
    if !(1..=500).contains(&limit) && limit != 0 {
        return Err(ApiError::bad_request("invalid_query", format!("limit {limit} is outside 1..=500")));
    }
    if !method.is_empty() && !METHODS.contains(&method) {
        return Err(ApiError::bad_request(
            "invalid_query",
            format!("unknown method {method:?}; available: {}", METHODS.join(", ")),
        ));
    }
    let state = match state {
        "" => None,
        s => Some(
            JobState::parse(s).ok_or_else(|| ApiError::bad_request("invalid_query", format!("unknown state {s:?}")))?,
        ),
    };
    if !cursor.is_empty() && !is_job_id(cursor) {
        return Err(ApiError::bad_request(
            "invalid_cursor",
            format!("cursor {cursor:?} is not a job id: pass the next_cursor of the previous page"),
        ));
    }
    let some = |s: &str| Some(s.to_string()).filter(|s| !s.is_empty());
    Ok(JobFilter { state, method: some(method), before: some(cursor), limit })
}

/// A job's spec as it arrived: bytes (a multipart part, gRPC `spec_json`) or a JSON value
/// inside a REST body already read under the JSON limit.
pub enum SpecInput {
    Bytes(Vec<u8>),
    Json(serde_json::Value),
}

impl JobService {
    /// Parses, validates and stores one mesh.
    ///
    /// # Errors
    /// 422 with the reader's code for a bad mesh, or the checks' (`mesh_not_finite`,
    /// `mesh_no_extent`, `zero_area_face`); 413 for one over the vertex cap.
    pub async fn upload_mesh(&self, owner: &str, bytes: Vec<u8>, hint: Option<&str>) -> Result<MeshView, ApiError> {
        let hint = parse_format(hint)?;
        let limits = MeshLimits { max_vertices: self.limits.max_vertices, max_faces: 2 * self.limits.max_vertices + 8 };
        let (bytes, parsed) = tokio::task::spawn_blocking(move || {
            // Parsed once, here: the reader, then the checks every job relies on (finite
            // numbers, an extent, no zero-area face in a closed mesh).
            let parsed = geom::io::read(&bytes, &ReadOptions { limits, hint }).and_then(|r| {
                let s = geom::topology::checked_summary(&r.mesh, r.layout.as_ref().map(|l| l.n_vertices()))?;
                // The attributes a job's `transfer` may name, checked at submission.
                let names = geom::pipeline::attribute_names(&r.mesh, r.layout.as_ref());
                Ok((r.format, geom::topology::Summary { attribute_names: Some(names), ..s }, r.warnings))
            });
            (bytes, parsed)
        })
        .await
        .map_err(ApiError::internal)?;
        let (format, summary, warnings) = parsed?;
        let id = self.blobs.put(&bytes).await.map_err(ApiError::internal)?;
        let summary = serde_json::to_value(&summary).map_err(ApiError::internal)?;
        let rec = MeshRecord {
            owner: owner.to_string(),
            id: id.clone(),
            format: format.name().to_string(),
            size_bytes: bytes.len() as i64,
            summary: summary.to_string(),
            created_at: now_ms(),
        };
        self.store.put_mesh(&rec).await?;
        Ok(MeshView {
            id,
            format: rec.format,
            size_bytes: rec.size_bytes,
            summary,
            warnings: warnings.into_iter().map(|w| w.message).collect(),
        })
    }

    /// An uploaded mesh's record, as its owner sees it.
    ///
    /// # Errors
    /// 400 `invalid_mesh_id` for a name that is not a sha256; 404 `mesh_not_found`.
    pub async fn mesh(&self, owner: &str, id: &str) -> Result<MeshRecord, ApiError> {
        if !BlobStore::valid_key(id) {
            return Err(ApiError::bad_request("invalid_mesh_id", format!("{id:?} is not a mesh id (64 hex digits)")));
        }
        self.store
            .get_mesh(owner, id)
            .await?
            .ok_or_else(|| ApiError::not_found("mesh_not_found", format!("no mesh {id:?}")))
    }

    /// An uploaded mesh as binary glTF in the file's own vertices (seam copies kept), so that
    /// a spec's vertex ids index it; for viewers.
    ///
    /// # Errors
    /// As [`JobService::mesh`]; 500 when its blob is missing.
    pub async fn mesh_glb(&self, owner: &str, id: &str) -> Result<Vec<u8>, ApiError> {
        let rec = self.mesh(owner, id).await?;
        let bytes = self
            .blobs
            .get(id)
            .await
            .map_err(ApiError::internal)?
            .ok_or_else(|| ApiError::internal(format!("blob of mesh {id} is missing")))?;
        let hint = parse_format(Some(&rec.format)).ok().flatten();
        let limits = MeshLimits { max_vertices: self.limits.max_vertices, max_faces: 2 * self.limits.max_vertices + 8 };
        tokio::task::spawn_blocking(move || {
            let r = geom::io::read(&bytes, &ReadOptions { limits, hint })?;
            Ok::<_, geom::Error>(geom::io::write_layout_glb(&r.mesh, r.layout.as_ref(), &[]))
        })
        .await
        .map_err(ApiError::internal)?
        .map_err(ApiError::from)
    }

    async fn summary(&self, owner: &str, role: &str, id: &str) -> Result<geom::topology::Summary, ApiError> {
        let m = self.store.get_mesh(owner, id).await?.ok_or_else(|| {
            ApiError::not_found(
                "mesh_not_found",
                format!("{role} mesh {id:?} is not known; upload it with POST /v1/meshes"),
            )
        })?;
        // A summary stored before uploads were checked may hold nulls (overflowed numbers).
        let unusable = |why: String| {
            ApiError::new(
                axum::http::StatusCode::UNPROCESSABLE_ENTITY,
                "mesh_not_finite",
                format!("{role} mesh {id:?} cannot be mapped: {why}; upload a scaled copy"),
            )
        };
        let s: geom::topology::Summary =
            serde_json::from_str(&m.summary).map_err(|e| unusable(format!("its summary does not read ({e})")))?;
        s.check_finite().map_err(|e| unusable(e.to_string()))?;
        Ok(s)
    }

    /// Validates a job against its meshes and queues it. Returns the job and whether it is new
    /// (false: an earlier request with the same idempotency key). Pair jobs take
    /// `[source, target]`; `quad` jobs take 1 to 16 meshes.
    ///
    /// # Errors
    /// 404 unknown mesh; 400 bad spec or unknown method; 422 genus mismatch, bad anchors;
    /// 409 idempotency key reused for another request.
    pub async fn submit(
        &self,
        owner: &str,
        meshes: &[String],
        spec: SpecInput,
        idempotency_key: Option<String>,
    ) -> Result<(JobRecord, bool), ApiError> {
        if meshes.is_empty() || meshes.len() > geom::pipeline::MAX_MODELS {
            return Err(ApiError::bad_request(
                "invalid_request",
                format!("a job takes 1 to {} meshes, got {}", geom::pipeline::MAX_MODELS, meshes.len()),
            ));
        }
        let mut summaries = Vec::with_capacity(meshes.len());
        for (i, id) in meshes.iter().enumerate() {
            let role = match (meshes.len(), i) {
                (2, 0) => "source".to_string(),
                (2, 1) => "target".to_string(),
                _ => format!("#{i}"),
            };
            summaries.push(self.summary(owner, &role, id).await?);
        }
        // The meshes first (404), then the spec: bounded (REST JSON bodies are bounded before
        // they are read; this covers multipart parts and gRPC), parsed once, here.
        let job = &match spec {
            SpecInput::Bytes(b) if b.len() > self.limits.max_json_bytes => {
                return Err(ApiError::too_large(format!(
                    "the spec of {} bytes exceeds the limit of {} for JSON",
                    b.len(),
                    self.limits.max_json_bytes
                )));
            }
            SpecInput::Bytes(b) => JobSpec::from_json(&b)?,
            SpecInput::Json(v) => JobSpec::from_value(v)?,
        };
        job.check(&summaries)?;
        let estimate = job.memory_estimate(&summaries);
        if estimate > self.limits.job_memory_bytes {
            return Err(geom::Error::from(geom::InputError::OverBudget {
                estimate_mib: estimate.div_ceil(1 << 20),
                budget_mib: self.limits.job_memory_bytes >> 20,
            })
            .into());
        }
        let method = job.method().name();
        let new = NewJob {
            owner: owner.to_string(),
            idempotency_key: idempotency_key.filter(|k| !k.is_empty()),
            method: method.to_string(),
            spec: job.to_json()?,
            meshes: meshes.to_vec(),
            max_attempts: self.limits.max_attempts,
        };
        let r = self.store.insert_job(&new).await?;
        if r.1 {
            metrics::counter!("surfmap_jobs_submitted_total", "method" => method).increment(1);
        }
        Ok(r)
    }

    /// # Errors
    /// 404 for a job `owner` cannot see.
    pub async fn get(&self, owner: &str, id: &str) -> Result<JobRecord, ApiError> {
        self.store
            .get_job(owner, id)
            .await?
            .ok_or_else(|| ApiError::not_found("job_not_found", format!("no job {id:?}")))
    }

    /// A page of jobs and the cursor of the next one.
    ///
    /// # Errors
    /// Store failures.
    pub async fn list(&self, owner: &str, mut filter: JobFilter) -> Result<(Vec<JobRecord>, Option<String>), ApiError> {
        filter.limit = if filter.limit <= 0 { 50 } else { filter.limit.min(500) };
        let jobs = self.store.list_jobs(owner, &filter).await?;
        let next = (jobs.len() as i64 == filter.limit).then(|| jobs.last().map(|j| j.id.clone())).flatten();
        Ok((jobs, next))
    }

    /// # Errors
    /// 404 for an unknown job.
    pub async fn cancel(&self, owner: &str, id: &str) -> Result<JobRecord, ApiError> {
        self.store
            .cancel_job(owner, id)
            .await?
            .ok_or_else(|| ApiError::not_found("job_not_found", format!("no job {id:?}")))
    }

    /// One artifact's record and bytes. The name must be one the job lists: a name with a
    /// path separator or `..` is refused before any lookup.
    ///
    /// # Errors
    /// 400 `invalid_artifact_name`; 404 unknown job or artifact.
    pub async fn artifact(&self, owner: &str, id: &str, name: &str) -> Result<(ArtifactRef, Vec<u8>), ApiError> {
        // Dot-separated runs of [A-Za-z0-9_-] (the OpenAPI pattern of `name`): no path, no `..`.
        let plain = name
            .split('.')
            .all(|p| !p.is_empty() && p.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-'));
        if !plain {
            return Err(ApiError::bad_request(
                "invalid_artifact_name",
                format!("artifact name {name:?} is not a plain file name"),
            ));
        }
        let job = self.get(owner, id).await?;
        let a = job.artifacts.iter().find(|a| a.name == name).cloned().ok_or_else(|| {
            ApiError::not_found(
                "artifact_not_found",
                format!("job {id} has no artifact {name:?} (state {})", job.state.as_str()),
            )
        })?;
        let bytes = self
            .blobs
            .get(&a.sha256)
            .await
            .map_err(ApiError::internal)?
            .ok_or_else(|| ApiError::internal(format!("blob {} of job {id} is missing", a.sha256)))?;
        Ok((a, bytes))
    }

    /// The job every time its state, stage, progress (to 0.1%) or attempts change, ending
    /// after a terminal state, or when the server stops (after the job as it is then). The
    /// first item is the job as it is now.
    pub fn watch(&self, owner: String, first: JobRecord) -> impl Stream<Item = JobRecord> + Send + 'static + use<> {
        struct S {
            svc: JobService,
            owner: String,
            id: String,
            first: Option<JobRecord>,
            last: Option<(String, String, i64, i64)>,
            done: bool,
        }
        let s = S { svc: self.clone(), owner, id: first.id.clone(), first: Some(first), last: None, done: false };
        futures::stream::unfold(s, |mut s| async move {
            if s.done {
                return None;
            }
            loop {
                let job = match s.first.take() {
                    Some(j) => j,
                    None => {
                        let stopping = tokio::select! {
                            () = tokio::time::sleep(s.svc.limits.watch_interval) => false,
                            () = s.svc.stopping.fired() => true,
                        };
                        let job = match s.svc.store.get_job(&s.owner, &s.id).await {
                            Ok(Some(j)) => j,
                            _ => return None,
                        };
                        if stopping {
                            s.done = true;
                            return Some((job, s));
                        }
                        job
                    }
                };
                let key =
                    (job.state.as_str().to_string(), job.stage.clone(), (job.progress * 1000.0) as i64, job.attempts);
                if s.last.as_ref() != Some(&key) {
                    s.last = Some(key);
                    s.done = job.state.is_terminal();
                    return Some((job, s));
                }
            }
        })
    }
}
