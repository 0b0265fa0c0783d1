//! One test per class of bad input against the real server: each answers 4xx with a clear
//! code and message (or the matching gRPC status), and the server stays up.

mod common;

use common::{Api, Env, SMPL, identity_spec, shared};
use futures::StreamExt;
use serde_json::{Value, json};
use std::time::Duration;
use surfmap_proto::v1 as pb;
use surfmap_proto::v1::surfmap_client::SurfmapClient;

async fn expect(api: &Api, (status, body): (u16, Value), want_status: u16, want_code: &str, message_has: &str) {
    assert_eq!(status, want_status, "{body}");
    assert_eq!(body["code"], want_code, "{body}");
    let msg = body["message"].as_str().unwrap_or_default();
    assert!(msg.contains(message_has), "message {msg:?} should mention {message_has:?}");
    assert_eq!(api.get("/healthz").await.0, 200, "server still up after {want_code}");
}

/// Posts a mesh body of `chunks` × 64 KiB that then stalls, optionally declaring `length`.
async fn oversize(api: &Api, length: Option<usize>, chunks: usize) -> (u16, Value) {
    let body = futures::stream::iter((0..chunks).map(|_| Ok::<_, std::io::Error>(vec![b'v'; 64 << 10])))
        .chain(futures::stream::pending());
    let mut req = api.req(reqwest::Method::POST, "/v1/meshes").body(reqwest::Body::wrap_stream(body));
    if let Some(n) = length {
        req = req.header("content-length", n.to_string());
    }
    let r = tokio::time::timeout(Duration::from_secs(20), req.send()).await.expect("answered").expect("response");
    (r.status().as_u16(), r.json().await.unwrap_or(Value::Null))
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn every_class_of_bad_input_gets_a_clear_4xx() {
    let env = Env::sqlite();
    let (_server, base) =
        env.server(&["--workers", "0", "--api-token", "alpha", "--api-token", "beta", "--max-body-mb", "1"]);
    let mut api = Api::new(&base);

    // Wrong or missing token.
    expect(&api, api.get("/v1/jobs").await, 401, "unauthorized", "token").await;
    api.token = Some("gamma".into());
    expect(&api, api.get("/v1/jobs").await, 401, "unauthorized", "token").await;
    api.token = Some("alpha".into());

    // Malformed mesh, lying counts, NaN coordinates, a non-manifold edge.
    let bad = b"OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n".to_vec();
    expect(&api, api.upload_bytes(bad).await, 422, "parse_error", "line 4").await;
    let lying = b"OFF\n1000000 2000000 0\n0 0 0\n1 0 0\n".to_vec();
    expect(&api, api.upload_bytes(lying).await, 422, "lying_count", "1000000").await;
    let nan = b"OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n".to_vec();
    expect(&api, api.upload_bytes(nan).await, 422, "non_finite_coordinate", "vertex 1").await;
    let fin = b"OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n".to_vec();
    expect(&api, api.upload_bytes(fin).await, 422, "non_manifold_edge", "(0, 1)").await;

    // Oversize bodies: a declared length over the limit is refused before any byte is read;
    // a chunked body is cut off once it passes the limit. The client then pauses (it does not
    // close), so the answer is read before anything else happens on the connection.
    expect(&api, oversize(&api, Some(2 << 20), 0).await, 413, "payload_too_large", "2097152").await;
    expect(&api, oversize(&api, None, 17).await, 413, "payload_too_large", "limit").await;

    // Good meshes for the job classes.
    let (_, man) = api.upload(&shared(SMPL.0)).await;
    let (_, woman) = api.upload(&shared(SMPL.1)).await;
    let (_, torus) = api.upload(&shared("meshes/torus.obj")).await;
    let (man, woman, torus) =
        (man["id"].as_str().unwrap(), woman["id"].as_str().unwrap(), torus["id"].as_str().unwrap());

    // Unknown method, malformed spec, anchors out of range, genus mismatch, unknown mesh.
    let magic = json!({"method": "magic", "anchors": [[0, 0], [1, 1], [2, 2]]});
    expect(&api, api.submit(man, woman, &magic).await, 400, "unknown_method", "magic").await;
    let typo = json!({"method": "voronoi", "anchors": [[0, 0], [1, 1], [2, 2]], "optionz": {}});
    expect(&api, api.submit(man, woman, &typo).await, 400, "invalid_spec", "optionz").await;
    let far = json!({"method": "voronoi", "anchors": [[0, 0], [1, 1], [99999, 2]]});
    expect(&api, api.submit(man, woman, &far).await, 422, "invalid_anchors", "99999").await;
    let spec = identity_spec("voronoi", 8);
    expect(&api, api.submit(man, torus, &spec).await, 422, "topology_mismatch", "genus").await;
    expect(&api, api.submit(man, &"0".repeat(64), &spec).await, 404, "mesh_not_found", "target").await;

    // Unknown job; an artifact name that climbs out of its directory.
    expect(&api, api.get("/v1/jobs/no-such-job").await, 404, "job_not_found", "no-such-job").await;
    let (st, job) = api.submit(man, woman, &spec).await;
    assert_eq!(st, 202);
    let id = job["id"].as_str().unwrap();
    let climb = api.get(&format!("/v1/jobs/{id}/artifacts/..%2F..%2Fsurfmap.db")).await;
    expect(&api, climb, 400, "invalid_artifact_name", "../").await;
    expect(&api, api.get(&format!("/v1/jobs/{id}/artifacts/nope.obj")).await, 404, "artifact_not_found", "nope").await;

    // Tokens isolate clients.
    let mut other = api.clone();
    other.token = Some("beta".into());
    expect(&other, other.get(&format!("/v1/jobs/{id}")).await, 404, "job_not_found", id).await;
    expect(&other, other.submit(man, woman, &spec).await, 404, "mesh_not_found", "source").await;

    // A queued job cancels at once; an idempotency key reused for another request is refused.
    let r = api.req(reqwest::Method::POST, &format!("/v1/jobs/{id}/cancel")).send().await.unwrap();
    assert_eq!(r.json::<Value>().await.unwrap()["state"], "cancelled");
    let post = |spec: Value| {
        api.req(reqwest::Method::POST, "/v1/jobs")
            .header("Idempotency-Key", "k-1")
            .json(&json!({"source": man, "target": woman, "spec": spec}))
            .send()
    };
    let first: Value = post(spec.clone()).await.unwrap().json().await.unwrap();
    let replay = post(spec.clone()).await.unwrap();
    assert_eq!(replay.headers()["idempotent-replayed"], "true");
    assert_eq!(replay.json::<Value>().await.unwrap()["id"], first["id"]);
    let r = post(identity_spec("voronoi", 9)).await.unwrap();
    let status = r.status().as_u16();
    expect(&api, (status, r.json().await.unwrap()), 409, "idempotency_conflict", "Idempotency-Key").await;

    // The same classes over gRPC.
    let channel = tonic::transport::Channel::from_shared(base.clone()).unwrap().connect().await.unwrap();
    let mut anon = SurfmapClient::new(channel.clone());
    let e = anon.get_job(pb::GetJobRequest { id: id.into() }).await.unwrap_err();
    assert_eq!(e.code(), tonic::Code::Unauthenticated);
    let token: tonic::metadata::MetadataValue<_> = "Bearer alpha".parse().unwrap();
    let mut g = SurfmapClient::with_interceptor(channel, move |mut req: tonic::Request<()>| {
        req.metadata_mut().insert("authorization", token.clone());
        Ok(req)
    });
    let e = g.get_job(pb::GetJobRequest { id: "no-such-job".into() }).await.unwrap_err();
    assert_eq!(e.code(), tonic::Code::NotFound);
    let req = |spec: &Value, t: &str| pb::SubmitJobRequest {
        source: man.into(),
        target: t.into(),
        spec_json: spec.to_string(),
        idempotency_key: String::new(),
        meshes: Vec::new(),
    };
    let e = g.submit_job(req(&magic, woman)).await.unwrap_err();
    assert_eq!(
        (e.code(), e.metadata().get("surfmap-error-code").unwrap().to_str().unwrap()),
        (tonic::Code::InvalidArgument, "unknown_method")
    );
    let e = g.submit_job(req(&spec, torus)).await.unwrap_err();
    assert_eq!(e.code(), tonic::Code::InvalidArgument);
    assert!(e.message().contains("genus"), "{}", e.message());
    let e = g
        .upload_mesh(pb::UploadMeshRequest { data: b"OFF\n9 9 0\n".to_vec(), format_hint: String::new() })
        .await
        .unwrap_err();
    assert_eq!(e.code(), tonic::Code::InvalidArgument);
    let e = g.get_artifact(pb::GetArtifactRequest { job_id: id.into(), name: "../../x".into() }).await.unwrap_err();
    assert_eq!(e.code(), tonic::Code::InvalidArgument);
    tokio::time::sleep(Duration::from_millis(10)).await;
    assert_eq!(api.get("/healthz").await.0, 200);
}
