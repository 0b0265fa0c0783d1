//! The router called directly (`oneshot`, no socket): uploads, submission, validation answers,
//! paging, SSE, artifacts, metrics and the OpenAPI document, with jobs drained step by step by a
//! worker in the test.

mod common;

use axum::body::Body;
use axum::http::{Request, StatusCode};
use common::{call, json_call, setup};
use geom::io::Format;
use serde_json::{Value, json};
use surfmap_store::BlobStore;
use surfmap_worker::Ran;

fn sphere_pair() -> (Vec<u8>, Vec<u8>) {
    let s = geom::mesh::shapes::icosphere(3);
    let t = s.with_positions(s.positions().iter().map(|p| geom::mesh::P3::new(p.x * 1.5, p.y * 0.8, p.z)).collect());
    (geom::io::write(&s, Format::Off), geom::io::write(&t.unwrap(), Format::Obj))
}

fn spec() -> Value {
    json!({"method": "voronoi", "anchors": [[0, 0], [2, 2], [5, 5], [7, 7], [9, 9], [11, 11]]})
}

#[tokio::test]
async fn upload_submit_drain_and_download() {
    let t = setup().await;
    let (s, tg) = sphere_pair();
    let (st, a) = json_call(&t, "POST", "/v1/meshes", Body::from(s.clone())).await;
    assert_eq!(st, StatusCode::CREATED, "{a}");
    assert_eq!((a["format"].as_str(), a["summary"]["genus"].as_i64()), (Some("off"), Some(0)));
    assert_eq!(a["id"].as_str().unwrap(), BlobStore::key(&s));
    let (_, b) = json_call(&t, "POST", "/v1/meshes", Body::from(tg)).await;
    assert_eq!(b["format"], "obj");
    let body = json!({"source": a["id"], "target": b["id"], "spec": spec()}).to_string();
    let req = Request::post("/v1/jobs").header("content-type", "application/json").body(Body::from(body)).unwrap();
    let (st, headers, job) = call(&t, req).await;
    assert_eq!(st, StatusCode::ACCEPTED);
    let job: Value = serde_json::from_slice(&job).unwrap();
    let id = job["id"].as_str().unwrap().to_string();
    assert_eq!(headers["location"], format!("/v1/jobs/{id}").as_str());
    assert_eq!((job["state"].as_str(), job["attempts"].as_i64()), (Some("queued"), Some(0)));
    let spec_back: Value = json_call(&t, "GET", &format!("/v1/jobs/{id}"), Body::empty()).await.1;
    assert_eq!(spec_back["state"], "queued");

    // Drain one step.
    let (tx, rx) = tokio::sync::watch::channel(false);
    assert_eq!(t.worker.run_once(&rx).await.unwrap(), Ran::Ran { job: id.clone(), outcome: "succeeded".into() });
    assert_eq!(t.worker.run_once(&rx).await.unwrap(), Ran::Idle);
    drop(tx);
    let (_, done) = json_call(&t, "GET", &format!("/v1/jobs/{id}"), Body::empty()).await;
    assert_eq!((done["state"].as_str(), done["progress"].as_f64()), (Some("succeeded"), Some(1.0)));
    assert_eq!(done["result"]["source_to_target"]["flipped_faces"], 0);

    // A finished job's SSE stream: one event, then the end.
    let (st, h, ev) = call(&t, Request::get(format!("/v1/jobs/{id}/events")).body(Body::empty()).unwrap()).await;
    assert_eq!((st, h["content-type"].to_str().unwrap()), (StatusCode::OK, "text/event-stream"));
    let ev = String::from_utf8(ev).unwrap();
    assert_eq!(ev.matches("event: job").count(), 1, "{ev}");
    assert!(ev.contains("\"state\":\"succeeded\""));

    // Artifacts: list, download with content types, compatible connectivity.
    let (_, list) = json_call(&t, "GET", &format!("/v1/jobs/{id}/artifacts"), Body::empty()).await;
    assert_eq!(list["artifacts"].as_array().unwrap().len(), 9, "voronoi artifacts with morph.glb");
    let (st, h, obj) =
        call(&t, Request::get(format!("/v1/jobs/{id}/artifacts/source_on_target.obj")).body(Body::empty()).unwrap())
            .await;
    assert_eq!((st, h["content-type"].to_str().unwrap()), (StatusCode::OK, "model/obj"));
    let mapped = geom::io::read(&obj, &Default::default()).unwrap().mesh;
    let source = geom::io::read(&s, &Default::default()).unwrap().mesh;
    assert_eq!(mapped.faces(), source.faces());

    // Metrics show the queue, the states and the worker's stage histogram.
    let (_, _, m) = call(&t, Request::get("/metrics").body(Body::empty()).unwrap()).await;
    let m = String::from_utf8(m).unwrap();
    assert!(m.contains("surfmap_queue_depth 0"), "{m}");
    assert!(m.contains("surfmap_jobs{state=\"succeeded\"} 1"), "{m}");
    assert!(m.contains("surfmap_stage_duration_seconds_bucket{method=\"voronoi\",stage=\"layout\""), "{m}");
}

#[tokio::test]
async fn validation_answers_before_queueing() {
    let t = setup().await;
    let (s, tg) = sphere_pair();
    let (_, a) = json_call(&t, "POST", "/v1/meshes", Body::from(s)).await;
    let (_, b) = json_call(&t, "POST", "/v1/meshes", Body::from(tg)).await;
    let torus = geom::io::write(&geom::mesh::shapes::torus(12, 8, 1.0, 0.3), Format::Off);
    let (_, c) = json_call(&t, "POST", "/v1/meshes", Body::from(torus)).await;
    let submit = |target: &Value, spec: Value| {
        let body = json!({"source": a["id"], "target": target, "spec": spec}).to_string();
        json_call(&t, "POST", "/v1/jobs", Body::from(body))
    };
    let (st, e) = submit(&c["id"], spec()).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("topology_mismatch")));
    let (st, e) = submit(&b["id"], json!({"method": "voronoi", "anchors": [[0, 0], [1, 1], [100000, 2]]})).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("invalid_anchors")));
    let (st, e) = submit(&b["id"], json!({"method": "voronoi", "anchors": [[0, 0], [1, 1]]})).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("invalid_anchors")));
    let (st, e) = submit(&b["id"], json!({"method": "quadz", "anchors": []})).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::BAD_REQUEST, Some("unknown_method")));
    let (st, e) = json_call(&t, "POST", "/v1/jobs", Body::from("{not json")).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::BAD_REQUEST, Some("invalid_request")));
    let (st, e) = json_call(&t, "POST", "/v1/meshes", Body::from(vec![b'x'; 2 << 20])).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::PAYLOAD_TOO_LARGE, Some("payload_too_large")));
    let (st, e) = json_call(&t, "GET", "/v2/nothing", Body::empty()).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::NOT_FOUND, Some("route_not_found")));
    let (st, e) = json_call(&t, "GET", "/v1/jobs?state=sleeping", Body::empty()).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::BAD_REQUEST, Some("invalid_query")));
    let (_, page) = json_call(&t, "GET", "/v1/jobs", Body::empty()).await;
    assert!(page["jobs"].as_array().unwrap().is_empty(), "nothing was queued");
}

#[tokio::test]
async fn multipart_one_shot_and_paging() {
    let t = setup().await;
    let (s, tg) = sphere_pair();
    let boundary = "XyZ";
    let mut body = Vec::new();
    for (name, file, bytes) in
        [("source", "a.off", s), ("target", "b.obj", tg), ("spec", "", spec().to_string().into_bytes())]
    {
        body.extend(format!("--{boundary}\r\nContent-Disposition: form-data; name=\"{name}\"").bytes());
        if !file.is_empty() {
            body.extend(format!("; filename=\"{file}\"").bytes());
        }
        body.extend(b"\r\n\r\n");
        body.extend(bytes);
        body.extend(b"\r\n");
    }
    body.extend(format!("--{boundary}--\r\n").bytes());
    for _ in 0..3 {
        let req = Request::post("/v1/jobs")
            .header("content-type", format!("multipart/form-data; boundary={boundary}"))
            .body(Body::from(body.clone()))
            .unwrap();
        let (st, _, b) = call(&t, req).await;
        assert_eq!(st, StatusCode::ACCEPTED, "{}", String::from_utf8_lossy(&b));
    }
    let (_, p1) = json_call(&t, "GET", "/v1/jobs?limit=2", Body::empty()).await;
    assert_eq!(p1["jobs"].as_array().unwrap().len(), 2);
    let cursor = p1["next_cursor"].as_str().unwrap();
    let (_, p2) = json_call(&t, "GET", &format!("/v1/jobs?limit=2&cursor={cursor}"), Body::empty()).await;
    assert_eq!(p2["jobs"].as_array().unwrap().len(), 1);
    assert!(p2["next_cursor"].is_null());
}

#[tokio::test]
async fn openapi_and_probes() {
    let t = setup().await;
    let (st, doc) = json_call(&t, "GET", "/openapi.json", Body::empty()).await;
    assert_eq!(st, StatusCode::OK);
    for path in ["/v1/meshes", "/v1/jobs", "/v1/jobs/{id}", "/v1/jobs/{id}/events", "/v1/jobs/{id}/artifacts/{name}"] {
        assert!(doc["paths"][path].is_object(), "{path} missing from the OpenAPI document");
    }
    assert!(doc["components"]["schemas"]["JobView"].is_object());
    // The document is valid OpenAPI: openapi-spec-validator reports no error (the README's
    // test command installs it).
    let file = t._dir.path().join("openapi.json");
    std::fs::write(&file, doc.to_string()).unwrap();
    let script = "import json, sys\nfrom openapi_spec_validator import validate\nfrom openapi_spec_validator.validation.exceptions import OpenAPIValidationError\n\
        errors = 0\ntry:\n    validate(json.load(open(sys.argv[1])))\nexcept OpenAPIValidationError as e:\n    print(e); errors = 1\nsys.exit(errors)";
    let out = std::process::Command::new("python3").arg("-c").arg(script).arg(&file).output().expect("python3");
    assert!(
        out.status.success(),
        "openapi-spec-validator (python3 -m pip install openapi-spec-validator):\n{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(json_call(&t, "GET", "/healthz", Body::empty()).await.0, StatusCode::OK);
    let (st, r) = json_call(&t, "GET", "/readyz", Body::empty()).await;
    assert_eq!((st, r["store"].as_str()), (StatusCode::OK, Some("sqlite")));
}

#[tokio::test]
async fn homology_job_through_the_queue() {
    let t = setup().await;
    let s = geom::mesh::shapes::torus(32, 16, 1.0, 0.35);
    let tg = s.with_positions(s.positions().iter().map(|p| geom::mesh::P3::new(p.x * 1.3, p.y, p.z * 0.9)).collect());
    let (_, a) = json_call(&t, "POST", "/v1/meshes", Body::from(geom::io::write(&s, Format::Off))).await;
    let (_, b) = json_call(&t, "POST", "/v1/meshes", Body::from(geom::io::write(&tg.unwrap(), Format::Off))).await;
    assert_eq!(a["summary"]["genus"].as_i64(), Some(1), "{a}");
    let spec = json!({"method": "homology", "anchors": [[0, 0]], "options": {"rotation": 0, "meta_mesh": true}});
    let body = json!({"source": a["id"], "target": b["id"], "spec": spec}).to_string();
    let req = Request::post("/v1/jobs").header("content-type", "application/json").body(Body::from(body)).unwrap();
    let (st, _, job) = call(&t, req).await;
    assert_eq!(st, StatusCode::ACCEPTED);
    let id = serde_json::from_slice::<Value>(&job).unwrap()["id"].as_str().unwrap().to_string();
    let (_tx, rx) = tokio::sync::watch::channel(false);
    assert_eq!(t.worker.run_once(&rx).await.unwrap(), Ran::Ran { job: id.clone(), outcome: "succeeded".into() });
    let (_, done) = json_call(&t, "GET", &format!("/v1/jobs/{id}"), Body::empty()).await;
    assert_eq!(done["result"]["source_to_target"]["flipped_faces"], 0, "{done}");
    assert_eq!(done["result"]["homology"]["h1"], json!([[1, 0], [0, 1]]), "{done}");
    let (_, list) = json_call(&t, "GET", &format!("/v1/jobs/{id}/artifacts"), Body::empty()).await;
    let names: Vec<&str> = list["artifacts"].as_array().unwrap().iter().filter_map(|a| a["name"].as_str()).collect();
    for n in ["basis_source.json", "domain_target.obj", "meta_source.obj", "meta_target.obj", "metrics.json"] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    // A disk with a feature curve (and its boundary as a feature): mapped exactly, with the
    // meta-mesh of the two circle domains.
    let g = geom::mesh::shapes::grid(8);
    let gt =
        g.with_positions(g.positions().iter().map(|p| geom::mesh::P3::new(p.x * 1.5, p.y, 0.3 * p.x * p.y)).collect());
    let (_, a) = json_call(&t, "POST", "/v1/meshes", Body::from(geom::io::write(&g, Format::Off))).await;
    let (_, b) = json_call(&t, "POST", "/v1/meshes", Body::from(geom::io::write(&gt.unwrap(), Format::Off))).await;
    let spec = json!({"method": "homology", "anchors": [[0, 0]],
        "features": [{"source": [40, 41, 42], "target": [40, 41, 42]}], "options": {"meta_mesh": true}});
    let body = json!({"source": a["id"], "target": b["id"], "spec": spec}).to_string();
    let req = Request::post("/v1/jobs").header("content-type", "application/json").body(Body::from(body)).unwrap();
    let (st, _, job) = call(&t, req).await;
    assert_eq!(st, StatusCode::ACCEPTED, "{}", String::from_utf8_lossy(&job));
    let id = serde_json::from_slice::<Value>(&job).unwrap()["id"].as_str().unwrap().to_string();
    assert_eq!(t.worker.run_once(&rx).await.unwrap(), Ran::Ran { job: id.clone(), outcome: "succeeded".into() });
    let (_, done) = json_call(&t, "GET", &format!("/v1/jobs/{id}"), Body::empty()).await;
    let f = &done["result"]["features"];
    assert_eq!(f["curves"], 2, "{done}");
    assert!(f["feature_error"][0].as_f64().unwrap() <= 1e-9, "{done}");
    assert_eq!(done["result"]["source_to_target"]["flipped_faces"], 0, "{done}");
    assert!(f["meta_mesh"]["faces"].as_u64().unwrap() >= 128 && f["meta_mesh"]["error"].is_null(), "{done}");
    let (_, list) = json_call(&t, "GET", &format!("/v1/jobs/{id}/artifacts"), Body::empty()).await;
    let names: Vec<&str> = list["artifacts"].as_array().unwrap().iter().filter_map(|a| a["name"].as_str()).collect();
    for n in ["meta_source.obj", "meta_target.obj", "meta_morph.glb", "morph.glb"] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    // Genus 0 has no homology basis: refused before queueing.
    let (sp, _) = sphere_pair();
    let (_, c) = json_call(&t, "POST", "/v1/meshes", Body::from(sp)).await;
    let body = json!({"source": c["id"], "target": c["id"], "spec": {"method": "homology", "anchors": [[0, 0]]}});
    let req = Request::post("/v1/jobs")
        .header("content-type", "application/json")
        .body(Body::from(body.to_string()))
        .unwrap();
    let (st, _, e) = call(&t, req).await;
    assert!(st.is_client_error(), "{st}");
    let e: Value = serde_json::from_slice(&e).unwrap();
    assert_eq!(e["code"], "topology_mismatch", "{e}");
}

#[tokio::test]
async fn quad_job_over_three_meshes_through_the_queue() {
    let t = setup().await;
    let s = geom::mesh::shapes::icosphere(3);
    let mut ids = Vec::new();
    for k in 0..3 {
        let f = 1.0 + 0.2 * f64::from(k);
        let m = s
            .with_positions(s.positions().iter().map(|p| geom::mesh::P3::new(p.x * f, p.y, p.z / f)).collect())
            .unwrap();
        let (_, a) = json_call(&t, "POST", "/v1/meshes", Body::from(geom::io::write(&m, Format::Off))).await;
        ids.push(a["id"].clone());
    }
    // Partition points: four vertices spread over the sphere; one feature point.
    let qspec = json!({"method": "quad", "anchors": [[0, 0, 0], [1, 1, 1], [2, 2, 2], [3, 3, 3], [40, 40, 40]],
        "options": {"level": 3, "image_level": 2, "metric_samples": 2000, "morph": {"frames": 2}}});
    let body = json!({"meshes": ids, "spec": qspec}).to_string();
    let req = Request::post("/v1/jobs").header("content-type", "application/json").body(Body::from(body)).unwrap();
    let (st, _, job) = call(&t, req).await;
    assert_eq!(st, StatusCode::ACCEPTED, "{}", String::from_utf8_lossy(&job));
    let job: Value = serde_json::from_slice(&job).unwrap();
    assert_eq!(job["method"], "quad");
    assert_eq!(job["meshes"], json!(ids), "one job shape: the meshes in the spec's order");
    let id = job["id"].as_str().unwrap().to_string();
    let (_tx, rx) = tokio::sync::watch::channel(false);
    assert_eq!(t.worker.run_once(&rx).await.unwrap(), Ran::Ran { job: id.clone(), outcome: "succeeded".into() });
    let (_, done) = json_call(&t, "GET", &format!("/v1/jobs/{id}"), Body::empty()).await;
    assert_eq!(done["result"]["models"], 3, "{done}");
    assert_eq!(done["result"]["feature_points"], 1, "{done}");
    assert!(done["result"]["feature_uv_error"].as_f64().unwrap() <= 1e-9, "{done}");
    let (_, list) = json_call(&t, "GET", &format!("/v1/jobs/{id}/artifacts"), Body::empty()).await;
    let names: Vec<&str> = list["artifacts"].as_array().unwrap().iter().filter_map(|a| a["name"].as_str()).collect();
    for n in ["remesh_0.obj", "remesh_2.obj", "param_1.obj", "morph.glb", "geometry_2_patch1.png", "metrics.json"] {
        assert!(names.contains(&n), "{n} missing from {names:?}");
    }
    // The same remesh faces for every model.
    let mut faces = Vec::new();
    for k in 0..3 {
        let req = Request::get(format!("/v1/jobs/{id}/artifacts/remesh_{k}.obj")).body(Body::empty()).unwrap();
        let (st, _, bytes) = call(&t, req).await;
        assert_eq!(st, StatusCode::OK);
        faces.push(geom::io::read(&bytes, &Default::default()).unwrap().mesh.faces().to_vec());
    }
    assert!(faces[0] == faces[1] && faces[1] == faces[2]);
    // A pair-form quad job with a torus: refused before queueing, naming the genus.
    let tor = geom::mesh::shapes::torus(24, 12, 1.0, 0.3);
    let (_, b) = json_call(&t, "POST", "/v1/meshes", Body::from(geom::io::write(&tor, Format::Off))).await;
    let body = json!({"source": ids[0], "target": b["id"], "spec": {"method": "quad", "anchors": [[0, 0], [1, 1], [2, 2], [3, 3]]}});
    let req = Request::post("/v1/jobs")
        .header("content-type", "application/json")
        .body(Body::from(body.to_string()))
        .unwrap();
    let (st, _, e) = call(&t, req).await;
    assert_eq!(st.as_u16(), 422);
    let e: Value = serde_json::from_slice(&e).unwrap();
    assert_eq!(e["code"], "topology_mismatch", "{e}");
    // A voronoi job over three meshes is a bad request.
    let body = json!({"meshes": ids, "spec": spec()});
    let req = Request::post("/v1/jobs")
        .header("content-type", "application/json")
        .body(Body::from(body.to_string()))
        .unwrap();
    let (st, _, e) = call(&t, req).await;
    assert!(st.is_client_error(), "{st} {}", String::from_utf8_lossy(&e));
}

/// Options out of their range (the spec bombs that once took the server down), unknown fields
/// at any depth and jobs over the memory budget are refused at submission, naming the field.
#[tokio::test]
async fn spec_bombs_nested_unknown_fields_and_budget_are_refused_at_submission() {
    let mut t = setup().await;
    t.state.service.limits.max_json_bytes = 64 << 10;
    let (s, tg) = sphere_pair();
    let (_, a) = json_call(&t, "POST", "/v1/meshes", Body::from(s)).await;
    let (_, b) = json_call(&t, "POST", "/v1/meshes", Body::from(tg)).await;
    let submit = |spec: Value| {
        let body = json!({"source": a["id"], "target": b["id"], "spec": spec}).to_string();
        Request::post("/v1/jobs").header("content-type", "application/json").body(Body::from(body)).unwrap()
    };
    let with = |options: Value| {
        let mut s = spec();
        s["options"] = options;
        s
    };
    let cases = [
        (
            json!({"layout": {"edge_nodes": {"min_nodes": 1_000_000_000u64}}}),
            422,
            "option_out_of_range",
            "layout.edge_nodes.min_nodes",
        ),
        (json!({"metric_samples": 1_000_000_000_000u64}), 422, "option_out_of_range", "metric_samples"),
        (json!({"smoothing": {"iterations": 1u64 << 40}}), 422, "option_out_of_range", "smoothing.iterations"),
        (json!({"smoothing": {"tolerance": 2.0}}), 422, "option_out_of_range", "smoothing.tolerance"),
        (json!({"untangle": {"max_rings": 10}}), 400, "invalid_spec", "untangle"),
        (json!({"basis": [0, 0]}), 400, "invalid_spec", "basis"),
        (json!({"layout": {"bogus": 1}}), 400, "invalid_spec", "bogus"),
        (json!({"smoothing": {"bogus": 1}}), 400, "invalid_spec", "bogus"),
        (json!({"layout": {"flip": {"bogus": 1}}}), 400, "invalid_spec", "bogus"),
        (json!({"global": {"bogus": 1}}), 400, "invalid_spec", "bogus"),
    ];
    for (options, status, code, field) in cases {
        let (st, _, body) = call(&t, submit(with(options.clone()))).await;
        let e: Value = serde_json::from_slice(&body).unwrap();
        assert_eq!((st.as_u16(), e["code"].as_str()), (status, Some(code)), "{options}: {e}");
        let msg = e["message"].as_str().unwrap();
        assert!(msg.contains(field), "{options}: {msg}");
        if status == 422 {
            assert!(msg.contains("outside its range ["), "names the range: {msg}");
        }
    }
    // A JSON body over its own limit (an anchor list of 100 kB): 413 before it is parsed.
    let mut big = spec();
    big["anchors"] = json!((0..10_000).map(|i| [i, i]).collect::<Vec<_>>());
    let (st, _, body) = call(&t, submit(big)).await;
    let e: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!((st.as_u16(), e["code"].as_str()), (413, Some("payload_too_large")), "{e}");
    // A budget smaller than the job's estimate: 422 over_budget, before anything is queued.
    let mut small = setup().await;
    small.state.service.limits.job_memory_bytes = 1 << 20;
    let (_, a2) = json_call(&small, "POST", "/v1/meshes", Body::from(sphere_pair().0)).await;
    let body = json!({"source": a2["id"], "target": a2["id"], "spec": spec()}).to_string();
    let req = Request::post("/v1/jobs").header("content-type", "application/json").body(Body::from(body)).unwrap();
    let (st, _, body) = call(&small, req).await;
    let e: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!((st.as_u16(), e["code"].as_str()), (422, Some("over_budget")), "{e}");
    let (_, list) = json_call(&small, "GET", "/v1/jobs", Body::empty()).await;
    assert_eq!(list["jobs"].as_array().map(Vec::len), Some(0), "{list}");
}

/// Concurrent uploads share one memory budget: while others hold it, an upload is refused
/// with 429 and Retry-After before its body is read; once released, it goes through.
#[tokio::test]
async fn uploads_over_the_shared_memory_budget_get_429() {
    let mut t = setup().await;
    t.state.service.limits.uploads = surfmap_server::service::UploadBudget::new(4 << 20);
    let (s, _) = sphere_pair();
    let held = t.state.service.limits.uploads.reserve(1 << 20).unwrap();
    let req = Request::post("/v1/meshes").header("content-length", s.len()).body(Body::from(s.clone())).unwrap();
    let (st, headers, body) = call(&t, req).await;
    let e: Value = serde_json::from_slice(&body).unwrap();
    assert_eq!((st, e["code"].as_str()), (StatusCode::TOO_MANY_REQUESTS, Some("uploads_busy")), "{e}");
    assert_eq!(headers["retry-after"], "1");
    drop(held);
    let req = Request::post("/v1/meshes").header("content-length", s.len()).body(Body::from(s)).unwrap();
    assert_eq!(call(&t, req).await.0, StatusCode::CREATED);
}

/// glTF uploads: a GLB split at seams is summarized with its own vertex count (the range of the
/// ids a job names on it); a file that requires Draco is 422 `unsupported_extension`.
#[tokio::test]
async fn gltf_uploads_are_summarized_or_refused_by_extension() {
    let t = setup().await;
    // Two triangles of a tetrahedron's four split like a seam: 6 input vertices, 4 welded.
    let tet = geom::mesh::shapes::tetrahedron();
    let p: Vec<geom::mesh::P3> = tet.positions().to_vec();
    let tris: Vec<[u32; 3]> = (0..4u32).map(|f| [3 * f, 3 * f + 1, 3 * f + 2]).collect();
    let split: Vec<geom::mesh::P3> = tet.faces().iter().flat_map(|f| f.map(|v| p[v.idx()])).collect();
    let attrs = geom::mesh::Attributes::default();
    let glb = geom::io::write_glb_mesh(&geom::io::GlbMesh {
        positions: &split,
        triangles: &tris,
        attributes: &attrs,
        targets: &[],
    });
    let (st, m) = json_call(&t, "POST", "/v1/meshes", Body::from(glb.clone())).await;
    assert_eq!(st, StatusCode::CREATED, "{m}");
    assert_eq!((m["format"].as_str(), m["summary"]["vertices"].as_u64()), (Some("gltf"), Some(4)), "{m}");
    assert_eq!(m["summary"]["input_vertices"], 12, "{m}");
    // The same document requiring Draco.
    let n = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    let mut doc: Value = serde_json::from_slice(&glb[20..20 + n]).unwrap();
    doc["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let mut js = serde_json::to_vec(&doc).unwrap();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    let bin = &glb[20 + n..];
    let mut out = b"glTF".to_vec();
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&((12 + 8 + js.len() + bin.len()) as u32).to_le_bytes());
    out.extend_from_slice(&(js.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&js);
    out.extend_from_slice(bin);
    let (st, e) = json_call(&t, "POST", "/v1/meshes", Body::from(out)).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("unsupported_extension")), "{e}");
    assert!(e["message"].as_str().unwrap().contains("KHR_draco_mesh_compression"), "{e}");
}

/// An open pair through the queue: a sphere with a hole onto a stretched copy, the loop named
/// by a `boundaries` row; the job succeeds with the loop report, and a `boundaries` row past the
/// meshes' vertices is refused at submission.
#[tokio::test]
async fn open_meshes_map_loop_onto_loop_through_the_queue() {
    let t = setup().await;
    let open = geom::mesh::shapes::icosphere_with_holes(3, &[0]);
    let stretched = open
        .with_positions(open.positions().iter().map(|p| geom::mesh::P3::new(1.4 * p.x, p.y, 0.9 * p.z)).collect())
        .unwrap();
    let first = open.tail(geom::topology::boundary_loops(&open)[0][0]).0;
    let (_, a) = json_call(&t, "POST", "/v1/meshes", Body::from(geom::io::write(&open, Format::Off))).await;
    let (_, b) = json_call(&t, "POST", "/v1/meshes", Body::from(geom::io::write(&stretched, Format::Off))).await;
    assert_eq!(a["summary"]["boundary_loops"], 1, "{a}");
    let submit = |boundaries: Value| {
        let spec = json!({"method": "voronoi", "anchors": [[20, 20], [61, 61], [100, 100], [222, 222]], "boundaries": boundaries});
        let body = json!({"source": a["id"], "target": b["id"], "spec": spec}).to_string();
        json_call(&t, "POST", "/v1/jobs", Body::from(body))
    };
    let (st, e) = submit(json!([[100000, 0]])).await;
    assert_eq!((st, e["code"].as_str()), (StatusCode::UNPROCESSABLE_ENTITY, Some("invalid_anchors")), "{e}");
    let (st, job) = submit(json!([[first, first]])).await;
    assert_eq!(st, StatusCode::ACCEPTED, "{job}");
    let id = job["id"].as_str().unwrap().to_string();
    let (_tx, rx) = tokio::sync::watch::channel(false);
    assert_eq!(t.worker.run_once(&rx).await.unwrap(), Ran::Ran { job: id.clone(), outcome: "succeeded".into() });
    let (_, done) = json_call(&t, "GET", &format!("/v1/jobs/{id}"), Body::empty()).await;
    let r = &done["result"];
    assert_eq!(r["source_to_target"]["flipped_faces"], 0, "{r}");
    assert_eq!(r["target_to_source"]["flipped_faces"], 0, "{r}");
    assert_eq!(r["boundaries"][0]["paired_by"], "boundaries", "{r}");
    assert_eq!(r["boundaries"][0]["off_loop"], json!([0, 0]), "{r}");
}
