//! The store's records and the values the queue operations exchange.

use serde::{Deserialize, Serialize};

/// Unix time in milliseconds.
pub fn now_ms() -> i64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| i64::try_from(d.as_millis()).unwrap_or(i64::MAX))
}

/// The life cycle of a job.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum JobState {
    Queued,
    Running,
    Succeeded,
    Failed,
    Cancelled,
}

impl JobState {
    pub const ALL: [JobState; 5] =
        [JobState::Queued, JobState::Running, JobState::Succeeded, JobState::Failed, JobState::Cancelled];

    pub fn as_str(self) -> &'static str {
        match self {
            JobState::Queued => "queued",
            JobState::Running => "running",
            JobState::Succeeded => "succeeded",
            JobState::Failed => "failed",
            JobState::Cancelled => "cancelled",
        }
    }

    pub fn parse(s: &str) -> Option<JobState> {
        JobState::ALL.into_iter().find(|st| st.as_str() == s)
    }

    /// True once the job can no longer change.
    pub fn is_terminal(self) -> bool {
        matches!(self, JobState::Succeeded | JobState::Failed | JobState::Cancelled)
    }
}

/// One stored artifact of a job.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct ArtifactRef {
    pub name: String,
    pub content_type: String,
    pub sha256: String,
    pub size: u64,
}

/// An uploaded mesh: the blob key and its summary.
#[derive(Debug, Clone, PartialEq)]
pub struct MeshRecord {
    pub owner: String,
    pub id: String,
    pub format: String,
    pub size_bytes: i64,
    /// JSON of the `inspect` summary.
    pub summary: String,
    pub created_at: i64,
}

/// A job row.
#[derive(Debug, Clone, PartialEq)]
pub struct JobRecord {
    pub id: String,
    pub owner: String,
    pub idempotency_key: Option<String>,
    pub method: String,
    /// JSON of the typed `JobSpec` (`geom::pipeline::JobSpec::to_json`).
    pub spec: String,
    /// Mesh ids in the spec's order (source, target for a pair job).
    pub meshes: Vec<String>,
    /// The first and the last mesh.
    pub source: String,
    pub target: String,
    pub state: JobState,
    pub stage: String,
    pub progress: f64,
    pub attempts: i64,
    pub max_attempts: i64,
    /// The worker holding (or, once finished, that last held) the lease.
    pub lease_owner: Option<String>,
    pub lease_expires_at: Option<i64>,
    pub fence: i64,
    pub cancel_requested: bool,
    pub error_code: Option<String>,
    pub error_message: Option<String>,
    /// JSON metrics report of a succeeded job.
    pub result: Option<String>,
    pub artifacts: Vec<ArtifactRef>,
    pub created_at: i64,
    pub updated_at: i64,
    pub started_at: Option<i64>,
    pub finished_at: Option<i64>,
}

/// What [`crate::Store::insert_job`] needs.
#[derive(Debug, Clone)]
pub struct NewJob {
    pub owner: String,
    pub idempotency_key: Option<String>,
    pub method: String,
    /// JSON of the typed `JobSpec`.
    pub spec: String,
    /// Mesh ids in the spec's order (source, target for a pair job).
    pub meshes: Vec<String>,
    pub max_attempts: i64,
}

/// A claimed job and the fencing token that every later write must present.
#[derive(Debug, Clone)]
pub struct Claim {
    pub job: JobRecord,
    pub fence: i64,
}

/// The answer to a heartbeat.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Heartbeat {
    /// The lease was extended; `cancel` says whether the client asked to cancel.
    Extended { cancel: bool },
    /// The token no longer matches: another worker owns the job (or it ended). Stop and discard.
    Lost,
}

/// How a worker ends a job.
#[derive(Debug, Clone)]
pub enum Outcome {
    Succeeded { result: String, artifacts: Vec<ArtifactRef> },
    Failed { code: String, message: String },
    Cancelled,
}

/// Filters of `list_jobs`; `before` is the cursor (a job id; newest first).
#[derive(Debug, Clone, Default)]
pub struct JobFilter {
    pub state: Option<JobState>,
    pub method: Option<String>,
    pub before: Option<String>,
    pub limit: i64,
}

/// What one expiry sweep did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Sweep {
    pub requeued: u64,
    pub failed: u64,
    pub cancelled: u64,
}
