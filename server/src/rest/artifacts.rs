//! Artifact routes: the list of a job's files and each file with its content type.

use super::extract::{Owner, P};
use crate::AppState;
use crate::error::{ApiError, ErrorBody};
use crate::views::{ArtifactList, artifact_view};
use axum::Json;
use axum::extract::State;
use axum::http::{HeaderValue, header};
use axum::response::{IntoResponse, Response};

/// Every file `surfmap map` writes for this job (empty until it succeeds).
#[utoipa::path(get, path = "/v1/jobs/{id}/artifacts", tag = "artifacts", params(("id" = String, Path)),
    responses((status = 200, description = "the job's artifacts", body = ArtifactList), (status = 404, description = "unknown job", body = ErrorBody)))]
pub async fn list_artifacts(
    State(st): State<AppState>,
    Owner(owner): Owner,
    P(id): P<String>,
) -> Result<Json<ArtifactList>, ApiError> {
    let job = st.service.get(&owner, &id).await?;
    Ok(Json(ArtifactList { artifacts: job.artifacts.iter().map(|a| artifact_view(&job.id, a)).collect() }))
}

/// One artifact's bytes.
#[utoipa::path(get, path = "/v1/jobs/{id}/artifacts/{name}", tag = "artifacts",
    params(("id" = String, Path), ("name" = String, Path, pattern = r"^[A-Za-z0-9_-]+(\.[A-Za-z0-9_-]+)*$", description = "an artifact's file name")),
    responses((status = 200, description = "the file, with its content type"),
        (status = 400, description = "a name with a path in it", body = ErrorBody), (status = 404, description = "unknown job or artifact", body = ErrorBody)))]
pub async fn get_artifact(
    State(st): State<AppState>,
    Owner(owner): Owner,
    P((id, name)): P<(String, String)>,
) -> Result<Response, ApiError> {
    let (a, bytes) = st.service.artifact(&owner, &id, &name).await?;
    let ct = HeaderValue::from_str(&a.content_type).unwrap_or(HeaderValue::from_static("application/octet-stream"));
    let disp = HeaderValue::from_str(&format!("attachment; filename=\"{}\"", a.name))
        .unwrap_or(HeaderValue::from_static("attachment"));
    Ok(([(header::CONTENT_TYPE, ct), (header::CONTENT_DISPOSITION, disp)], bytes).into_response())
}
