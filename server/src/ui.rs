//! The dashboard: `/ui/` (jobs, live over the SSE stream) and `/ui/jobs/{id}` (one job and its
//! 3D viewer), static pages and ES modules embedded in the binary, with three.js vendored
//! under `ui/vendor/three` (its LICENSE beside it). The pages hold no data: their scripts call
//! the REST API, so tokens and tenant isolation are the API's. A page request that carries
//! `Authorization` (a proxy that adds it) must carry a valid token, and the page then calls
//! the API without asking for one; otherwise, with tokens configured, the page asks for a token
//! and keeps it in `sessionStorage`.

use crate::AppState;
use crate::error::ApiError;
use axum::Router;
use axum::extract::State;
use axum::http::{HeaderMap, HeaderValue, header};
use axum::response::{IntoResponse, Redirect, Response};
use axum::routing::get;

/// Embedded files under `/ui/assets/`: path, content type, bytes.
const ASSETS: &[(&str, &str, &[u8])] = &[
    ("app.css", "text/css; charset=utf-8", include_bytes!("../ui/app.css")),
    ("api.js", "text/javascript; charset=utf-8", include_bytes!("../ui/api.js")),
    ("jobs.js", "text/javascript; charset=utf-8", include_bytes!("../ui/jobs.js")),
    ("job.js", "text/javascript; charset=utf-8", include_bytes!("../ui/job.js")),
    ("viewer.js", "text/javascript; charset=utf-8", include_bytes!("../ui/viewer.js")),
    ("vendor/three/LICENSE", "text/plain; charset=utf-8", include_bytes!("../ui/vendor/three/LICENSE")),
    (
        "vendor/three/three.module.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../ui/vendor/three/three.module.js"),
    ),
    (
        "vendor/three/three.core.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../ui/vendor/three/three.core.js"),
    ),
    (
        "vendor/three/addons/loaders/GLTFLoader.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../ui/vendor/three/addons/loaders/GLTFLoader.js"),
    ),
    (
        "vendor/three/addons/controls/OrbitControls.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../ui/vendor/three/addons/controls/OrbitControls.js"),
    ),
    (
        "vendor/three/addons/utils/BufferGeometryUtils.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../ui/vendor/three/addons/utils/BufferGeometryUtils.js"),
    ),
    (
        "vendor/three/addons/utils/SkeletonUtils.js",
        "text/javascript; charset=utf-8",
        include_bytes!("../ui/vendor/three/addons/utils/SkeletonUtils.js"),
    ),
];

const JOBS_PAGE: &str = include_str!("../ui/jobs.html");
const JOB_PAGE: &str = include_str!("../ui/job.html");

/// How the page's scripts authenticate: `none` (no tokens configured), `token` (ask for one,
/// keep it in sessionStorage), `forwarded` (the page request carried a valid `Authorization`;
/// the same front sends it with the API calls).
fn auth_mode(st: &AppState, headers: &HeaderMap) -> Result<&'static str, ApiError> {
    if !st.auth.enabled() {
        return Ok("none");
    }
    match headers.get(header::AUTHORIZATION) {
        None => Ok("token"),
        Some(v) => st.auth.owner(v.to_str().ok()).map(|_| "forwarded"),
    }
}

fn page(st: &AppState, headers: &HeaderMap, html: &str) -> Result<Response, ApiError> {
    let body = html.replace("{{AUTH_MODE}}", auth_mode(st, headers)?);
    Ok((
        [
            (header::CONTENT_TYPE, HeaderValue::from_static("text/html; charset=utf-8")),
            (header::CACHE_CONTROL, HeaderValue::from_static("no-store")),
            (header::X_CONTENT_TYPE_OPTIONS, HeaderValue::from_static("nosniff")),
            (header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY")),
            (header::REFERRER_POLICY, HeaderValue::from_static("no-referrer")),
        ],
        body,
    )
        .into_response())
}

async fn jobs_page(State(st): State<AppState>, headers: HeaderMap) -> Result<Response, ApiError> {
    page(&st, &headers, JOBS_PAGE)
}

/// The job page is the same for every id (its script fetches the job; an unknown or another
/// tenant's job is the API's 404, shown as such).
async fn job_page(State(st): State<AppState>, headers: HeaderMap) -> Result<Response, ApiError> {
    page(&st, &headers, JOB_PAGE)
}

/// An embedded asset, or the JSON 404.
pub fn asset(path: &str) -> Option<(&'static str, &'static [u8])> {
    ASSETS.iter().find(|(p, _, _)| *p == path).map(|(_, ct, b)| (*ct, *b))
}

async fn get_asset(axum::extract::Path(path): axum::extract::Path<String>) -> Result<Response, ApiError> {
    let (ct, bytes) = asset(&path).ok_or_else(|| ApiError::not_found("route_not_found", "no such asset"))?;
    Ok((
        [
            (header::CONTENT_TYPE, HeaderValue::from_static(ct)),
            (header::CACHE_CONTROL, HeaderValue::from_static("no-cache")),
            (header::X_CONTENT_TYPE_OPTIONS, HeaderValue::from_static("nosniff")),
        ],
        bytes,
    )
        .into_response())
}

/// The dashboard's routes.
pub fn router(state: AppState) -> Router {
    Router::new()
        .route("/ui", get(|| async { Redirect::permanent("/ui/") }))
        .route("/ui/", get(jobs_page))
        .route("/ui/jobs/{id}", get(job_page))
        .route("/ui/assets/{*path}", get(get_asset))
        .with_state(state)
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_module_a_page_or_module_imports_is_embedded() {
        for page in [super::JOBS_PAGE, super::JOB_PAGE] {
            for part in page.split("/ui/assets/").skip(1) {
                let path: String = part.chars().take_while(|c| !matches!(c, '"' | '\'' | ')')).collect();
                assert!(super::asset(&path).is_some() || path.ends_with('/'), "{path} is not embedded");
            }
        }
        for (p, _, b) in super::ASSETS.iter().filter(|(p, _, _)| p.ends_with(".js")) {
            let text = std::str::from_utf8(b).expect("utf-8");
            for line in text.lines().filter(|l| l.contains("from './") || l.contains("from \"./")) {
                let rel = line.split(['\'', '"']).nth(1).unwrap_or_default().trim_start_matches("./");
                let dir = p.rsplit_once('/').map(|(d, _)| format!("{d}/")).unwrap_or_default();
                assert!(super::asset(&format!("{dir}{rel}")).is_some(), "{p} imports {rel}, not embedded");
            }
        }
    }
}
