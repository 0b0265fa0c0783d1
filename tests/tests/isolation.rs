//! Jobs run in child processes of the worker: cancel, the time limit and SIGTERM stop a job
//! within a second at any stage, and a job whose process dies (here: over its memory cap)
//! fails alone while the API keeps serving. Real binaries on ephemeral ports, SQLite.

mod common;

use common::{Api, Env, SMPL, identity_spec, shared, wait_for};
use serde_json::Value;
use std::time::{Duration, Instant};

static ONE_AT_A_TIME: tokio::sync::Mutex<()> = tokio::sync::Mutex::const_new(());

/// The SMPL pair subdivided once (27.5k vertices each) with smoothing that never converges
/// early: a job that runs for minutes unless stopped, nearly all of it in the `smooth` stage.
async fn long_job(api: &Api) -> String {
    let fine = |name: &str| {
        let m = geom::io::read_path(&shared(name), &Default::default()).unwrap().mesh;
        geom::io::write(&geom::mesh::shapes::subdivide(&m, 1), geom::io::Format::Obj)
    };
    let (_, s) = api.upload_bytes(fine(SMPL.0)).await;
    let (_, t) = api.upload_bytes(fine(SMPL.1)).await;
    let mut spec = identity_spec("voronoi", 24);
    spec["options"] = serde_json::json!({"smoothing": {"iterations": 10000, "tolerance": 0.0}});
    let (st, j) = api.submit(s["id"].as_str().unwrap(), t["id"].as_str().unwrap(), &spec).await;
    assert_eq!(st, 202, "{j}");
    j["id"].as_str().unwrap().to_string()
}

/// Waits until the job is running in `stage` (any stage when `None`), on its `attempt`-th
/// attempt when given; returns the job as then seen.
async fn wait_stage(api: &Api, id: &str, stage: Option<&str>, attempt: Option<i64>) -> Value {
    let (api, id) = (api.clone(), id.to_string());
    wait_for(Duration::from_secs(300), || {
        let (api, id) = (api.clone(), id.clone());
        async move {
            let j = api.job(&id).await;
            let at = stage.is_none_or(|s| j["stage"] == s) && attempt.is_none_or(|a| j["attempts"] == a);
            (j["state"] == "running" && at).then_some(j)
        }
    })
    .await
    .unwrap_or_else(|| panic!("job {id} never ran in stage {stage:?} (attempt {attempt:?})"))
}

/// Polls every 20 ms until the job is in a terminal state; the time it took.
async fn time_to_end(api: &Api, id: &str, from: Instant) -> (Value, Duration) {
    loop {
        let j = api.job(id).await;
        if matches!(j["state"].as_str(), Some("succeeded" | "failed" | "cancelled")) {
            return (j, from.elapsed());
        }
        assert!(from.elapsed() < Duration::from_secs(60), "job {id} did not end: {j}");
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn cancel_and_time_limit_land_within_a_second_in_the_longest_stage() {
    let _one = ONE_AT_A_TIME.lock().await;
    let env = Env::sqlite();
    let (mut server, base) = env.server(&["--workers", "1", "--time-limit-secs", "600"]);
    let api = Api::new(&base);
    let id = long_job(&api).await;
    wait_stage(&api, &id, Some("smooth"), None).await;
    let asked = Instant::now();
    let r = api.req(reqwest::Method::POST, &format!("/v1/jobs/{id}/cancel")).send().await.unwrap();
    assert_eq!(r.status(), 200);
    let (j, took) = time_to_end(&api, &id, asked).await;
    assert_eq!(j["state"], "cancelled", "{j}");
    assert!(took < Duration::from_secs(1), "cancel took {took:?}");
    server.signal("TERM");
    assert!(server.wait_exit(Duration::from_secs(10)).is_some(), "{}", server.log_text());

    // The time limit, on a fresh server: the job fails with `time_limit` within a second of it.
    let (_server, base) = env.server(&["--workers", "1", "--time-limit-secs", "4"]);
    let api = Api::new(&base);
    let id = long_job(&api).await;
    wait_stage(&api, &id, None, None).await;
    let (j, _) = time_to_end(&api, &id, Instant::now()).await;
    assert_eq!((j["state"].as_str(), j["error"]["code"].as_str()), (Some("failed"), Some("time_limit")), "{j}");
    let ran = j["finished_at_ms"].as_i64().unwrap() - j["started_at_ms"].as_i64().unwrap();
    assert!((4000..5000).contains(&ran), "the 4 s limit ended the job after {ran} ms: {j}\n{}", _server.log_text());
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn sigterm_with_a_two_second_grace_releases_the_job_and_exits() {
    let _one = ONE_AT_A_TIME.lock().await;
    let env = Env::sqlite();
    let (_server, base) = env.server(&["--workers", "0"]);
    let api = Api::new(&base);
    let mut worker = env.worker("w", &["--shutdown-grace-secs", "2"]);
    let id = long_job(&api).await;
    wait_stage(&api, &id, Some("smooth"), None).await;
    let asked = Instant::now();
    worker.signal("TERM");
    let status = worker.wait_exit(Duration::from_secs(10));
    let took = asked.elapsed();
    assert!(status.is_some_and(|s| s.success()), "{}", worker.log_text());
    assert!(took < Duration::from_secs(3), "the worker exited {took:?} after SIGTERM with a 2 s grace");
    let j = api.job(&id).await;
    assert_eq!(j["state"], "queued", "released back to the queue: {j}");
    assert_eq!(j["attempts"], 0, "a released attempt is not counted: {j}");
}

/// A job process that dies (SIGABRT, as an allocation over the cap ends it) is retried within
/// `max_attempts`, then the job fails with `worker_crashed`; the server keeps serving.
#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn a_job_process_that_dies_fails_the_job_not_the_server() {
    let _one = ONE_AT_A_TIME.lock().await;
    let env = Env::sqlite();
    let (mut server, base) = env.server(&["--workers", "1", "--max-attempts", "2"]);
    let api = Api::new(&base);
    let id = long_job(&api).await;
    for attempt in 1..=2 {
        wait_stage(&api, &id, Some("smooth"), Some(attempt)).await;
        let children = std::process::Command::new("pgrep").arg("-P").arg(server.pid().to_string()).output().unwrap();
        let pids = String::from_utf8_lossy(&children.stdout).to_string();
        let pid = pids.split_whitespace().next().unwrap_or_else(|| panic!("no job process under the server"));
        assert!(std::process::Command::new("kill").args(["-ABRT", pid]).status().unwrap().success());
    }
    let done = api.wait_done(&id, Duration::from_secs(60)).await;
    assert_eq!(
        (done["state"].as_str(), done["error"]["code"].as_str()),
        (Some("failed"), Some("worker_crashed")),
        "{done}"
    );
    assert_eq!(done["attempts"], 2, "{done}");
    assert!(server.child.try_wait().unwrap().is_none(), "the server is still running");
    assert_eq!(api.get("/readyz").await.0, 200);
    assert_eq!(api.get("/v1/jobs").await.0, 200);
}

/// The job process caps its own address space: a job that needs more than its budget aborts
/// or fails with `out_of_memory` instead of growing.
#[tokio::test]
async fn the_job_process_aborts_above_its_memory_cap() {
    let _one = ONE_AT_A_TIME.lock().await;
    let dir = tempfile::tempdir().unwrap();
    let spec = identity_spec("voronoi", 24);
    for (i, name) in [SMPL.0, SMPL.1].iter().enumerate() {
        let m = geom::io::read_path(&shared(name), &Default::default()).unwrap().mesh;
        std::fs::write(
            dir.path().join(format!("mesh_{i}")),
            geom::io::write(&geom::mesh::shapes::subdivide(&m, 2), geom::io::Format::Obj),
        )
        .unwrap();
    }
    let job = serde_json::json!({"job": spec, "meshes": 2, "max_vertices": 2_000_000, "memory_bytes": 400u64 << 20});
    std::fs::write(dir.path().join("job.json"), job.to_string()).unwrap();
    // The child exits when its stdin closes, so the test holds the pipe open until it ends.
    let mut child = std::process::Command::new(common::binary("surfmap-worker"))
        .arg("__run-job")
        .arg(dir.path())
        .env("MALLOC_ARENA_MAX", "2")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let _stdin = child.stdin.take();
    let out = child.wait_with_output().unwrap();
    use std::os::unix::process::ExitStatusExt;
    let stderr = String::from_utf8_lossy(&out.stderr);
    let result = std::fs::read_to_string(dir.path().join("result.json")).unwrap_or_default();
    // Either an allocation that cannot report failure aborts the process, or a solver reports
    // it and the job fails with `out_of_memory`.
    if out.status.signal() == Some(6) {
        assert!(stderr.contains("memory allocation"), "{stderr}");
        assert!(result.is_empty());
    } else {
        let r: serde_json::Value =
            serde_json::from_str(&result).unwrap_or_else(|_| panic!("{:?}\n{stderr}", out.status));
        assert_eq!(r["Failed"]["code"], "out_of_memory", "{r}");
        assert!(r["Failed"]["message"].as_str().unwrap().contains("400 MiB"), "{r}");
    }
}
