//! Worker settings, shared by the `surfmap-worker` binary and the server's in-process workers.

use std::time::Duration;

/// How a worker claims and runs jobs.
#[derive(Debug, Clone)]
pub struct WorkerConfig {
    /// Lease owner name, unique per worker (host, pid and a random suffix by default).
    pub id: String,
    /// Lease length; a heartbeat extends it. A worker silent for this long loses its job.
    pub lease: Duration,
    /// Idle wait between claim attempts.
    pub poll: Duration,
    /// Wall-clock limit per job; over it the job is cancelled and fails with `time_limit`.
    pub time_limit: Duration,
    /// Meshes with more vertices are refused (`too_large`) before they are built.
    pub max_vertices: u64,
    /// On shutdown, how long the current job may still run before its lease is released.
    pub shutdown_grace: Duration,
}

impl WorkerConfig {
    /// A fresh worker id: `host-pid-xxxx`.
    pub fn default_id() -> String {
        let host = std::env::var("HOSTNAME").unwrap_or_else(|_| "worker".into());
        let rnd = uuid::Uuid::new_v4().simple().to_string();
        format!("{host}-{}-{}", std::process::id(), &rnd[..6])
    }

    /// Heartbeat period: a third of the lease, at most one second (progress stays fresh).
    pub fn heartbeat(&self) -> Duration {
        (self.lease / 3).min(Duration::from_secs(1)).max(Duration::from_millis(50))
    }
}

impl Default for WorkerConfig {
    fn default() -> Self {
        Self {
            id: Self::default_id(),
            lease: Duration::from_secs(30),
            poll: Duration::from_millis(500),
            time_limit: Duration::from_secs(1800),
            max_vertices: 2_000_000,
            shutdown_grace: Duration::from_secs(60),
        }
    }
}
