//! The API's edges a hostile or new client finds (issue 51): undecodable gRPC bytes, bad
//! cursors, the bearer scheme's case, 405 bodies, the document's security, gRPC `Job.meshes`.

mod common;
use axum::body::Body;
use axum::http::{Request, StatusCode};
use common::*;
use serde_json::{Value, json};
use surfmap_proto::v1 as pb;
use surfmap_proto::v1::surfmap_server::Surfmap;

/// A gRPC request over the router: the 5-byte frame header, then `message`.
fn grpc_request(method: &str, message: &[u8]) -> Request<Body> {
    let mut body = vec![0u8];
    body.extend((message.len() as u32).to_be_bytes());
    body.extend(message);
    Request::post(format!("/surfmap.v1.Surfmap/{method}"))
        .header("content-type", "application/grpc")
        .header("te", "trailers")
        .body(Body::from(body))
        .unwrap()
}

#[tokio::test]
async fn undecodable_grpc_bytes_are_invalid_argument_with_the_code() {
    let t = setup().await;
    // Wire type 7 does not exist; a length running past the end; a truncated varint.
    for bad in [&[0xffu8, 0xff, 0xff][..], &[0x0a, 0x7f, 0x01], &[0x08, 0x80]] {
        for method in ["SubmitJob", "UploadMesh", "GetJob", "WatchJob"] {
            let (st, h, _) = call(&t, grpc_request(method, bad)).await;
            assert_eq!(st, StatusCode::OK, "gRPC answers in its own status");
            let get = |k: &str| h.get(k).and_then(|v| v.to_str().ok()).unwrap_or("");
            assert_eq!(get("grpc-status"), "3", "{method} {bad:?}: {h:?}");
            assert_eq!(get("surfmap-error-code"), "invalid_message", "{method} {bad:?}: {h:?}");
        }
    }
    // A decodable request still reaches the service (an unknown job: NOT_FOUND with its code).
    let (_, h, _) = call(&t, grpc_request("GetJob", &[0x0a, 0x01, b'x'])).await;
    assert_eq!(h.get("grpc-status").map(|v| v.to_str().unwrap()), Some("5"), "{h:?}");
    assert_eq!(h.get("surfmap-error-code").map(|v| v.to_str().unwrap()), Some("job_not_found"));
}

#[tokio::test]
async fn a_cursor_that_is_not_a_job_id_is_a_400() {
    let t = setup().await;
    for c in ["", "!!!", "abc", "0190e2c4-1b2a-7c3d-8e4f-5a6b7c8d9e0", "0190E2C4-1B2A-7C3D-8E4F-5A6B7C8D9E0F", "%00"] {
        let (st, e) = json_call(&t, "GET", &format!("/v1/jobs?cursor={c}"), Body::empty()).await;
        assert_eq!((st, e["code"].as_str()), (StatusCode::BAD_REQUEST, Some("invalid_cursor")), "{c}: {e}");
    }
    let (st, page) = json_call(&t, "GET", "/v1/jobs?cursor=0190e2c4-1b2a-7c3d-8e4f-5a6b7c8d9e0f", Body::empty()).await;
    assert_eq!((st, &page["jobs"]), (StatusCode::OK, &json!([])));
    let api = surfmap_server::grpc::GrpcApi { state: t.state.clone() };
    let req = tonic::Request::new(pb::ListJobsRequest { cursor: "!!!".into(), ..Default::default() });
    let s = api.list_jobs(req).await.unwrap_err();
    assert_eq!(s.code(), tonic::Code::InvalidArgument);
    assert_eq!(s.metadata().get("surfmap-error-code").unwrap(), "invalid_cursor");
}

#[tokio::test]
async fn the_bearer_scheme_is_case_insensitive() {
    let t = setup_with(&["T0k".to_string()]).await;
    for (h, want) in [
        ("Bearer T0k", StatusCode::OK),
        ("bearer T0k", StatusCode::OK),
        ("BEARER T0k", StatusCode::OK),
        ("bearer t0k", StatusCode::UNAUTHORIZED),
        ("Basic T0k", StatusCode::UNAUTHORIZED),
    ] {
        let req = Request::get("/v1/jobs").header("authorization", h).body(Body::empty()).unwrap();
        let (st, _, b) = call(&t, req).await;
        assert_eq!(st, want, "{h}: {}", String::from_utf8_lossy(&b));
    }
    let api = surfmap_server::grpc::GrpcApi { state: t.state.clone() };
    let mut req = tonic::Request::new(pb::ListJobsRequest::default());
    req.metadata_mut().insert("authorization", "bearer T0k".parse().unwrap());
    assert!(api.list_jobs(req).await.is_ok());
}

#[tokio::test]
async fn a_405_has_a_json_body_and_the_allow_header() {
    let t = setup().await;
    for (m, uri) in [("DELETE", "/v1/jobs"), ("PUT", "/v1/meshes"), ("POST", "/healthz"), ("PATCH", "/v1/jobs/x")] {
        let req = Request::builder().method(m).uri(uri).body(Body::empty()).unwrap();
        let (st, h, b) = call(&t, req).await;
        let e: Value = serde_json::from_slice(&b).unwrap_or(Value::Null);
        assert_eq!((st, e["code"].as_str()), (StatusCode::METHOD_NOT_ALLOWED, Some("method_not_allowed")), "{m} {uri}");
        assert!(e["message"].as_str().is_some_and(|s| !s.is_empty()));
        assert!(h.contains_key("allow"), "{m} {uri}: {h:?}");
    }
}

#[tokio::test]
async fn the_document_declares_the_bearer_scheme_and_401s() {
    for (tokens, required) in [(vec!["k".to_string()], true), (vec![], false)] {
        let t = setup_with(&tokens).await;
        let (st, doc) = json_call(&t, "GET", "/openapi.json", Body::empty()).await;
        assert_eq!(st, StatusCode::OK);
        assert_eq!(doc["components"]["securitySchemes"]["bearer"]["scheme"], "bearer");
        for (path, method) in [("/v1/meshes", "post"), ("/v1/jobs", "get"), ("/v1/jobs/{id}/events", "get")] {
            let op = &doc["paths"][path][method];
            assert!(op["responses"]["401"].is_object(), "{path}");
            let alternatives = op["security"].as_array().unwrap();
            assert_eq!(alternatives[0], json!({"bearer": []}));
            assert_eq!(alternatives.len() == 1, required, "{path}: {alternatives:?}");
        }
        assert!(doc["paths"]["/healthz"]["get"]["security"].is_null(), "probes take no token");
    }
}

#[tokio::test]
async fn grpc_jobs_carry_their_meshes() {
    let t = setup().await;
    let s = geom::mesh::shapes::icosphere(2);
    let mut ids = Vec::new();
    for k in [1.0, 1.3] {
        let m = s.with_positions(s.positions().iter().map(|p| geom::mesh::P3::from(p.coords * k)).collect()).unwrap();
        let (_, a) = json_call(&t, "POST", "/v1/meshes", geom::io::write(&m, geom::io::Format::Off)).await;
        ids.push(a["id"].as_str().unwrap().to_string());
    }
    let api = surfmap_server::grpc::GrpcApi { state: t.state.clone() };
    let spec = json!({"method": "voronoi", "anchors": [[0, 0], [5, 5], [9, 9]]}).to_string();
    let req = pb::SubmitJobRequest { meshes: ids.clone(), spec_json: spec, ..Default::default() };
    let j = api.submit_job(tonic::Request::new(req)).await.unwrap().into_inner();
    assert_eq!(j.meshes, ids);
    let got = api.get_job(tonic::Request::new(pb::GetJobRequest { id: j.id.clone() })).await.unwrap().into_inner();
    assert_eq!((got.meshes, got.source, got.target), (ids.clone(), ids[0].clone(), ids[1].clone()));
}
