//! Operations routes: liveness, readiness and Prometheus metrics (the OpenAPI document's
//! route is `crate::openapi::serve`).

use crate::AppState;
use crate::error::ApiError;
use axum::Json;
use axum::extract::State;
use axum::http::header;
use axum::response::IntoResponse;

/// Liveness: the process answers.
#[utoipa::path(get, path = "/healthz", tag = "ops", responses((status = 200, description = "alive")))]
pub async fn healthz() -> Json<serde_json::Value> {
    Json(serde_json::json!({"status": "ok"}))
}

/// Readiness: the store answers.
#[utoipa::path(get, path = "/readyz", tag = "ops", responses((status = 200, description = "ready"), (status = 503, description = "store unavailable")))]
pub async fn readyz(State(st): State<AppState>) -> Result<Json<serde_json::Value>, ApiError> {
    st.service.store.ping().await?;
    Ok(Json(serde_json::json!({"status": "ready", "store": st.service.store.dialect()})))
}

/// Prometheus text: queue depth, jobs by state, stage and job duration histograms by method,
/// failures by code, rejected requests by code.
/// With `--metrics-token`, only that bearer token may read it; with API tokens and no metrics
/// token, nobody may (the figures span every tenant).
#[utoipa::path(get, path = "/metrics", tag = "ops", responses((status = 200, content_type = "text/plain", description = "Prometheus exposition"),
    (status = 401, description = "the metrics token is required", body = crate::error::ErrorBody)))]
pub async fn metrics(
    State(st): State<AppState>,
    headers: axum::http::HeaderMap,
) -> Result<impl IntoResponse, ApiError> {
    st.auth.metrics_allowed(headers.get(header::AUTHORIZATION).and_then(|v| v.to_str().ok()))?;
    for (state, n) in st.service.store.count_by_state().await? {
        metrics::gauge!("surfmap_jobs", "state" => state.as_str()).set(n as f64);
        if state == surfmap_store::JobState::Queued {
            metrics::gauge!("surfmap_queue_depth").set(n as f64);
        }
    }
    Ok(([(header::CONTENT_TYPE, "text/plain; version=0.0.4")], surfmap_worker::telemetry::prometheus().render()))
}
