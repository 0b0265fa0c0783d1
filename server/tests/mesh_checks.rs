//! Meshes no job can run on are refused at upload with 422 and a code that says why, over
//! REST (multipart job parts too) and gRPC; a summary stored before the checks existed is a
//! 422 at submission, never a 500.

mod common;
use axum::body::Body;
use axum::http::{Request, StatusCode};
use common::*;
use serde_json::{Value, json};
use surfmap_proto::v1::surfmap_server::Surfmap;
use surfmap_store::{MeshRecord, now_ms};

/// The codes of every refused upload, each a 422 `{code, message}`.
#[tokio::test]
async fn unmappable_meshes_are_refused_at_upload_with_a_code() {
    let t = setup().await;
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("overflow", tetrahedron_obj("1e200"), "mesh_not_finite"),
        ("overflowing products", tetrahedron_obj("1e100"), "mesh_not_finite"),
        ("one point", tetrahedron_obj("0"), "mesh_no_extent"),
        (
            "zero-area face",
            b"v 0 0 0\nv 2 0 0\nv 1 0 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n".to_vec(),
            "zero_area_face",
        ),
        ("flat open mesh", b"v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n".to_vec(), "mesh_no_extent"),
    ];
    for (what, bytes, code) in cases {
        let (st, e) = json_call(&t, "POST", "/v1/meshes", bytes).await;
        assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some(code)), "{what}: {e}");
        assert!(e["message"].as_str().is_some_and(|m| !m.is_empty()), "{what}: {e}");
    }
    // The same tetrahedron at a sane scale is stored with finite numbers.
    let (st, m) = json_call(&t, "POST", "/v1/meshes", tetrahedron_obj("1")).await;
    assert_eq!(st, StatusCode::CREATED, "{m}");
    for k in ["area", "bbox_diagonal"] {
        assert!(m["summary"][k].as_f64().is_some_and(f64::is_finite), "{k}: {m}");
    }
    // A multipart job whose mesh part overflows: the same 422, nothing queued.
    let boundary = "XyZ";
    let mut body = Vec::new();
    for (name, bytes) in [("mesh", tetrahedron_obj("1e200")), ("mesh", tetrahedron_obj("2"))] {
        body.extend(
            format!("--{boundary}\r\nContent-Disposition: form-data; name=\"{name}\"; filename=\"m.obj\"\r\n\r\n")
                .bytes(),
        );
        body.extend(bytes);
        body.extend(b"\r\n");
    }
    body.extend(format!("--{boundary}\r\nContent-Disposition: form-data; name=\"spec\"\r\n\r\n{{\"method\": \"voronoi\", \"anchors\": [[0, 0], [1, 1], [2, 2]]}}\r\n--{boundary}--\r\n").bytes());
    let req = Request::post("/v1/jobs")
        .header("content-type", format!("multipart/form-data; boundary={boundary}"))
        .body(Body::from(body))
        .unwrap();
    let (st, _, e) = call(&t, req).await;
    let e: Value = serde_json::from_slice(&e).unwrap();
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("mesh_not_finite")), "{e}");
    let (_, page) = json_call(&t, "GET", "/v1/jobs", Body::empty()).await;
    assert_eq!(page["jobs"], json!([]));
}

#[tokio::test]
async fn grpc_upload_of_an_overflowing_mesh_is_invalid_argument_with_the_code() {
    let t = setup().await;
    let api = surfmap_server::grpc::GrpcApi { state: t.state.clone() };
    let req = tonic::Request::new(surfmap_proto::v1::UploadMeshRequest {
        data: tetrahedron_obj("1e200"),
        ..Default::default()
    });
    let s = api.upload_mesh(req).await.unwrap_err();
    assert_eq!(s.code(), tonic::Code::InvalidArgument, "{s:?}");
    assert_eq!(s.metadata().get("surfmap-error-code").and_then(|v| v.to_str().ok()), Some("mesh_not_finite"));
}

/// A mesh stored by an older server with nulls in its summary: jobs on it are a 422, not a 500.
#[tokio::test]
async fn a_stored_summary_with_nulls_is_a_422_at_submission() {
    let t = setup().await;
    let (_, good) = json_call(&t, "POST", "/v1/meshes", tetrahedron_obj("1")).await;
    let mut summary = good["summary"].clone();
    summary["area"] = Value::Null;
    summary["bbox_diagonal"] = Value::Null;
    let id = "ab".repeat(32);
    let rec = MeshRecord {
        owner: String::new(),
        id: id.clone(),
        format: "obj".into(),
        size_bytes: 10,
        summary: summary.to_string(),
        created_at: now_ms(),
    };
    t.state.service.store.put_mesh(&rec).await.unwrap();
    let spec = json!({"method": "voronoi", "anchors": [[0, 0], [1, 1], [2, 2]]});
    let body = json!({"source": id, "target": good["id"], "spec": spec}).to_string();
    let (st, e) = json_call(&t, "POST", "/v1/jobs", body).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("mesh_not_finite")), "{e}");
}
