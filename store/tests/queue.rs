//! The queue protocol on both dialects: claim exclusivity, fencing, expiry and retry rules,
//! idempotency, cancellation, release, paging and owner isolation. Every test runs on a fresh
//! SQLite file and, when `SURFMAP_TEST_POSTGRES_URL` is set, on a fresh PostgreSQL database.

use std::collections::HashSet;
use surfmap_store::{Heartbeat, JobFilter, JobState, MeshRecord, NewJob, Outcome, Store, StoreError, testing};

async fn stores() -> Vec<(Store, Option<tempfile::TempDir>)> {
    let dir = tempfile::tempdir().unwrap();
    let url = format!("sqlite://{}", dir.path().join("t.db").display());
    let mut v = vec![(Store::connect(&url).await.unwrap(), Some(dir))];
    if let Some(base) = testing::postgres_base_url() {
        let url = testing::fresh_postgres_database(&base).await.unwrap();
        v.push((Store::connect(&url).await.unwrap(), None));
    }
    v
}

fn job(key: Option<&str>, spec: &str) -> NewJob {
    NewJob {
        owner: "alice".into(),
        idempotency_key: key.map(str::to_string),
        method: "voronoi".into(),
        spec: spec.into(),
        meshes: vec!["s".repeat(64), "t".repeat(64)],
        max_attempts: 2,
    }
}

#[tokio::test]
async fn concurrent_claims_take_each_job_once() {
    for (store, _dir) in stores().await {
        for i in 0..24 {
            store.insert_job(&job(None, &format!("{{\"i\":{i}}}"))).await.unwrap();
        }
        let mut tasks = Vec::new();
        for w in 0..4 {
            let s = store.clone();
            tasks.push(tokio::spawn(async move {
                let mut got = Vec::new();
                while let Some(c) = s.claim(&format!("w{w}"), 60_000).await.unwrap() {
                    got.push(c.job.id);
                }
                got
            }));
        }
        let mut all = Vec::new();
        for t in tasks {
            all.extend(t.await.unwrap());
        }
        let unique: HashSet<_> = all.iter().collect();
        assert_eq!(all.len(), 24, "{}", store.dialect());
        assert_eq!(unique.len(), 24, "{}", store.dialect());
        let counts = store.count_by_state().await.unwrap();
        assert!(counts.contains(&(JobState::Running, 24)), "{counts:?}");
    }
}

#[tokio::test]
async fn a_stale_fence_cannot_write() {
    for (store, _dir) in stores().await {
        let (j, created) = store.insert_job(&job(None, "{}")).await.unwrap();
        assert!(created);
        let c1 = store.claim("w1", 1).await.unwrap().unwrap();
        assert_eq!((c1.job.attempts, c1.job.state), (1, JobState::Running));
        tokio::time::sleep(std::time::Duration::from_millis(10)).await;
        let sweep = store.requeue_expired().await.unwrap();
        assert_eq!(sweep.requeued, 1);
        let c2 = store.claim("w2", 60_000).await.unwrap().unwrap();
        assert_eq!(c2.job.id, j.id);
        assert_eq!(c2.job.attempts, 2);
        assert!(c2.fence > c1.fence);
        // The first worker wakes up: its heartbeat and its completion are refused.
        assert_eq!(store.heartbeat(&j.id, c1.fence, "late", 0.9, 60_000).await.unwrap(), Heartbeat::Lost);
        let late = Outcome::Succeeded { result: "{\"by\":\"w1\"}".into(), artifacts: vec![] };
        assert!(!store.complete(&j.id, c1.fence, &late).await.unwrap());
        assert_eq!(
            store.heartbeat(&j.id, c2.fence, "compose", 0.5, 60_000).await.unwrap(),
            Heartbeat::Extended { cancel: false }
        );
        let ok = Outcome::Succeeded { result: "{\"by\":\"w2\"}".into(), artifacts: vec![] };
        assert!(store.complete(&j.id, c2.fence, &ok).await.unwrap());
        assert!(!store.complete(&j.id, c2.fence, &late).await.unwrap(), "a job completes once");
        let done = store.get_job("alice", &j.id).await.unwrap().unwrap();
        assert_eq!(done.state, JobState::Succeeded);
        assert_eq!(done.result.as_deref(), Some("{\"by\":\"w2\"}"));
        assert_eq!(done.attempts, 2);
        assert_eq!(done.progress, 1.0);
        assert_eq!(done.lease_owner.as_deref(), Some("w2"), "the finishing worker is kept");
        assert!(done.lease_expires_at.is_none());
    }
}

#[tokio::test]
async fn expired_leases_run_out_of_attempts() {
    for (store, _dir) in stores().await {
        let (j, _) = store.insert_job(&job(None, "{}")).await.unwrap();
        for attempt in 1..=2 {
            let c = store.claim("w", 1).await.unwrap().unwrap();
            assert_eq!(c.job.attempts, attempt);
            tokio::time::sleep(std::time::Duration::from_millis(10)).await;
            let s = store.requeue_expired().await.unwrap();
            assert_eq!((s.requeued, s.failed), if attempt == 1 { (1, 0) } else { (0, 1) });
        }
        let j = store.get_job_any(&j.id).await.unwrap().unwrap();
        assert_eq!(j.state, JobState::Failed);
        assert_eq!(j.error_code.as_deref(), Some("attempts_exhausted"));
        assert!(store.claim("w", 1000).await.unwrap().is_none());
    }
}

#[tokio::test]
async fn failures_are_final_and_release_does_not_count() {
    for (store, _dir) in stores().await {
        let (j, _) = store.insert_job(&job(None, "{}")).await.unwrap();
        let c = store.claim("w", 60_000).await.unwrap().unwrap();
        assert!(store.release(&j.id, c.fence).await.unwrap());
        let r = store.get_job_any(&j.id).await.unwrap().unwrap();
        assert_eq!((r.state, r.attempts), (JobState::Queued, 0));
        let c = store.claim("w", 60_000).await.unwrap().unwrap();
        let failed = Outcome::Failed { code: "topology_mismatch".into(), message: "genus".into() };
        assert!(store.complete(&j.id, c.fence, &failed).await.unwrap());
        assert_eq!(store.requeue_expired().await.unwrap(), Default::default());
        assert!(store.claim("w", 60_000).await.unwrap().is_none(), "a failed job is never retried");
        let r = store.get_job_any(&j.id).await.unwrap().unwrap();
        assert_eq!((r.state, r.attempts, r.error_code.as_deref()), (JobState::Failed, 1, Some("topology_mismatch")));
    }
}

#[tokio::test]
async fn idempotency_keys_dedupe_and_detect_conflicts() {
    for (store, _dir) in stores().await {
        let (a, ca) = store.insert_job(&job(Some("k1"), "{}")).await.unwrap();
        let (b, cb) = store.insert_job(&job(Some("k1"), "{}")).await.unwrap();
        assert!(ca && !cb);
        assert_eq!(a.id, b.id);
        assert!(matches!(store.insert_job(&job(Some("k1"), "{\"x\":1}")).await, Err(StoreError::IdempotencyConflict)));
        let mut other = job(Some("k1"), "{}");
        other.owner = "bob".into();
        let (c, cc) = store.insert_job(&other).await.unwrap();
        assert!(cc && c.id != a.id, "keys are per owner");
    }
}

#[tokio::test]
async fn cancellation_of_queued_and_running_jobs() {
    for (store, _dir) in stores().await {
        let (q, _) = store.insert_job(&job(None, "{\"q\":1}")).await.unwrap();
        let (r, _) = store.insert_job(&job(None, "{\"r\":1}")).await.unwrap();
        let c = store.claim("w", 60_000).await.unwrap().unwrap();
        assert_eq!(c.job.id, q.id, "FIFO");
        let after = store.cancel_job("alice", &r.id).await.unwrap().unwrap();
        assert_eq!(after.state, JobState::Cancelled);
        assert!(store.cancel_job("bob", &q.id).await.unwrap().is_none(), "owners are isolated");
        let running = store.cancel_job("alice", &q.id).await.unwrap().unwrap();
        assert_eq!(running.state, JobState::Running);
        assert!(running.cancel_requested);
        assert_eq!(
            store.heartbeat(&q.id, c.fence, "layout", 0.1, 60_000).await.unwrap(),
            Heartbeat::Extended { cancel: true }
        );
        assert!(store.complete(&q.id, c.fence, &Outcome::Cancelled).await.unwrap());
        assert_eq!(store.get_job_any(&q.id).await.unwrap().unwrap().state, JobState::Cancelled);
    }
}

#[tokio::test]
async fn listing_pages_and_filters() {
    for (store, _dir) in stores().await {
        let mut ids = Vec::new();
        for i in 0..7 {
            ids.push(store.insert_job(&job(None, &format!("{{\"i\":{i}}}"))).await.unwrap().0.id);
        }
        store.claim("w", 60_000).await.unwrap();
        let mut seen = Vec::new();
        let mut f = JobFilter { limit: 3, ..Default::default() };
        loop {
            let page = store.list_jobs("alice", &f).await.unwrap();
            if page.is_empty() {
                break;
            }
            f.before = page.last().map(|j| j.id.clone());
            seen.extend(page.into_iter().map(|j| j.id));
        }
        ids.reverse();
        assert_eq!(seen, ids, "newest first, every job once");
        let running = store
            .list_jobs("alice", &JobFilter { state: Some(JobState::Running), limit: 10, ..Default::default() })
            .await;
        assert_eq!(running.unwrap().len(), 1);
        assert!(store.list_jobs("bob", &JobFilter { limit: 10, ..Default::default() }).await.unwrap().is_empty());
        let m = MeshRecord {
            owner: "alice".into(),
            id: "a".repeat(64),
            format: "off".into(),
            size_bytes: 10,
            summary: "{}".into(),
            created_at: 1,
        };
        store.put_mesh(&m).await.unwrap();
        store.put_mesh(&m).await.unwrap();
        assert_eq!(store.get_mesh("alice", &m.id).await.unwrap(), Some(m.clone()));
        assert_eq!(store.get_mesh("bob", &m.id).await.unwrap(), None);
    }
}
