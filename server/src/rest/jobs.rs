//! Job routes: submit (JSON or multipart), get, list, cancel, and SSE progress.

use super::extract::{Owner, P, Q, is_multipart, multipart_error, read_limited, reserve_upload};
use crate::AppState;
use crate::error::{ApiError, ErrorBody};
use crate::service::{SpecInput, format_hint, job_filter};
use crate::views::{JobPage, JobView, SubmitJob, SubmitJobRequest, job_view};
use axum::Json;
use axum::extract::{FromRequest, Multipart, Request, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::sse::{Event, KeepAlive, Sse};
use axum::response::{IntoResponse, Response};
use futures::{Stream, StreamExt};
use std::convert::Infallible;
use surfmap_store::BlobStore;

/// Filters and paging of `GET /v1/jobs`.
#[derive(Debug, serde::Deserialize, utoipa::IntoParams)]
#[into_params(parameter_in = Query)]
pub struct ListQuery {
    /// queued | running | succeeded | failed | cancelled
    #[param(pattern = "^(queued|running|succeeded|failed|cancelled)$")]
    pub state: Option<String>,
    /// voronoi | greedy | homology | quad | spherical | auto
    #[param(pattern = "^(voronoi|greedy|homology|quad|spherical|auto)$")]
    pub method: Option<String>,
    /// `next_cursor` of the previous page (a job id).
    #[param(pattern = "^[0-9a-f]{8}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{4}-[0-9a-f]{12}$")]
    pub cursor: Option<String>,
    /// 1 to 500; 50 by default.
    #[param(minimum = 1, maximum = 500)]
    pub limit: Option<i64>,
}

/// A multipart part: a mesh id, or mesh bytes to upload first (a part with a file name, or
/// anything that is not a 64-hex-digit id).
async fn mesh_part(st: &AppState, owner: &str, bytes: &[u8], file_name: Option<String>) -> Result<String, ApiError> {
    let text = std::str::from_utf8(bytes).map(str::trim).unwrap_or("");
    if file_name.is_none() && BlobStore::valid_key(text) {
        return Ok(text.to_string());
    }
    Ok(st.service.upload_mesh(owner, bytes.to_vec(), format_hint(file_name.as_deref())).await?.id)
}

async fn multipart_job(st: &AppState, owner: &str, mut mp: Multipart) -> Result<(Vec<String>, Vec<u8>), ApiError> {
    let (mut source, mut target, mut spec) = (None, None, None);
    let mut meshes = Vec::new();
    while let Some(field) = mp.next_field().await.map_err(multipart_error)? {
        let name = field.name().unwrap_or_default().to_string();
        let file = field.file_name().map(str::to_string);
        let bytes = field.bytes().await.map_err(multipart_error)?;
        match name.as_str() {
            "source" => source = Some(mesh_part(st, owner, &bytes, file).await?),
            "target" => target = Some(mesh_part(st, owner, &bytes, file).await?),
            "spec" => spec = Some(bytes.to_vec()),
            "mesh" => meshes.push(mesh_part(st, owner, &bytes, file).await?),
            other => return Err(ApiError::bad_request("invalid_multipart", format!("unexpected part {other:?}"))),
        }
    }
    let missing = |p: &str| ApiError::bad_request("invalid_multipart", format!("missing part {p:?}"));
    let spec = spec.ok_or_else(|| missing("spec"))?;
    if !meshes.is_empty() {
        return Ok((meshes, spec));
    }
    Ok((vec![source.ok_or_else(|| missing("source"))?, target.ok_or_else(|| missing("target"))?], spec))
}

/// Validates a job against its meshes and queues it.
#[utoipa::path(post, path = "/v1/jobs", tag = "jobs", request_body = SubmitJobRequest,
    params(("Idempotency-Key" = Option<String>, Header, description = "retries with the same key return the same job")),
    responses((status = 202, description = "queued (or the job an earlier request with this Idempotency-Key made)", body = JobView, headers(("Location" = String, description = "the job's URL"))),
        (status = 400, description = "bad spec or unknown method", body = ErrorBody),
        (status = 404, description = "unknown mesh", body = ErrorBody),
        (status = 409, description = "idempotency key reused", body = ErrorBody),
        (status = 422, description = "genus mismatch, anchors out of range, an option out of its range, over the memory budget", body = ErrorBody)))]
pub async fn submit_job(State(st): State<AppState>, Owner(owner): Owner, req: Request) -> Result<Response, ApiError> {
    let key = req.headers().get("idempotency-key").and_then(|v| v.to_str().ok()).map(str::to_string);
    let (meshes, spec) = if is_multipart(req.headers()) {
        // Mesh parts are uploads: they share the upload memory budget.
        let _held = reserve_upload(&st, req.headers())?;
        let mp = Multipart::from_request(req, &st)
            .await
            .map_err(|e| ApiError::bad_request("invalid_multipart", e.body_text()))?;
        let (meshes, spec) = multipart_job(&st, &owner, mp).await?;
        (meshes, SpecInput::Bytes(spec))
    } else {
        let (parts, body) = req.into_parts();
        // A JSON job carries ids and a spec, never mesh bytes: its own small limit, checked
        // before anything is parsed.
        let bytes = read_limited(&parts.headers, body, st.service.limits.max_json_bytes).await?;
        let s: SubmitJob = serde_json::from_slice(&bytes).map_err(|e| {
            ApiError::bad_request(
                "invalid_request",
                format!("expected {{source, target, spec}} or {{meshes, spec}}: {e}"),
            )
        })?;
        let meshes = match (s.meshes, s.source, s.target) {
            (Some(m), None, None) => m,
            (None, Some(a), Some(b)) => vec![a, b],
            _ => {
                return Err(ApiError::bad_request(
                    "invalid_request",
                    "give either \"source\" and \"target\" or \"meshes\"",
                ));
            }
        };
        (meshes, SpecInput::Json(s.spec))
    };
    let (job, created) = st.service.submit(&owner, &meshes, spec, key).await?;
    let mut headers = HeaderMap::new();
    if let Ok(v) = HeaderValue::from_str(&format!("/v1/jobs/{}", job.id)) {
        headers.insert(header::LOCATION, v);
    }
    if !created {
        headers.insert("idempotent-replayed", HeaderValue::from_static("true"));
    }
    Ok((StatusCode::ACCEPTED, headers, Json(job_view(&job))).into_response())
}

/// State, stage, progress, attempts, timestamps, error and result links of a job.
#[utoipa::path(get, path = "/v1/jobs/{id}", tag = "jobs", params(("id" = String, Path)),
    responses((status = 200, description = "the job", body = JobView), (status = 404, description = "unknown job", body = ErrorBody)))]
pub async fn get_job(
    State(st): State<AppState>,
    Owner(owner): Owner,
    P(id): P<String>,
) -> Result<Json<JobView>, ApiError> {
    Ok(Json(job_view(&st.service.get(&owner, &id).await?)))
}

/// Jobs, newest first, with filters and cursor paging.
#[utoipa::path(get, path = "/v1/jobs", tag = "jobs", params(ListQuery), responses((status = 200, description = "a page of jobs, newest first", body = JobPage), (status = 400, description = "a bad filter, limit or cursor", body = ErrorBody)))]
pub async fn list_jobs(
    State(st): State<AppState>,
    Owner(owner): Owner,
    Q(q): Q<ListQuery>,
) -> Result<Json<JobPage>, ApiError> {
    if q.state.as_deref() == Some("") || q.method.as_deref() == Some("") {
        return Err(ApiError::bad_request("invalid_query", "state and method, when given, must not be empty"));
    }
    if q.cursor.as_deref() == Some("") {
        return Err(ApiError::bad_request("invalid_cursor", "cursor, when given, is the next_cursor of a page"));
    }
    let filter = job_filter(
        q.state.as_deref().unwrap_or_default(),
        q.method.as_deref().unwrap_or_default(),
        q.cursor.as_deref().unwrap_or_default(),
        match q.limit {
            None => 50,
            Some(l @ 1..=500) => l,
            Some(l) => return Err(ApiError::bad_request("invalid_query", format!("limit {l} is outside 1..=500"))),
        },
    )?;
    let (jobs, next_cursor) = st.service.list(&owner, filter).await?;
    Ok(Json(JobPage { jobs: jobs.iter().map(job_view).collect(), next_cursor }))
}

/// Cancels a queued job at once; a running job stops at its next check.
#[utoipa::path(post, path = "/v1/jobs/{id}/cancel", tag = "jobs", params(("id" = String, Path)),
    responses((status = 200, description = "cancelled, or cancellation requested of a running job", body = JobView), (status = 404, description = "unknown job", body = ErrorBody)))]
pub async fn cancel_job(
    State(st): State<AppState>,
    Owner(owner): Owner,
    P(id): P<String>,
) -> Result<Json<JobView>, ApiError> {
    Ok(Json(job_view(&st.service.cancel(&owner, &id).await?)))
}

/// Server-sent events: one `job` event (a JobView) per change of state, stage or progress;
/// the stream ends after a terminal state. When the server shuts down it sends the job once
/// more, then `event: shutdown` (`{code: "shutting_down", message}`), and ends: reconnect.
#[utoipa::path(get, path = "/v1/jobs/{id}/events", tag = "jobs", params(("id" = String, Path)),
    responses((status = 200, content_type = "text/event-stream", description = "`event: job` with a JobView as data; `event: shutdown` last when the server stops"),
        (status = 404, description = "unknown job", body = ErrorBody)))]
pub async fn job_events(
    State(st): State<AppState>,
    Owner(owner): Owner,
    P(id): P<String>,
) -> Result<Sse<impl Stream<Item = Result<Event, Infallible>>>, ApiError> {
    let first = st.service.get(&owner, &id).await?;
    let stream = st.service.watch(owner, first).map(|job| {
        let ev = Event::default().event("job");
        Ok(ev.json_data(job_view(&job)).unwrap_or_else(|_| Event::default().event("error")))
    });
    let stopping = st.service.stopping.clone();
    let last = futures::stream::once(async move { stopping.is_set() }).filter_map(|stopping| async move {
        let body = ErrorBody { code: "shutting_down".into(), message: "the server is stopping; reconnect".into() };
        stopping.then(|| Ok(Event::default().event("shutdown").json_data(body).unwrap_or_default()))
    });
    Ok(Sse::new(stream.chain(last)).keep_alive(KeepAlive::default()))
}
