//! The gRPC face (`surfmap.v1.Surfmap`): the same `JobService` calls as REST, with statuses
//! from the same `ApiError`s, `WatchJob` as a server stream and artifacts in 64 KiB chunks.

use crate::AppState;
use crate::service::job_filter;
use futures::{Stream, StreamExt};
use std::pin::Pin;
use surfmap_proto::v1 as pb;
use surfmap_proto::v1::surfmap_server::Surfmap;
use surfmap_store::{ArtifactRef, JobRecord};
use tonic::{Request, Response, Status};

/// The gRPC service over the shared state.
#[derive(Clone)]
pub struct GrpcApi {
    pub state: AppState,
}

const CHUNK: usize = 64 << 10;

fn owner<T>(st: &AppState, req: &Request<T>) -> Result<String, Status> {
    let h = req.metadata().get("authorization").and_then(|v| v.to_str().ok());
    Ok(st.auth.owner(h)?)
}

fn artifact(a: &ArtifactRef) -> pb::Artifact {
    pb::Artifact { name: a.name.clone(), content_type: a.content_type.clone(), size: a.size, sha256: a.sha256.clone() }
}

/// A store record as the proto message.
pub fn job(j: &JobRecord) -> pb::Job {
    pb::Job {
        id: j.id.clone(),
        state: j.state.as_str().to_string(),
        stage: j.stage.clone(),
        progress: j.progress,
        attempts: j.attempts,
        method: j.method.clone(),
        source: j.source.clone(),
        target: j.target.clone(),
        created_at_ms: j.created_at,
        started_at_ms: j.started_at.unwrap_or(0),
        finished_at_ms: j.finished_at.unwrap_or(0),
        error_code: j.error_code.clone().unwrap_or_default(),
        error_message: j.error_message.clone().unwrap_or_default(),
        result_json: j.result.clone().unwrap_or_default(),
        artifacts: j.artifacts.iter().map(artifact).collect(),
        cancel_requested: j.cancel_requested,
        worker: j.lease_owner.clone().unwrap_or_default(),
        meshes: j.meshes.clone(),
    }
}

type BoxStream<T> = Pin<Box<dyn Stream<Item = Result<T, Status>> + Send + 'static>>;

#[tonic::async_trait]
impl Surfmap for GrpcApi {
    async fn upload_mesh(&self, req: Request<pb::UploadMeshRequest>) -> Result<Response<pb::MeshInfo>, Status> {
        let o = owner(&self.state, &req)?;
        let r = req.into_inner();
        let hint = Some(r.format_hint.as_str()).filter(|h| !h.is_empty());
        let _held = self.state.service.limits.uploads.reserve(r.data.len())?;
        let m = self.state.service.upload_mesh(&o, r.data, hint).await?;
        Ok(Response::new(pb::MeshInfo {
            id: m.id,
            format: m.format,
            size_bytes: m.size_bytes as u64,
            summary_json: m.summary.to_string(),
        }))
    }

    async fn submit_job(&self, req: Request<pb::SubmitJobRequest>) -> Result<Response<pb::Job>, Status> {
        let o = owner(&self.state, &req)?;
        let r = req.into_inner();
        let key = Some(r.idempotency_key).filter(|k| !k.is_empty());
        let meshes = if r.meshes.is_empty() { vec![r.source, r.target] } else { r.meshes };
        let (j, _) = self
            .state
            .service
            .submit(&o, &meshes, crate::service::SpecInput::Bytes(r.spec_json.into_bytes()), key)
            .await?;
        Ok(Response::new(job(&j)))
    }

    async fn get_job(&self, req: Request<pb::GetJobRequest>) -> Result<Response<pb::Job>, Status> {
        let o = owner(&self.state, &req)?;
        Ok(Response::new(job(&self.state.service.get(&o, &req.into_inner().id).await?)))
    }

    async fn list_jobs(&self, req: Request<pb::ListJobsRequest>) -> Result<Response<pb::ListJobsResponse>, Status> {
        let o = owner(&self.state, &req)?;
        let r = req.into_inner();
        let filter = job_filter(&r.state, &r.method, &r.cursor, i64::from(r.limit))?;
        let (jobs, next) = self.state.service.list(&o, filter).await?;
        Ok(Response::new(pb::ListJobsResponse {
            jobs: jobs.iter().map(job).collect(),
            next_cursor: next.unwrap_or_default(),
        }))
    }

    async fn cancel_job(&self, req: Request<pb::CancelJobRequest>) -> Result<Response<pb::Job>, Status> {
        let o = owner(&self.state, &req)?;
        Ok(Response::new(job(&self.state.service.cancel(&o, &req.into_inner().id).await?)))
    }

    type WatchJobStream = BoxStream<pb::Job>;

    async fn watch_job(&self, req: Request<pb::WatchJobRequest>) -> Result<Response<Self::WatchJobStream>, Status> {
        let o = owner(&self.state, &req)?;
        let first = self.state.service.get(&o, &req.into_inner().id).await?;
        let s = self.state.service.watch(o, first).map(|j| Ok(job(&j)));
        // On shutdown: the job once more, then UNAVAILABLE with the code `shutting_down`.
        let stopping = self.state.service.stopping.clone();
        let last = futures::stream::once(async move { stopping.is_set() }).filter_map(|stopping| async move {
            let e = crate::error::ApiError::new(
                axum::http::StatusCode::SERVICE_UNAVAILABLE,
                "shutting_down",
                "the server is stopping; reconnect",
            );
            stopping.then(|| Err(Status::from(e)))
        });
        Ok(Response::new(Box::pin(s.chain(last))))
    }

    async fn list_artifacts(
        &self,
        req: Request<pb::ListArtifactsRequest>,
    ) -> Result<Response<pb::ListArtifactsResponse>, Status> {
        let o = owner(&self.state, &req)?;
        let j = self.state.service.get(&o, &req.into_inner().job_id).await?;
        Ok(Response::new(pb::ListArtifactsResponse { artifacts: j.artifacts.iter().map(artifact).collect() }))
    }

    type GetArtifactStream = BoxStream<pb::ArtifactChunk>;

    async fn get_artifact(
        &self,
        req: Request<pb::GetArtifactRequest>,
    ) -> Result<Response<Self::GetArtifactStream>, Status> {
        let o = owner(&self.state, &req)?;
        let r = req.into_inner();
        let (a, bytes) = self.state.service.artifact(&o, &r.job_id, &r.name).await?;
        let total = bytes.len() as u64;
        // At least one chunk, so an empty artifact still reports its content type.
        let n = bytes.len().div_ceil(CHUNK).max(1);
        let chunks: Vec<Result<pb::ArtifactChunk, Status>> = (0..n)
            .map(|i| {
                let first = i == 0;
                Ok(pb::ArtifactChunk {
                    content_type: if first { a.content_type.clone() } else { String::new() },
                    total_size: if first { total } else { 0 },
                    data: bytes[i * CHUNK..((i + 1) * CHUNK).min(bytes.len())].to_vec(),
                })
            })
            .collect();
        Ok(Response::new(Box::pin(futures::stream::iter(chunks))))
    }
}
