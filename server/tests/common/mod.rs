//! The router under test (`oneshot`, no socket) over a temporary SQLite store, with a worker
//! that drains jobs step by step.
#![allow(dead_code)]

use axum::body::Body;
use axum::http::{Request, StatusCode};
use http_body_util::BodyExt;
use serde_json::Value;
use surfmap_server::service::{JobService, Limits};
use surfmap_server::{AppState, app, auth::Auth};
use surfmap_store::{BlobStore, Store};
use surfmap_worker::{Worker, WorkerConfig};
use tower::ServiceExt;

pub struct T {
    pub _dir: tempfile::TempDir,
    pub state: AppState,
    pub worker: Worker,
}

pub async fn setup_with(tokens: &[String]) -> T {
    let dir = tempfile::tempdir().unwrap();
    let store = Store::connect(&format!("sqlite://{}", dir.path().join("t.db").display())).await.unwrap();
    let blobs = BlobStore::open(dir.path()).unwrap();
    let limits = Limits { max_body_bytes: 1 << 20, ..Limits::default() };
    let state = AppState {
        service: JobService { store: store.clone(), blobs: blobs.clone(), limits, stopping: Default::default() },
        auth: Auth::new(tokens),
    };
    let worker = Worker { store, blobs, config: WorkerConfig::default() };
    T { _dir: dir, state, worker }
}

pub async fn setup() -> T {
    setup_with(&[]).await
}

pub async fn call(t: &T, req: Request<Body>) -> (StatusCode, axum::http::HeaderMap, Vec<u8>) {
    let r = app(t.state.clone()).oneshot(req).await.unwrap();
    let (parts, body) = r.into_parts();
    (parts.status, parts.headers, body.collect().await.unwrap().to_bytes().to_vec())
}

pub async fn json_call(t: &T, method: &str, uri: &str, body: impl Into<Body>) -> (StatusCode, Value) {
    let req = Request::builder().method(method).uri(uri).body(body.into()).unwrap();
    let (s, _, b) = call(t, req).await;
    (s, serde_json::from_slice(&b).unwrap_or(Value::Null))
}

/// The tetrahedron of issue 51 with every coordinate scaled by `k` (1e200 overflows its area).
pub fn tetrahedron_obj(k: &str) -> Vec<u8> {
    format!("v {k} 0 0\nv -{k} 0 0\nv 0 {k} 0\nv 0 0 {k}\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n").into_bytes()
}
