//! The worker drained step by step with `run_once` against a temporary SQLite store: success
//! with artifacts, bad input failed without a retry, the time limit, cancellation, and an
//! empty queue.

use geom::io::Format;
use geom::mesh::shapes;
use std::time::Duration;
use surfmap_store::{BlobStore, JobState, NewJob, Store};
use surfmap_worker::{Ran, Worker, WorkerConfig};

struct Setup {
    _dir: tempfile::TempDir,
    worker: Worker,
    source: String,
    target: String,
}

async fn setup(config: WorkerConfig) -> Setup {
    let dir = tempfile::tempdir().unwrap();
    let store = Store::connect(&format!("sqlite://{}", dir.path().join("t.db").display())).await.unwrap();
    let blobs = BlobStore::open(dir.path()).unwrap();
    let s = shapes::icosphere(3);
    // The target: the same sphere stretched, so vertex i matches vertex i.
    let stretched = s.positions().iter().map(|p| geom::mesh::P3::new(p.x * 1.6, p.y, p.z * 0.7)).collect();
    let t = s.with_positions(stretched).unwrap();
    let source = blobs.put(&geom::io::write(&s, Format::Off)).await.unwrap();
    let target = blobs.put(&geom::io::write(&t, Format::Off)).await.unwrap();
    Setup { _dir: dir, worker: Worker { store, blobs, config }, source, target }
}

fn spec() -> String {
    let anchors: Vec<[u32; 2]> = [0u32, 2, 5, 7, 9, 11].iter().map(|&i| [i, i]).collect();
    serde_json::json!({"method": "voronoi", "anchors": anchors}).to_string()
}

async fn submit(s: &Setup, spec: String) -> String {
    let job = NewJob {
        owner: String::new(),
        idempotency_key: None,
        method: "voronoi".into(),
        spec,
        meshes: vec![s.source.clone(), s.target.clone()],
        max_attempts: 3,
    };
    s.worker.store.insert_job(&job).await.unwrap().0.id
}

fn no_shutdown() -> surfmap_worker::Shutdown {
    let (tx, rx) = tokio::sync::watch::channel(false);
    std::mem::forget(tx);
    rx
}

#[tokio::test]
async fn a_job_runs_to_success_with_every_artifact() {
    let s = setup(WorkerConfig::default()).await;
    let id = submit(&s, spec()).await;
    let ran = s.worker.run_once(&no_shutdown()).await.unwrap();
    assert_eq!(ran, Ran::Ran { job: id.clone(), outcome: "succeeded".into() });
    let j = s.worker.store.get_job_any(&id).await.unwrap().unwrap();
    assert_eq!((j.state, j.attempts, j.progress), (JobState::Succeeded, 1, 1.0));
    assert_eq!(j.artifacts.len(), 9, "voronoi artifacts with morph.glb");
    let report: serde_json::Value = serde_json::from_str(j.result.as_deref().unwrap()).unwrap();
    assert_eq!(report["source_to_target"]["flipped_faces"], 0);
    assert_eq!(report["source_to_target"]["anchor_error_max"], 0.0);
    for a in &j.artifacts {
        let bytes = s.worker.blobs.get(&a.sha256).await.unwrap().unwrap();
        assert_eq!(bytes.len() as u64, a.size, "{}", a.name);
    }
    assert_eq!(s.worker.run_once(&no_shutdown()).await.unwrap(), Ran::Idle);
}

#[tokio::test]
async fn bad_input_fails_once_and_is_not_retried() {
    let s = setup(WorkerConfig { max_vertices: 100, ..WorkerConfig::default() }).await;
    let id = submit(&s, spec()).await;
    let ran = s.worker.run_once(&no_shutdown()).await.unwrap();
    assert_eq!(ran, Ran::Ran { job: id.clone(), outcome: "failed".into() });
    let j = s.worker.store.get_job_any(&id).await.unwrap().unwrap();
    assert_eq!((j.state, j.attempts, j.error_code.as_deref()), (JobState::Failed, 1, Some("too_large")));
    assert!(j.error_message.unwrap().contains("vertices"));
    assert_eq!(s.worker.run_once(&no_shutdown()).await.unwrap(), Ran::Idle, "never retried");
}

#[tokio::test]
async fn over_the_time_limit_a_job_fails_with_time_limit() {
    let s = setup(WorkerConfig { time_limit: Duration::ZERO, ..WorkerConfig::default() }).await;
    let id = submit(&s, spec()).await;
    let ran = s.worker.run_once(&no_shutdown()).await.unwrap();
    assert_eq!(ran, Ran::Ran { job: id.clone(), outcome: "failed".into() });
    let j = s.worker.store.get_job_any(&id).await.unwrap().unwrap();
    assert_eq!(j.error_code.as_deref(), Some("time_limit"));
}

#[tokio::test]
async fn a_cancel_request_stops_the_job() {
    let s = setup(WorkerConfig::default()).await;
    let id = submit(&s, spec()).await;
    // Claim as another worker would, ask for cancellation, then let the lease lapse so this
    // worker picks the job up with the request already standing.
    let c = s.worker.store.claim("other", 1).await.unwrap().unwrap();
    assert!(s.worker.store.cancel_job("", &id).await.unwrap().unwrap().cancel_requested);
    tokio::time::sleep(Duration::from_millis(5)).await;
    let ran = s.worker.run_once(&no_shutdown()).await.unwrap();
    assert_eq!(ran, Ran::Idle, "an expired job with a cancel request is cancelled by the sweep");
    let j = s.worker.store.get_job_any(&id).await.unwrap().unwrap();
    assert_eq!((j.state, c.fence), (JobState::Cancelled, 1));
}

#[tokio::test]
async fn malformed_spec_in_the_store_fails_cleanly() {
    let s = setup(WorkerConfig::default()).await;
    let id = submit(&s, "{\"method\": \"voronoi\"}".into()).await;
    let ran = s.worker.run_once(&no_shutdown()).await.unwrap();
    assert_eq!(ran, Ran::Ran { job: id.clone(), outcome: "failed".into() });
    let j = s.worker.store.get_job_any(&id).await.unwrap().unwrap();
    assert_eq!(j.error_code.as_deref(), Some("invalid_spec"));
}

#[tokio::test]
async fn shutdown_past_the_grace_period_releases_the_lease() {
    let config =
        WorkerConfig { lease: Duration::from_millis(150), shutdown_grace: Duration::ZERO, ..WorkerConfig::default() };
    let mut s = setup(config).await;
    // A larger sphere, so the job is still running when the grace period (zero) ends.
    let big = shapes::icosphere(5);
    s.source = s.worker.blobs.put(&geom::io::write(&big, Format::Off)).await.unwrap();
    s.target = s.source.clone();
    let id = submit(&s, spec()).await;
    let (tx, rx) = tokio::sync::watch::channel(false);
    tx.send(true).unwrap();
    let ran = s.worker.run_once(&rx).await.unwrap();
    assert_eq!(ran, Ran::Ran { job: id.clone(), outcome: "released".into() });
    let j = s.worker.store.get_job_any(&id).await.unwrap().unwrap();
    assert_eq!(
        (j.state, j.attempts, j.stage.as_str()),
        (JobState::Queued, 0, "released"),
        "back in the queue, attempt not counted"
    );
}
