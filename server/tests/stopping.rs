//! On shutdown the watch streams end: SSE with the job once more and `event: shutdown`,
//! gRPC `WatchJob` with the job once more and UNAVAILABLE carrying `shutting_down`.

mod common;
use axum::body::Body;
use axum::http::Request;
use common::*;
use futures::StreamExt;
use http_body_util::BodyExt;
use serde_json::json;
use std::time::Duration;
use surfmap_proto::v1 as pb;
use surfmap_proto::v1::surfmap_server::Surfmap;
use tower::ServiceExt;

/// A queued job (no worker runs it) on a service whose stopping signal the test holds.
async fn queued(t: &mut T) -> (String, tokio::sync::watch::Sender<bool>) {
    let (tx, rx) = tokio::sync::watch::channel(false);
    t.state.service.stopping = surfmap_server::stopping::Stopping::new(rx);
    let s = geom::mesh::shapes::icosphere(2);
    let (_, a) = json_call(t, "POST", "/v1/meshes", geom::io::write(&s, geom::io::Format::Off)).await;
    let spec = json!({"method": "voronoi", "anchors": [[0, 0], [5, 5], [9, 9]]});
    let body = json!({"source": a["id"], "target": a["id"], "spec": spec}).to_string();
    let (_, j) = json_call(t, "POST", "/v1/jobs", body).await;
    (j["id"].as_str().unwrap().to_string(), tx)
}

#[tokio::test]
async fn sse_ends_with_a_shutdown_event() {
    let mut t = setup().await;
    let (id, tx) = queued(&mut t).await;
    let req = Request::get(format!("/v1/jobs/{id}/events")).body(Body::empty()).unwrap();
    let res = surfmap_server::app(t.state.clone()).oneshot(req).await.unwrap();
    let stopper = tokio::spawn(async move {
        tokio::time::sleep(Duration::from_millis(300)).await;
        tx.send(true).unwrap();
        tx
    });
    let body = tokio::time::timeout(Duration::from_secs(5), res.into_body().collect()).await.expect("the stream ends");
    let text = String::from_utf8(body.unwrap().to_bytes().to_vec()).unwrap();
    assert_eq!(text.matches("event: job").count(), 2, "the job, then the job once more: {text}");
    assert!(
        text.trim_end().ends_with(r#"data: {"code":"shutting_down","message":"the server is stopping; reconnect"}"#),
        "{text}"
    );
    drop(stopper.await);
}

#[tokio::test]
async fn grpc_watch_ends_unavailable_with_the_code() {
    let mut t = setup().await;
    let (id, tx) = queued(&mut t).await;
    let api = surfmap_server::grpc::GrpcApi { state: t.state.clone() };
    let mut s = api.watch_job(tonic::Request::new(pb::WatchJobRequest { id })).await.unwrap().into_inner();
    assert_eq!(s.next().await.unwrap().unwrap().state, "queued");
    tx.send(true).unwrap();
    let items: Vec<_> = tokio::time::timeout(Duration::from_secs(5), s.collect::<Vec<_>>()).await.expect("ends");
    assert_eq!(items.len(), 2, "the job once more, then the status");
    assert_eq!(items[0].as_ref().unwrap().state, "queued");
    let e = items[1].as_ref().unwrap_err();
    assert_eq!(e.code(), tonic::Code::Unavailable);
    assert_eq!(e.metadata().get("surfmap-error-code").unwrap(), "shutting_down");
}
