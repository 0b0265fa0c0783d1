//! The job store: jobs, meshes and the lease-based queue on SQLite (embedded default) or
//! PostgreSQL (many workers on many machines), plus content-addressed blobs. This crate is the
//! only place in surfmap that writes SQL.
//!
//! The queue protocol (see ARCHITECTURE.md for the state table):
//! - [`Store::claim`] moves the oldest queued job to `running`, sets the lease owner and expiry,
//!   bumps the fencing token and counts the attempt, in one statement.
//! - [`Store::heartbeat`] records stage and progress and extends the lease, fenced by the token.
//! - [`Store::complete`] writes the outcome only if the token still matches (a worker whose
//!   lease expired and was re-claimed gets `false` and must discard its result).
//! - [`Store::requeue_expired`] puts jobs with expired leases back in the queue, or fails them
//!   once their attempts are used up.

mod blobs;
mod model;
mod queries;
pub mod testing;

pub use blobs::BlobStore;
pub use model::{
    ArtifactRef, Claim, Heartbeat, JobFilter, JobRecord, JobState, MeshRecord, NewJob, Outcome, Sweep, now_ms,
};
pub use queries::Store;

/// Store failures.
#[derive(Debug, thiserror::Error)]
pub enum StoreError {
    #[error("database error: {0}")]
    Database(#[from] sqlx::Error),
    #[error("migration failed: {0}")]
    Migrate(#[from] sqlx::migrate::MigrateError),
    #[error("unsupported database URL {0:?} (use sqlite://PATH or postgres://...)")]
    Url(String),
    #[error("idempotency key reused with a different request")]
    IdempotencyConflict,
    #[error("blob store: {0}")]
    Io(#[from] std::io::Error),
    #[error("corrupt row: {0}")]
    Corrupt(String),
}

/// Result alias.
pub type Result<T, E = StoreError> = std::result::Result<T, E>;
