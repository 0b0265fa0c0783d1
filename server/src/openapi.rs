//! The OpenAPI document, derived from the handlers' annotations (utoipa), with the bearer
//! security scheme and the 401 answers of the routes that take a token added here.

use crate::AppState;
use crate::error::ErrorBody;
use crate::rest::{artifacts, jobs, meshes, ops};
use crate::views::{
    ArtifactList, ArtifactView, JobLinks, JobPage, JobView, MeshView, MeshesJobRequest, PairJobRequest, SpecOutline,
    SubmitJobRequest,
};
use axum::Json;
use axum::extract::State;

#[derive(utoipa::OpenApi)]
#[openapi(
    info(
        title = "surfmap",
        description = "Compatible meshes, cross-parameterizations and distortion metrics for pairs of triangle meshes."
    ),
    paths(
        meshes::upload_mesh,
        meshes::get_mesh,
        meshes::get_mesh_glb,
        jobs::submit_job,
        jobs::list_jobs,
        jobs::get_job,
        jobs::cancel_job,
        jobs::job_events,
        artifacts::list_artifacts,
        artifacts::get_artifact,
        ops::healthz,
        ops::readyz,
        ops::metrics,
        serve
    ),
    components(schemas(
        ErrorBody,
        MeshView,
        JobView,
        JobLinks,
        JobPage,
        ArtifactView,
        ArtifactList,
        SubmitJobRequest,
        PairJobRequest,
        MeshesJobRequest,
        SpecOutline
    ))
)]
pub struct ApiDoc;

/// The document as served: every `/v1` route (and `/metrics`) takes a bearer token and may
/// answer 401. With tokens configured the token is required; without, it is optional (`{}`
/// among the requirements: the server then ignores it).
pub fn document(auth_required: bool) -> serde_json::Value {
    use serde_json::json;
    use utoipa::OpenApi;
    let mut doc = serde_json::to_value(ApiDoc::openapi()).unwrap_or_default();
    doc["components"]["securitySchemes"]["bearer"] = json!({
        "type": "http", "scheme": "bearer",
        "description": "a token of `--api-token`; the owner of the jobs and meshes it sees (`--metrics-token` for /metrics)"
    });
    let security = if auth_required { json!([{"bearer": []}]) } else { json!([{"bearer": []}, {}]) };
    let unauthorized = json!({
        "description": "missing or unknown bearer token",
        "content": {"application/json": {"schema": {"$ref": "#/components/schemas/ErrorBody"}}}
    });
    if let Some(paths) = doc.get_mut("paths").and_then(serde_json::Value::as_object_mut) {
        for (path, item) in paths.iter_mut().filter(|(p, _)| p.starts_with("/v1/") || *p == "/metrics") {
            let ops = item.as_object_mut().into_iter().flat_map(|m| m.iter_mut());
            for (_, op) in ops.filter(|(m, _)| ["get", "post", "put", "patch", "delete"].contains(&m.as_str())) {
                op["security"] = if path == "/metrics" { json!([{"bearer": []}, {}]) } else { security.clone() };
                op["responses"]["401"] = unauthorized.clone();
            }
        }
    }
    doc
}

/// The OpenAPI 3.1 document of this API.
#[utoipa::path(get, path = "/openapi.json", tag = "ops", responses((status = 200, description = "OpenAPI document")))]
pub async fn serve(State(st): State<AppState>) -> Json<serde_json::Value> {
    Json(document(st.auth.enabled()))
}
