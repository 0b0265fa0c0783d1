//! The REST face: routes and JSON rejections (the owner extractor and limited body reading are
//! in `extract`).
//! Each handler is a few lines around one `JobService` call.

pub mod artifacts;
mod extract;
pub mod jobs;
pub mod meshes;
pub mod ops;

pub use extract::{Owner, P, Q, declared_length, is_multipart, multipart_error, read_limited, reserve_upload};

use crate::AppState;
use crate::error::ApiError;
use axum::Router;
use axum::extract::DefaultBodyLimit;
use axum::routing::{get, post};

/// The JSON 404 of unknown routes (installed once, on the merged router).
pub async fn not_found() -> ApiError {
    ApiError::not_found("route_not_found", "no such route")
}

/// The JSON 405 of a known route called with a method it does not take (axum keeps the
/// `Allow` header).
pub async fn method_not_allowed() -> ApiError {
    ApiError::new(
        axum::http::StatusCode::METHOD_NOT_ALLOWED,
        "method_not_allowed",
        "this route does not take that method (see the Allow header)",
    )
}

/// The REST routes.
pub fn router(state: AppState) -> Router {
    let limit = state.service.limits.max_body_bytes;
    Router::new()
        .route("/v1/meshes", post(meshes::upload_mesh))
        .route("/v1/meshes/{id}", get(meshes::get_mesh))
        .route("/v1/meshes/{id}/glb", get(meshes::get_mesh_glb))
        .route("/v1/jobs", post(jobs::submit_job).get(jobs::list_jobs))
        .route("/v1/jobs/{id}", get(jobs::get_job))
        .route("/v1/jobs/{id}/cancel", post(jobs::cancel_job))
        .route("/v1/jobs/{id}/events", get(jobs::job_events))
        .route("/v1/jobs/{id}/artifacts", get(artifacts::list_artifacts))
        .route("/v1/jobs/{id}/artifacts/{name}", get(artifacts::get_artifact))
        .route("/openapi.json", get(crate::openapi::serve))
        .route("/healthz", get(ops::healthz))
        .route("/readyz", get(ops::readyz))
        .route("/metrics", get(ops::metrics))
        .method_not_allowed_fallback(method_not_allowed)
        .layer(DefaultBodyLimit::max(limit))
        .with_state(state)
}
