//! End to end: the real `surfmap-server` and `surfmap-worker` binaries on ephemeral ports,
//! on a temporary SQLite file and, when `SURFMAP_TEST_POSTGRES_URL` is set, on PostgreSQL.
//! Scenarios run one at a time (they start several processes each on a 2-core machine).

mod common;

use common::{Api, Env, SMPL, assert_metrics_agree, evaluate, identity_spec, shared, wait_for};
use futures::StreamExt;
use serde_json::{Value, json};
use std::time::Duration;
use surfmap_proto::v1 as pb;
use surfmap_proto::v1::surfmap_client::SurfmapClient;

static ONE_AT_A_TIME: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());

const ARTIFACTS: [&str; 9] = [
    "source_on_target.obj",
    "target_on_source.obj",
    "source_to_target.csv",
    "target_to_source.csv",
    "layout.json",
    "layout_source.ply",
    "layout_target.ply",
    "morph.glb",
    "metrics.json",
];

async fn upload_pair(api: &Api) -> (String, String) {
    let (s1, a) = api.upload(&shared(SMPL.0)).await;
    let (s2, b) = api.upload(&shared(SMPL.1)).await;
    assert_eq!((s1, s2), (201, 201), "{a} {b}");
    assert_eq!(a["summary"]["vertices"], 6890);
    assert_eq!(a["summary"]["genus"], 0);
    (a["id"].as_str().unwrap().to_string(), b["id"].as_str().unwrap().to_string())
}

/// Reads the SSE stream of a job to its end: the job states it carried.
async fn sse_events(api: &Api, id: &str) -> Vec<Value> {
    let r = api.req(reqwest::Method::GET, &format!("/v1/jobs/{id}/events")).send().await.unwrap();
    assert_eq!(r.status(), 200);
    assert!(r.headers()["content-type"].to_str().unwrap().starts_with("text/event-stream"));
    let mut body = r.bytes_stream();
    let (mut buf, mut events) = (String::new(), Vec::new());
    while let Some(chunk) = tokio::time::timeout(Duration::from_secs(120), body.next()).await.expect("SSE stalled") {
        buf.push_str(&String::from_utf8_lossy(&chunk.unwrap()));
        while let Some(end) = buf.find("\n\n") {
            let block: String = buf.drain(..end + 2).collect();
            if block.lines().any(|l| l == "event: job") {
                let data: String = block.lines().filter_map(|l| l.strip_prefix("data: ")).collect();
                events.push(serde_json::from_str(&data).unwrap());
            }
        }
    }
    events
}

async fn rest_and_grpc(env: &Env) {
    let (mut server, base) = env.server(&["--workers", "0"]);
    let mut worker = env.worker("w1", &["--lease-secs", "5"]);
    let api = Api::new(&base);
    assert_eq!(api.get("/readyz").await.0, 200);
    let (src, tgt) = upload_pair(&api).await;

    // REST: submit, watch over SSE, download, judge with the shared evaluator.
    let spec = identity_spec("voronoi", 20);
    let r =
        api.req(reqwest::Method::POST, "/v1/jobs").json(&json!({"source": src, "target": tgt, "spec": spec})).send();
    let r = r.await.unwrap();
    assert_eq!(r.status(), 202);
    let location = r.headers()["location"].to_str().unwrap().to_string();
    let job: Value = r.json().await.unwrap();
    let id = job["id"].as_str().unwrap().to_string();
    assert_eq!(location, format!("/v1/jobs/{id}"));
    let events = sse_events(&api, &id).await;
    let last = events.last().expect("events");
    assert_eq!(last["state"], "succeeded", "{last}");
    assert!(events.iter().any(|e| e["state"] == "running"), "progress was watched while running");
    let p: Vec<f64> = events.iter().map(|e| e["progress"].as_f64().unwrap()).collect();
    assert!(p.windows(2).all(|w| w[1] >= w[0]), "progress is monotone: {p:?}");
    assert!(events.len() >= 3, "{} events", events.len());
    let (_, list) = api.get(&format!("/v1/jobs/{id}/artifacts")).await;
    let names: Vec<&str> = list["artifacts"].as_array().unwrap().iter().map(|a| a["name"].as_str().unwrap()).collect();
    for n in ARTIFACTS {
        assert!(names.contains(&n), "missing artifact {n}: {names:?}");
    }
    let dir = tempfile::tempdir().unwrap();
    let (st, obj, ct) = api.bytes(&format!("/v1/jobs/{id}/artifacts/source_on_target.obj")).await;
    assert_eq!((st, ct.as_str()), (200, "model/obj"));
    std::fs::write(dir.path().join("sot.obj"), &obj).unwrap();
    let (_, metrics, ct) = api.bytes(&format!("/v1/jobs/{id}/artifacts/metrics.json")).await;
    assert_eq!(ct, "application/json");
    let metrics: Value = serde_json::from_slice(&metrics).unwrap();
    assert_eq!(metrics, last["result"], "the job result is metrics.json");
    let gt = dir.path().join("gt.txt");
    std::fs::write(&gt, (0..6890).map(|i| format!("{i}\n")).collect::<String>()).unwrap();
    let theirs = evaluate(&shared(SMPL.0), &shared(SMPL.1), &dir.path().join("sot.obj"), &spec["anchors"], Some(&gt));
    assert_metrics_agree(&metrics["source_to_target"], &theirs);
    assert_eq!(theirs["flipped_faces"], 0);
    assert!(theirs["anchor_error_max"].as_f64().unwrap() <= 1e-9);
    assert!(theirs["off_surface_max"].as_f64().unwrap() <= 1e-9);

    // gRPC on the same port: upload, submit, WatchJob, artifacts in chunks, health.
    let mut g = SurfmapClient::connect(base.clone()).await.unwrap();
    let channel = tonic::transport::Channel::from_shared(base.clone()).unwrap().connect().await.unwrap();
    let mut health = tonic_health::pb::health_client::HealthClient::new(channel.clone());
    let h = health.check(tonic_health::pb::HealthCheckRequest { service: "surfmap.v1.Surfmap".into() }).await.unwrap();
    assert_eq!(h.into_inner().status, tonic_health::pb::health_check_response::ServingStatus::Serving as i32);
    {
        use tonic_reflection::pb::v1::server_reflection_request::MessageRequest;
        use tonic_reflection::pb::v1::server_reflection_response::MessageResponse;
        let mut refl = tonic_reflection::pb::v1::server_reflection_client::ServerReflectionClient::new(channel.clone());
        let ask = tonic_reflection::pb::v1::ServerReflectionRequest {
            host: String::new(),
            message_request: Some(MessageRequest::ListServices(String::new())),
        };
        let mut answers = refl.server_reflection_info(futures::stream::iter([ask])).await.unwrap().into_inner();
        match answers.next().await.unwrap().unwrap().message_response {
            Some(MessageResponse::ListServicesResponse(l)) => {
                assert!(l.service.iter().any(|s| s.name == "surfmap.v1.Surfmap"), "{l:?}");
                assert!(l.service.iter().any(|s| s.name == "grpc.health.v1.Health"), "{l:?}");
            }
            other => panic!("reflection answered {other:?}"),
        }
        // The older v1alpha protocol too, describing the health service's file.
        use tonic_reflection::pb::v1alpha as alpha;
        let mut refl = alpha::server_reflection_client::ServerReflectionClient::new(channel);
        let ask = alpha::ServerReflectionRequest {
            host: String::new(),
            message_request: Some(alpha::server_reflection_request::MessageRequest::FileContainingSymbol(
                "grpc.health.v1.Health".into(),
            )),
        };
        let mut answers = refl.server_reflection_info(futures::stream::iter([ask])).await.unwrap().into_inner();
        match answers.next().await.unwrap().unwrap().message_response {
            Some(alpha::server_reflection_response::MessageResponse::FileDescriptorResponse(f)) => {
                assert!(!f.file_descriptor_proto.is_empty());
            }
            other => panic!("v1alpha reflection answered {other:?}"),
        }
    }
    let data = std::fs::read(shared(SMPL.0)).unwrap();
    let m = g.upload_mesh(pb::UploadMeshRequest { data, format_hint: String::new() }).await.unwrap().into_inner();
    assert_eq!(m.id, src, "content addressed");
    let spec2 = identity_spec("voronoi", 16);
    let req = pb::SubmitJobRequest {
        source: src.clone(),
        target: tgt.clone(),
        spec_json: spec2.to_string(),
        idempotency_key: "g1".into(),
        meshes: Vec::new(),
    };
    let j = g.submit_job(req.clone()).await.unwrap().into_inner();
    let again = g.submit_job(req).await.unwrap().into_inner();
    assert_eq!(j.id, again.id, "idempotent over gRPC");
    let mut stream = g.watch_job(pb::WatchJobRequest { id: j.id.clone() }).await.unwrap().into_inner();
    let mut seen = Vec::new();
    while let Some(ev) = tokio::time::timeout(Duration::from_secs(120), stream.next()).await.expect("watch stalled") {
        seen.push(ev.unwrap());
    }
    let fin = seen.last().unwrap();
    assert_eq!(fin.state, "succeeded", "{fin:?}");
    assert!(seen.len() >= 2);
    let arts = g.list_artifacts(pb::ListArtifactsRequest { job_id: j.id.clone() }).await.unwrap().into_inner();
    assert_eq!(arts.artifacts.len(), ARTIFACTS.len());
    let art = arts.artifacts.iter().find(|a| a.name == "target_on_source.obj").unwrap();
    let mut chunks = g
        .get_artifact(pb::GetArtifactRequest { job_id: j.id.clone(), name: art.name.clone() })
        .await
        .unwrap()
        .into_inner();
    let (mut bytes, mut n) = (Vec::new(), 0);
    while let Some(c) = chunks.next().await {
        let c = c.unwrap();
        if n == 0 {
            assert_eq!(c.total_size, art.size);
            assert_eq!(c.content_type, "model/obj");
        }
        assert!(c.data.len() <= 64 << 10);
        bytes.extend(c.data);
        n += 1;
    }
    assert!(n > 1, "streamed in chunks");
    assert_eq!(bytes, api.bytes(&format!("/v1/jobs/{}/artifacts/target_on_source.obj", j.id)).await.1);
    let tos = dir.path().join("tos.obj");
    std::fs::write(&tos, &bytes).unwrap();
    let theirs = evaluate(&shared(SMPL.1), &shared(SMPL.0), &tos, &spec2["anchors"], None);
    let ours: Value = serde_json::from_str(&fin.result_json).unwrap();
    assert_metrics_agree(&ours["target_to_source"], &theirs);
    // Compatible outputs: both re-embeddings keep their source's connectivity.
    let sot = geom::io::read_path(&dir.path().join("sot.obj"), &Default::default()).unwrap().mesh;
    let man = geom::io::read_path(&shared(SMPL.0), &Default::default()).unwrap().mesh;
    assert_eq!(sot.faces(), man.faces());

    // Cancel a running job: the pair subdivided once (27.5k vertices each), so the job runs for
    // seconds, well past the worker's one-second heartbeat that carries the cancel request.
    let fine = |name: &str| {
        let m = geom::io::read_path(&shared(name), &Default::default()).unwrap().mesh;
        geom::io::write(&geom::mesh::shapes::subdivide(&m, 1), geom::io::Format::Obj)
    };
    let (_, fs) = api.upload_bytes(fine(SMPL.0)).await;
    let (_, ft) = api.upload_bytes(fine(SMPL.1)).await;
    let (src, tgt) = (fs["id"].as_str().unwrap().to_string(), ft["id"].as_str().unwrap().to_string());
    let (_, c) = api.submit(&src, &tgt, &identity_spec("voronoi", 24)).await;
    let cid = c["id"].as_str().unwrap().to_string();
    let running = wait_for(Duration::from_secs(60), || {
        let api = api.clone();
        let cid = cid.clone();
        async move { (api.job(&cid).await["state"] == "running").then_some(()) }
    });
    assert!(running.await.is_some());
    let (st, _) = {
        let r = api.req(reqwest::Method::POST, &format!("/v1/jobs/{cid}/cancel")).send().await.unwrap();
        (r.status().as_u16(), ())
    };
    assert_eq!(st, 200);
    let done = api.wait_done(&cid, Duration::from_secs(60)).await;
    assert_eq!(done["state"], "cancelled", "{done}");

    // Metrics endpoint, then a clean SIGTERM of both processes.
    let (_, text, _) = api.bytes("/metrics").await;
    let text = String::from_utf8(text).unwrap();
    assert!(text.contains("surfmap_queue_depth"), "{text}");
    assert!(text.contains("surfmap_jobs{state=\"succeeded\"} 2"), "{text}");
    worker.signal("TERM");
    assert!(worker.wait_exit(Duration::from_secs(30)).is_some_and(|s| s.success()), "{}", worker.log_text());
    server.signal("TERM");
    assert!(server.wait_exit(Duration::from_secs(30)).is_some_and(|s| s.success()), "{}", server.log_text());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn rest_and_grpc_end_to_end() {
    let _one = ONE_AT_A_TIME.lock().await;
    for env in Env::all().await {
        rest_and_grpc(&env).await;
    }
}

async fn crash(env: &Env) {
    let (_server, base) = env.server(&["--workers", "0", "--lease-secs", "2"]);
    let api = Api::new(&base);
    let (src, tgt) = upload_pair(&api).await;
    let ports = [common::free_port(), common::free_port()];
    let listen = ports.map(|p| format!("127.0.0.1:{p}"));
    let a = env.worker("a", &["--lease-secs", "2", "--metrics-listen", &listen[0]]);
    let b = env.worker("b", &["--lease-secs", "2", "--metrics-listen", &listen[1]]);
    let (st, job) = api.submit(&src, &tgt, &identity_spec("voronoi", 20)).await;
    assert_eq!(st, 202);
    let id = job["id"].as_str().unwrap().to_string();
    let owner = wait_for(Duration::from_secs(60), || {
        let (api, id) = (api.clone(), id.clone());
        async move {
            let j = api.job(&id).await;
            (j["state"] == "running" && j["stage"] != "claimed")
                .then(|| j["worker"].as_str().unwrap_or_default().to_string())
        }
    })
    .await
    .expect("the job starts");
    let (mut victim, mut survivor) = if owner == "a" { (a, b) } else { (b, a) };
    victim.signal("KILL");
    victim.wait_exit(Duration::from_secs(10)).expect("killed");
    let done = api.wait_done(&id, Duration::from_secs(120)).await;
    assert_eq!(done["state"], "succeeded", "{done}");
    assert_eq!(done["attempts"], 2, "{done}");
    assert_ne!(done["worker"].as_str().unwrap(), owner);
    assert_eq!(done["artifacts"].as_array().unwrap().len(), ARTIFACTS.len());
    let (_, page) = api.get("/v1/jobs").await;
    assert_eq!(page["jobs"].as_array().unwrap().len(), 1, "exactly one job, one result");
    // The survivor's own metrics endpoint has the stage and job durations of the job it ran.
    let port = if owner == "a" { &listen[1] } else { &listen[0] };
    let text = reqwest::get(format!("http://{port}/metrics")).await.unwrap().text().await.unwrap();
    assert!(text.contains("surfmap_stage_duration_seconds_bucket{method=\"voronoi\",stage=\"metrics\""), "{text}");
    assert!(text.contains("surfmap_job_duration_seconds_count{method=\"voronoi\",outcome=\"succeeded\"} 1"), "{text}");
    survivor.signal("TERM");
    assert!(survivor.wait_exit(Duration::from_secs(30)).is_some_and(|s| s.success()));
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn kill_9_mid_run_is_retried_to_one_result() {
    let _one = ONE_AT_A_TIME.lock().await;
    for env in Env::all().await {
        crash(&env).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_stalled_worker_s_late_write_is_rejected_by_the_fence() {
    let _one = ONE_AT_A_TIME.lock().await;
    let env = Env::sqlite();
    let (_server, base) = env.server(&["--workers", "0", "--lease-secs", "2"]);
    let api = Api::new(&base);
    let (src, tgt) = upload_pair(&api).await;
    let mut a = env.worker("a", &["--lease-secs", "2"]);
    let (_, job) = api.submit(&src, &tgt, &identity_spec("voronoi", 20)).await;
    let id = job["id"].as_str().unwrap().to_string();
    let started = wait_for(Duration::from_secs(60), || {
        let (api, id) = (api.clone(), id.clone());
        async move { (api.job(&id).await["state"] == "running").then_some(()) }
    });
    assert!(started.await.is_some());
    stop_outside_a_commit(&a, &env).await;
    let b = env.worker("b", &["--lease-secs", "2"]);
    let done = api
        .poll_done(&id, Duration::from_secs(120))
        .await
        .unwrap_or_else(|| panic!("job {id} did not finish; worker b:\n{}\nworker a:\n{}", b.log_text(), a.log_text()));
    assert_eq!(
        (done["state"].as_str(), done["attempts"].as_i64(), done["worker"].as_str()),
        (Some("succeeded"), Some(2), Some("b"))
    );
    a.signal("CONT");
    let rejected = wait_for(Duration::from_secs(60), || {
        let log = a.log_text();
        async move { (log.contains("lease lost") || log.contains("rejected by the fence")).then_some(()) }
    });
    assert!(rejected.await.is_some(), "worker a never noticed: {}", a.log_text());
    let after = api.job(&id).await;
    assert_eq!(after, done, "the late worker changed nothing");
    a.signal("TERM");
    assert!(a.wait_exit(Duration::from_secs(30)).is_some_and(|s| s.success()));
}

/// Stops `p` at an instant it does not hold the SQLite write lock. A process stopped in the
/// middle of a commit (a heartbeat) keeps that lock until it is continued, and every other
/// writer waits on it; that is SQLite's locking, not the fence this test is about.
async fn stop_outside_a_commit(p: &common::Proc, env: &Env) {
    for _ in 0..100 {
        p.signal("STOP");
        if surfmap_store::testing::sqlite_write_lock_free(&env.database_url).await.expect("open the database") {
            return;
        }
        eprintln!("the worker was stopped inside a commit; continuing it and stopping it again");
        p.signal("CONT");
        tokio::time::sleep(Duration::from_millis(37)).await;
    }
    panic!("the worker held the write lock at every one of 100 tries");
}

async fn restart(env: &Env) {
    let (mut server, base) = env.server(&["--workers", "0"]);
    let api = Api::new(&base);
    let (src, tgt) = upload_pair(&api).await;
    let mut ids = Vec::new();
    for k in [12, 16, 20] {
        let (st, j) = api.submit(&src, &tgt, &identity_spec("voronoi", k)).await;
        assert_eq!(st, 202);
        ids.push(j["id"].as_str().unwrap().to_string());
    }
    server.signal("TERM");
    assert!(server.wait_exit(Duration::from_secs(30)).is_some_and(|s| s.success()));
    let (_server, base) = env.server(&["--workers", "2"]);
    let api = Api::new(&base);
    for id in &ids {
        let j = api.wait_done(id, Duration::from_secs(180)).await;
        assert_eq!((j["state"].as_str(), j["attempts"].as_i64()), (Some("succeeded"), Some(1)), "{j}");
    }
    let (_, page) = api.get("/v1/jobs?limit=2").await;
    assert_eq!(page["jobs"].as_array().unwrap().len(), 2);
    let cursor = page["next_cursor"].as_str().unwrap();
    let (_, rest) = api.get(&format!("/v1/jobs?limit=2&cursor={cursor}")).await;
    assert_eq!(rest["jobs"].as_array().unwrap().len(), 1, "three jobs in all");
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn queued_jobs_survive_a_server_restart() {
    let _one = ONE_AT_A_TIME.lock().await;
    for env in Env::all().await {
        restart(&env).await;
    }
}

async fn quad_over_rest(env: &Env) {
    let (mut server, base) = env.server(&["--workers", "1"]);
    let api = Api::new(&base);
    let (a, b) = upload_pair(&api).await;
    // SMPL man and woman: four partition points and two features (same vertex ids on both).
    let spec = json!({"method": "quad", "anchors": [[0, 0], [6763, 6763], [5905, 5905], [2445, 2445], [1262, 1262], [4716, 4716]],
        "options": {"level": 5, "image_level": 3, "metric_samples": 20000}});
    let r =
        api.req(reqwest::Method::POST, "/v1/jobs").json(&json!({"meshes": [a, b], "spec": spec})).send().await.unwrap();
    assert_eq!(r.status(), 202);
    let job: Value = r.json().await.unwrap();
    let id = job["id"].as_str().unwrap().to_string();
    let done = api.wait_done(&id, Duration::from_secs(120)).await;
    assert_eq!(done["state"], "succeeded", "{done}");
    assert_eq!(done["result"]["models"], 2);
    assert_eq!(done["result"]["feature_uv_error"], 0.0);
    let mut faces = Vec::new();
    for k in 0..2 {
        let (st, bytes, _) = api.bytes(&format!("/v1/jobs/{id}/artifacts/remesh_{k}.obj")).await;
        assert_eq!(st, 200);
        let text = String::from_utf8(bytes).unwrap();
        faces.push(text.lines().filter(|l| l.starts_with("f ")).map(str::to_string).collect::<Vec<_>>());
    }
    assert_eq!(faces[0], faces[1], "identical remesh connectivity");
    assert_eq!(faces[0].len(), 4 * 32 * 32);
    let (st, glb, ct) = api.bytes(&format!("/v1/jobs/{id}/artifacts/morph.glb")).await;
    assert_eq!((st, ct.as_str()), (200, "model/gltf-binary"));
    assert_eq!(&glb[..4], b"glTF");
    server.signal("TERM");
    assert!(server.wait_exit(Duration::from_secs(30)).is_some_and(|s| s.success()), "{}", server.log_text());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn quad_job_over_rest_with_the_real_binaries() {
    let _one = ONE_AT_A_TIME.lock().await;
    for env in Env::all().await {
        quad_over_rest(&env).await;
    }
}
