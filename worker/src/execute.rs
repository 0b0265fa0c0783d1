//! Running one claimed job: the heartbeat loop around the blocking pipeline call, and the
//! mapping of its outcome onto the store (fenced completion, release on shutdown).

use crate::Shutdown;
use crate::config::WorkerConfig;
use crate::progress::Shared;
use crate::running::{Finished, RunError, Running};
use geom::pipeline::JobSpec;
use std::time::Instant;
use surfmap_store::{ArtifactRef, BlobStore, Claim, Heartbeat, JobRecord, Outcome, Store, StoreError};
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
        let shared = Shared::default();
        let mut running = match self.load(&job).await {
            Ok((spec, meshes)) => Running::start(&self.config, spec, meshes, &shared).await,
            Err(e) => Err(RunError::Geom(e)),
        };
        let mut stops = Stops::default();
        if let Ok(run) = &mut running {
            self.supervise(run, &shared, &job.id, fence, lease_ms, &mut shutdown, &mut stops).await;
        }
        let stopped = stops.user || stops.lost || stops.timed_out || stops.shutdown;
        let result = match running {
            Ok(run) => match run.collect(stopped).await {
                Ok(done) => self.store_artifacts(&job.method, done).await,
                Err(e) => Err(e),
            },
            Err(e) => Err(e),
        };
        self.finish(&job, fence, started, result, &stops).await
    }

    /// Heartbeats while the run lasts and stops it on cancel, time limit, lost lease or the
    /// end of the shutdown grace, each within a heartbeat period (the deadlines exactly).
    #[allow(clippy::too_many_arguments)]
    async fn supervise(
        &self,
        run: &mut Running,
        shared: &Shared,
        id: &str,
        fence: i64,
        lease_ms: i64,
        shutdown: &mut Shutdown,
        stops: &mut Stops,
    ) {
        let deadline = tokio::time::Instant::now() + self.config.time_limit;
        let far = deadline + std::time::Duration::from_secs(365 * 86_400);
        let mut grace_end = far;
        let mut tick = tokio::time::interval(self.config.heartbeat());
        tick.set_missed_tick_behavior(tokio::time::MissedTickBehavior::Delay);
        loop {
            tokio::select! {
                _ = run.ended() => return,
                _ = tick.tick() => {
                    let (stage, frac) = shared.snapshot();
                    let stage = if stage.is_empty() { "loading".to_string() } else { stage };
                    match self.store.heartbeat(id, fence, &stage, frac, lease_ms).await {
                        Ok(Heartbeat::Extended { cancel }) if cancel && !stops.user => {
                            stops.user = true;
                            run.stop(shared);
                        }
                        Ok(Heartbeat::Lost) if !stops.lost => {
                            warn!(job = %id, fence, "lease lost to another worker; stopping and discarding this run");
                            stops.lost = true;
                            run.stop(shared);
                        }
                        Ok(_) => {}
                        Err(e) => warn!(job = %id, "heartbeat failed: {e}"),
                    }
                }
                _ = tokio::time::sleep_until(deadline), if !stops.timed_out => {
                    stops.timed_out = true;
                    run.stop(shared);
                }
                _ = tokio::time::sleep_until(grace_end), if grace_end < far => {
                    grace_end = far;
                    run.stop(shared);
                }
                _ = shutdown.changed(), if !stops.shutdown => {
                    if *shutdown.borrow() {
                        info!(job = %id, "shutdown: finishing the current job within the grace period");
                        stops.shutdown = true;
                        grace_end = tokio::time::Instant::now() + self.config.shutdown_grace;
                    }
                }
            }
        }
    }

    /// The job's typed spec (stored by the server from the same type) and its meshes' bytes.
    async fn load(&self, job: &JobRecord) -> Result<(JobSpec, Vec<Vec<u8>>), geom::Error> {
        let spec = JobSpec::from_json(job.spec.as_bytes())?;
        let keys = &job.meshes;
        let mut meshes = Vec::with_capacity(keys.len());
        for key in keys {
            let bytes = self
                .blobs
                .get(key)
                .await
                .map_err(|e| geom::Error::Internal(format!("blob {key}: {e}")))?
                .ok_or_else(|| geom::Error::Internal(format!("mesh blob {key} is missing from the data dir")))?;
            meshes.push(bytes);
        }
        Ok((spec, meshes))
    }

    async fn store_artifacts(&self, method: &str, done: Finished) -> Result<(String, Vec<ArtifactRef>), RunError> {
        let internal = |m: String| RunError::Geom(geom::Error::Internal(m));
        let mut refs = Vec::with_capacity(done.artifacts.len());
        for (name, content_type, bytes) in done.artifacts {
            let sha256 = self.blobs.put(&bytes).await.map_err(|e| internal(format!("artifact store: {e}")))?;
            refs.push(ArtifactRef { name, content_type, sha256, size: bytes.len() as u64 });
        }
        for (stage, ms) in &done.timings_ms {
            metrics::histogram!("surfmap_stage_duration_seconds", "method" => method.to_string(), "stage" => stage.clone())
                .record(ms / 1e3);
        }
        let json = serde_json::to_string(&done.report).map_err(|e| internal(e.to_string()))?;
        Ok((json, refs))
    }

    async fn finish(
        &self,
        job: &JobRecord,
        fence: i64,
        started: Instant,
        result: Result<(String, Vec<ArtifactRef>), RunError>,
        stops: &Stops,
    ) -> Result<String, StoreError> {
        let id = job.id.as_str();
        if stops.lost {
            return Ok("lease_lost".into());
        }
        let outcome = match result {
            // A cancellation asked for while the last stage finished still wins.
            _ if stops.user => Outcome::Cancelled,
            Ok((result, artifacts)) => Outcome::Succeeded { result, artifacts },
            Err(_) if stops.timed_out => Outcome::Failed {
                code: "time_limit".into(),
                message: format!("the job ran longer than its limit of {} s", self.config.time_limit.as_secs()),
            },
            Err(_) if stops.shutdown => {
                let released = self.store.release(id, fence).await?;
                info!(job = %id, released, "shutdown: lease released, the job goes back to the queue");
                return Ok("released".into());
            }
            Err(RunError::Crashed(why)) if job.attempts < job.max_attempts => {
                warn!(job = %id, attempt = job.attempts, "{why}; the job goes back to the queue");
                metrics::counter!("surfmap_job_crashes_total").increment(1);
                let requeued = self.store.retry(id, fence).await?;
                return Ok(if requeued { "retried" } else { "fence_rejected" }.into());
            }
            Err(RunError::Crashed(why)) => {
                metrics::counter!("surfmap_job_crashes_total").increment(1);
                Outcome::Failed {
                    code: "worker_crashed".into(),
                    message: format!("{why}, on each of {} attempts", job.attempts),
                }
            }
            Err(RunError::Stopped) | Err(RunError::Geom(geom::Error::Cancelled)) => {
                Outcome::Failed { code: "cancelled".into(), message: "the job was stopped".into() }
            }
            Err(RunError::Geom(e)) => {
                if matches!(e, geom::Error::Internal(_)) {
                    tracing::error!(job = %id, "internal error: {e}");
                }
                Outcome::Failed { code: e.code().to_string(), message: e.to_string() }
            }
            Err(RunError::Failed { code, message, internal }) => {
                if internal {
                    tracing::error!(job = %id, "internal error: {message}");
                }
                Outcome::Failed { code, message }
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
        metrics::histogram!("surfmap_job_duration_seconds", "method" => job.method.clone(), "outcome" => state)
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
