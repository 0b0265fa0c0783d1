//! Worker settings, shared by the `surfmap-worker` binary and the server's in-process workers.

use std::path::PathBuf;
use std::time::Duration;

/// Where a claimed job's pipeline runs.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Runner {
    /// On a blocking thread of this process: cancellation is cooperative (the pipeline polls
    /// between iterations) and a job that aborts takes the process with it. For tests and
    /// embedding.
    Thread,
    /// In a child process `exe __run-job DIR` ([`crate::child`]): killed at once on cancel,
    /// time limit and shutdown; capped at the job memory budget; a crash fails only the job.
    /// What both binaries use.
    Process { exe: PathBuf },
}

impl Runner {
    /// Child processes of the running binary (which must call [`crate::main_if_child`]).
    ///
    /// # Errors
    /// When the path of the running executable cannot be found.
    pub fn current_exe() -> std::io::Result<Runner> {
        Ok(Runner::Process { exe: std::env::current_exe()? })
    }
}

/// Default memory budget of one job: 8 GiB.
pub const DEFAULT_JOB_MEMORY_BYTES: u64 = 8 << 30;

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
    /// Where jobs run.
    pub runner: Runner,
    /// Address space of a job's child process, in bytes (0: unlimited); a job that needs more
    /// aborts and fails with `worker_crashed`.
    pub job_memory_bytes: u64,
}

impl WorkerConfig {
    /// A fresh worker id: `host-pid-xxxx`.
    pub fn default_id() -> String {
        let host = std::env::var("HOSTNAME").unwrap_or_else(|_| "worker".into());
        let rnd = uuid::Uuid::new_v4().simple().to_string();
        format!("{host}-{}-{}", std::process::id(), &rnd[..6])
    }

    /// Heartbeat period: a third of the lease, at most 400 ms (progress stays fresh and a
    /// cancel requested through the store is seen well within a second).
    pub fn heartbeat(&self) -> Duration {
        (self.lease / 3).min(Duration::from_millis(400)).max(Duration::from_millis(50))
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
            runner: Runner::Thread,
            job_memory_bytes: DEFAULT_JOB_MEMORY_BYTES,
        }
    }
}
