//! Running one claimed job: the heartbeat loop around the blocking pipeline call, and the
//! mapping of its outcome onto the store (fenced completion, release on shutdown).

use crate::Shutdown;
use crate::config::WorkerConfig;
use crate::progress::Shared;
use geom::io::ReadOptions;
use geom::mesh::MeshLimits;
use geom::pipeline::Job;
use std::time::Instant;
use surfmap_store::{ArtifactRef, BlobStore, Claim, Heartbeat, Outcome, Store, StoreError};
use tracing::{info, warn};

/// What one [`Worker::run_once`] did.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Ran {
    /// Ran a job; `outcome` is the state written (or `lease_lost` / `released`).
    Ran { job: String, outcome: String },
    /// The queue was empty.
    Idle,
}

/// A worker bound to a store and a blob directory.
#[derive(Debug, Clone)]
pub struct Worker {
    pub store: Store,
    pub blobs: BlobStore,
    pub config: WorkerConfig,
}

/// Why the pipeline was asked to stop.
#[derive(Debug, Default)]
struct Stops {
    lost: bool,
    user: bool,
    timed_out: bool,
    shutdown: bool,
}

impl Worker {
    /// Loops until `shutdown`: sweep expired leases, claim, run; wait `poll` when idle.
    pub async fn run(&self, mut shutdown: Shutdown) {
        info!(worker = %self.config.id, "worker started");
        while !*shutdown.borrow() {
            match self.run_once(&shutdown).await {
                Ok(Ran::Ran { .. }) => continue,
                Ok(Ran::Idle) => {}
                Err(e) => warn!(worker = %self.config.id, "store unavailable: {e}"),
            }
            tokio::select! {
                _ = tokio::time::sleep(self.config.poll) => {}
                _ = shutdown.changed() => {}
            }
        }
        info!(worker = %self.config.id, "worker stopped");
    }

    /// Sweeps expired leases, then claims and runs at most one job.
    ///
    /// # Errors
    /// Store failures (the job, if any, stays leased and will be retried after expiry).
    pub async fn run_once(&self, shutdown: &Shutdown) -> Result<Ran, StoreError> {
        let sweep = self.store.requeue_expired().await?;
        if sweep != Default::default() {
            info!(?sweep, "expired leases swept");
        }
        let lease_ms = i64::try_from(self.config.lease.as_millis()).unwrap_or(i64::MAX);
        let Some(claim) = self.store.claim(&self.config.id, lease_ms).await? else { return Ok(Ran::Idle) };
        let job = claim.job.id.clone();
        info!(worker = %self.config.id, %job, attempt = claim.job.attempts, fence = claim.fence, "claimed");
        let outcome = self.execute(claim, shutdown.clone()).await?;
        Ok(Ran::Ran { job, outcome })
    }

    async fn execute(&self, claim: Claim, mut shutdown: Shutdown) -> Result<String, StoreError> {
        let Claim { job, fence } = claim;
        let started = Instant::now();
        let lease_ms = i64::try_from(self.config.lease.as_millis()).unwrap_or(i64::MAX);
        let inputs = match self.load(&job.spec, &job.source, &job.target).await {
            Ok(x) => x,
            Err(e) => return self.finish(&job.id, fence, &job.method, started, Err(e), &Stops::default()).await,
        };
        let shared = Shared::default();
        let mut progress = shared.clone();
        let (spec, meshes) = inputs;
        let mut handle = tokio::task::spawn_blocking(move || geom::pipeline::run_job(&spec, &meshes, &mut progress));
        let deadline = tokio::time::Instant::now() + self.config.time_limit;
        let mut grace_end: Option<tokio::time::Instant> = None;
        let mut stops = Stops::default();
        let mut tick = tokio::time::interval(self.config.heartbeat());
        tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        let result = loop {
            tokio::select! {
                r = &mut handle => break r,
                _ = tick.tick() => {
                    let (stage, frac) = shared.snapshot();
                    let stage = if stage.is_empty() { "loading".to_string() } else { stage };
                    match self.store.heartbeat(&job.id, fence, &stage, frac, lease_ms).await {
                        Ok(Heartbeat::Extended { cancel }) if cancel && !stops.user => { stops.user = true; shared.cancel(); }
                        Ok(Heartbeat::Lost) if !stops.lost => {
                            warn!(job = %job.id, fence, "lease lost to another worker; stopping and discarding this run");
                            stops.lost = true;
                            shared.cancel();
                        }
                        Ok(_) => {}
                        Err(e) => warn!(job = %job.id, "heartbeat failed: {e}"),
                    }
                    let now = tokio::time::Instant::now();
                    if now >= deadline && !stops.timed_out { stops.timed_out = true; shared.cancel(); }
                    if grace_end.is_some_and(|g| now >= g) { shared.cancel(); }
                }
                _ = shutdown.changed(), if grace_end.is_none() => {
                    if *shutdown.borrow() {
                        info!(job = %job.id, "shutdown: finishing the current job within the grace period");
                        stops.shutdown = true;
                        grace_end = Some(tokio::time::Instant::now() + self.config.shutdown_grace);
                    }
                }
            }
        };
        let result = match result {
            Ok(r) => r,
            Err(e) => Err(geom::Error::Internal(format!("pipeline thread panicked: {e}"))),
        };
        let result = match result {
            Ok((report, artifacts)) => self.store_artifacts(report, artifacts).await,
            Err(e) => Err(e),
        };
        self.finish(&job.id, fence, &job.method, started, result, &stops).await
    }

    /// Spec and meshes of a job, read under the vertex cap. A pair job stores its spec and its
    /// source and target; an N-mesh job stores `{"meshes": [id, ...], "spec": {...}}`.
    async fn load(&self, spec: &str, source: &str, target: &str) -> Result<(Job, Vec<geom::Mesh>), geom::Error> {
        let stored: serde_json::Value = serde_json::from_str(spec).unwrap_or_default();
        let ids = stored
            .get("meshes")
            .and_then(|m| m.as_array())
            .map(|a| a.iter().filter_map(|x| x.as_str().map(str::to_string)).collect::<Vec<String>>());
        let (job, keys) = match (ids, stored.get("spec")) {
            (Some(ids), Some(inner)) => {
                let bytes = serde_json::to_vec(inner).map_err(|e| geom::Error::Internal(e.to_string()))?;
                (Job::from_json(&bytes)?, ids)
            }
            _ => (Job::from_json(spec.as_bytes())?, vec![source.to_string(), target.to_string()]),
        };
        let limits = MeshLimits { max_vertices: self.config.max_vertices, max_faces: 2 * self.config.max_vertices + 8 };
        let read = move |bytes: Vec<u8>| geom::io::read(&bytes, &ReadOptions { limits, hint: None }).map(|r| r.mesh);
        let mut pending = Vec::with_capacity(keys.len());
        for key in &keys {
            let bytes = self
                .blobs
                .get(key)
                .await
                .map_err(|e| geom::Error::Internal(format!("blob {key}: {e}")))?
                .ok_or_else(|| geom::Error::Internal(format!("mesh blob {key} is missing from the data dir")))?;
            pending.push(tokio::task::spawn_blocking(move || read(bytes)));
        }
        let mut meshes = Vec::with_capacity(pending.len());
        for p in pending {
            meshes.push(p.await.map_err(|e| geom::Error::Internal(e.to_string()))??);
        }
        Ok((job, meshes))
    }

    async fn store_artifacts(
        &self,
        report: geom::pipeline::JobOutput,
        artifacts: Vec<geom::pipeline::Artifact>,
    ) -> Result<(String, Vec<ArtifactRef>), geom::Error> {
        let mut refs = Vec::with_capacity(artifacts.len());
        for a in artifacts {
            let sha256 =
                self.blobs.put(&a.bytes).await.map_err(|e| geom::Error::Internal(format!("artifact store: {e}")))?;
            refs.push(ArtifactRef {
                name: a.name,
                content_type: a.content_type.to_string(),
                sha256,
                size: a.bytes.len() as u64,
            });
        }
        for (stage, ms) in &report.timings_ms {
            metrics::histogram!("surfmap_stage_duration_seconds", "method" => report.method, "stage" => stage.clone())
                .record(ms / 1e3);
        }
        let json = serde_json::to_string(&report.report).map_err(|e| geom::Error::Internal(e.to_string()))?;
        Ok((json, refs))
    }

    async fn finish(
        &self,
        id: &str,
        fence: i64,
        method: &str,
        started: Instant,
        result: Result<(String, Vec<ArtifactRef>), geom::Error>,
        stops: &Stops,
    ) -> Result<String, StoreError> {
        if stops.lost {
            return Ok("lease_lost".into());
        }
        let outcome = match result {
            // A cancellation asked for while the last stage finished still wins.
            _ if stops.user => Outcome::Cancelled,
            Ok((result, artifacts)) => Outcome::Succeeded { result, artifacts },
            Err(geom::Error::Cancelled) if stops.timed_out => Outcome::Failed {
                code: "time_limit".into(),
                message: format!("the job ran longer than its limit of {} s", self.config.time_limit.as_secs()),
            },
            Err(geom::Error::Cancelled) if stops.shutdown => {
                let released = self.store.release(id, fence).await?;
                info!(job = %id, released, "shutdown: lease released, the job goes back to the queue");
                return Ok("released".into());
            }
            Err(e) => {
                if matches!(e, geom::Error::Internal(_)) {
                    tracing::error!(job = %id, "internal error: {e}");
                }
                Outcome::Failed { code: e.code().to_string(), message: e.to_string() }
            }
        };
        let state = match &outcome {
            Outcome::Succeeded { .. } => "succeeded",
            Outcome::Failed { code, .. } => {
                metrics::counter!("surfmap_jobs_failed_total", "code" => code.clone()).increment(1);
                "failed"
            }
            Outcome::Cancelled => "cancelled",
        };
        metrics::histogram!("surfmap_job_duration_seconds", "method" => method.to_string(), "outcome" => state)
            .record(started.elapsed().as_secs_f64());
        if self.store.complete(id, fence, &outcome).await? {
            info!(job = %id, state, secs = started.elapsed().as_secs_f64(), "completed");
            Ok(state.into())
        } else {
            warn!(job = %id, fence, "completion rejected by the fence: another worker owns this job now; result discarded");
            Ok("fence_rejected".into())
        }
    }
}
