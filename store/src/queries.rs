//! Every SQL statement of surfmap, for both dialects. Statements use `$n` placeholders, which
//! SQLite and PostgreSQL both accept, so one text serves both except where a dialect differs
//! (the Postgres claim adds `FOR UPDATE SKIP LOCKED`).

use crate::model::{Claim, Heartbeat, JobFilter, JobRecord, JobState, MeshRecord, NewJob, Outcome, Sweep, now_ms};
use crate::{Result, StoreError};
use sqlx::Row;
use sqlx::postgres::{PgPool, PgPoolOptions};
use sqlx::sqlite::{SqliteConnectOptions, SqliteJournalMode, SqlitePool, SqlitePoolOptions, SqliteSynchronous};
use std::str::FromStr;
use std::time::Duration;

#[derive(Debug, Clone)]
enum Db {
    Sqlite(SqlitePool),
    Postgres(PgPool),
}

/// A connection pool to the job store. Cheap to clone.
#[derive(Debug, Clone)]
pub struct Store {
    db: Db,
}

/// Runs `$body` with `$pool` bound to whichever pool the store has; the body is type-checked
/// once per dialect.
macro_rules! on {
    ($self:expr, $pool:ident => $body:expr) => {
        match &$self.db {
            Db::Sqlite($pool) => $body,
            Db::Postgres($pool) => $body,
        }
    };
}

macro_rules! job_from_row {
    ($r:expr) => {{
        let r = $r;
        let state: String = r.try_get("state")?;
        let artifacts: Option<String> = r.try_get("artifacts")?;
        JobRecord {
            id: r.try_get("id")?,
            owner: r.try_get("owner")?,
            idempotency_key: r.try_get("idempotency_key")?,
            method: r.try_get("method")?,
            spec: r.try_get("spec")?,
            meshes: {
                let m: String = r.try_get("meshes")?;
                serde_json::from_str(&m).map_err(|e| StoreError::Corrupt(format!("meshes: {e}")))?
            },
            source: r.try_get("source")?,
            target: r.try_get("target")?,
            state: JobState::parse(&state).ok_or_else(|| StoreError::Corrupt(format!("job state {state:?}")))?,
            stage: r.try_get("stage")?,
            progress: r.try_get("progress")?,
            attempts: r.try_get("attempts")?,
            max_attempts: r.try_get("max_attempts")?,
            lease_owner: r.try_get("lease_owner")?,
            lease_expires_at: r.try_get("lease_expires_at")?,
            fence: r.try_get("fence")?,
            cancel_requested: r.try_get::<i64, _>("cancel_requested")? != 0,
            error_code: r.try_get("error_code")?,
            error_message: r.try_get("error_message")?,
            result: r.try_get("result")?,
            artifacts: match artifacts {
                Some(a) => serde_json::from_str(&a).map_err(|e| StoreError::Corrupt(format!("artifacts: {e}")))?,
                None => Vec::new(),
            },
            created_at: r.try_get("created_at")?,
            updated_at: r.try_get("updated_at")?,
            started_at: r.try_get("started_at")?,
            finished_at: r.try_get("finished_at")?,
        }
    }};
}

const CLAIM_SQLITE: &str = "UPDATE jobs SET state = 'running', lease_owner = $1, lease_expires_at = $2, \
     fence = fence + 1, attempts = attempts + 1, started_at = COALESCE(started_at, $3), updated_at = $3, \
     stage = 'claimed', progress = 0 \
     WHERE id = (SELECT id FROM jobs WHERE state = 'queued' ORDER BY id LIMIT 1) AND state = 'queued' \
     RETURNING *";
const CLAIM_POSTGRES: &str = "UPDATE jobs SET state = 'running', lease_owner = $1, lease_expires_at = $2, \
     fence = fence + 1, attempts = attempts + 1, started_at = COALESCE(started_at, $3), updated_at = $3, \
     stage = 'claimed', progress = 0 \
     WHERE id = (SELECT id FROM jobs WHERE state = 'queued' ORDER BY id LIMIT 1 FOR UPDATE SKIP LOCKED) \
     AND state = 'queued' RETURNING *";

impl Store {
    /// Connects to `sqlite://PATH` (the file is created on first run; WAL) or `postgres://…`, and
    /// applies the migrations of that dialect.
    ///
    /// # Errors
    /// An unsupported URL, a connection failure or a failed migration.
    pub async fn connect(url: &str) -> Result<Store> {
        let db = if url.starts_with("sqlite:") {
            let opts = SqliteConnectOptions::from_str(url)?
                .create_if_missing(true)
                .journal_mode(SqliteJournalMode::Wal)
                .synchronous(SqliteSynchronous::Normal)
                .busy_timeout(Duration::from_secs(30));
            let pool = SqlitePoolOptions::new().max_connections(8).connect_with(opts).await?;
            // Two processes starting on one new file may race on the first migration; the
            // loser sees it applied on the second try.
            if let Err(e) = sqlx::migrate!("../migrations/sqlite").run(&pool).await {
                tracing::warn!("sqlite migration retry after: {e}");
                tokio::time::sleep(Duration::from_millis(300)).await;
                sqlx::migrate!("../migrations/sqlite").run(&pool).await?;
            }
            Db::Sqlite(pool)
        } else if url.starts_with("postgres://") || url.starts_with("postgresql://") {
            let pool = PgPoolOptions::new().max_connections(16).connect(url).await?;
            sqlx::migrate!("../migrations/postgres").run(&pool).await?;
            Db::Postgres(pool)
        } else {
            return Err(StoreError::Url(url.to_string()));
        };
        Ok(Store { db })
    }

    /// The dialect name (`sqlite` or `postgres`).
    pub fn dialect(&self) -> &'static str {
        match self.db {
            Db::Sqlite(_) => "sqlite",
            Db::Postgres(_) => "postgres",
        }
    }

    /// One round trip, for readiness checks.
    ///
    /// # Errors
    /// When the database does not answer.
    pub async fn ping(&self) -> Result<()> {
        on!(self, p => { sqlx::query("SELECT 1").execute(p).await?; });
        Ok(())
    }

    /// Records an uploaded mesh (idempotent per owner and content).
    ///
    /// # Errors
    /// Database failures.
    pub async fn put_mesh(&self, m: &MeshRecord) -> Result<()> {
        on!(self, p => sqlx::query(
            "INSERT INTO meshes (owner, id, format, size_bytes, summary, created_at) VALUES ($1, $2, $3, $4, $5, $6) \
             ON CONFLICT (owner, id) DO NOTHING")
            .bind(&m.owner).bind(&m.id).bind(&m.format).bind(m.size_bytes).bind(&m.summary).bind(m.created_at)
            .execute(p).await?.rows_affected());
        Ok(())
    }

    /// The mesh `id` visible to `owner`.
    ///
    /// # Errors
    /// Database failures.
    pub async fn get_mesh(&self, owner: &str, id: &str) -> Result<Option<MeshRecord>> {
        let row = on!(self, p => {
            let r = sqlx::query("SELECT owner, id, format, size_bytes, summary, created_at FROM meshes WHERE owner = $1 AND id = $2")
                .bind(owner).bind(id).fetch_optional(p).await?;
            match r {
                Some(r) => Some(MeshRecord {
                    owner: r.try_get("owner")?, id: r.try_get("id")?, format: r.try_get("format")?,
                    size_bytes: r.try_get("size_bytes")?, summary: r.try_get("summary")?, created_at: r.try_get("created_at")?,
                }),
                None => None,
            }
        });
        Ok(row)
    }

    /// Queues a job. With an idempotency key already used by `owner`, returns the existing job
    /// and `false` (or [`StoreError::IdempotencyConflict`] when the request differs).
    ///
    /// # Errors
    /// Database failures; `IdempotencyConflict`.
    pub async fn insert_job(&self, j: &NewJob) -> Result<(JobRecord, bool)> {
        let id = uuid::Uuid::now_v7().to_string();
        let now = now_ms();
        let meshes = serde_json::to_string(&j.meshes).map_err(|e| StoreError::Corrupt(e.to_string()))?;
        let hash =
            crate::blobs::sha256_hex(format!("{}\n{meshes}\n{}\n{}", j.method, j.max_attempts, j.spec).as_bytes());
        let (source, target) =
            (j.meshes.first().cloned().unwrap_or_default(), j.meshes.last().cloned().unwrap_or_default());
        let inserted = on!(self, p => sqlx::query(
            "INSERT INTO jobs (id, owner, idempotency_key, request_hash, method, spec, meshes, source, target, state, \
             max_attempts, created_at, updated_at) VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, 'queued', $10, $11, $11) \
             ON CONFLICT (owner, idempotency_key) DO NOTHING")
            .bind(&id).bind(&j.owner).bind(&j.idempotency_key).bind(&hash).bind(&j.method).bind(&j.spec)
            .bind(&meshes).bind(&source).bind(&target).bind(j.max_attempts).bind(now)
            .execute(p).await?.rows_affected());
        if inserted == 1 {
            let job =
                self.get_job_any(&id).await?.ok_or_else(|| StoreError::Corrupt("inserted job vanished".into()))?;
            return Ok((job, true));
        }
        let key = j.idempotency_key.as_deref().unwrap_or_default();
        let found = on!(self, p => {
            match sqlx::query("SELECT *, request_hash FROM jobs WHERE owner = $1 AND idempotency_key = $2")
                .bind(&j.owner).bind(key).fetch_optional(p).await? {
                Some(r) => { let h: String = r.try_get("request_hash")?; Some((job_from_row!(&r), h)) }
                None => None,
            }
        });
        match found {
            Some((job, h)) if h == hash => Ok((job, false)),
            Some(_) => Err(StoreError::IdempotencyConflict),
            None => Err(StoreError::Corrupt("insert ignored without a conflicting row".into())),
        }
    }

    /// The job `id` if `owner` may see it.
    ///
    /// # Errors
    /// Database failures.
    pub async fn get_job(&self, owner: &str, id: &str) -> Result<Option<JobRecord>> {
        Ok(self.get_job_any(id).await?.filter(|j| j.owner == owner))
    }

    /// The job `id`, whoever owns it (workers and the janitor).
    ///
    /// # Errors
    /// Database failures.
    pub async fn get_job_any(&self, id: &str) -> Result<Option<JobRecord>> {
        Ok(on!(self, p => match sqlx::query("SELECT * FROM jobs WHERE id = $1").bind(id).fetch_optional(p).await? {
            Some(r) => Some(job_from_row!(&r)),
            None => None,
        }))
    }

    /// Jobs of `owner`, newest first, filtered; page with `filter.before` = the last id seen.
    ///
    /// # Errors
    /// Database failures.
    pub async fn list_jobs(&self, owner: &str, f: &JobFilter) -> Result<Vec<JobRecord>> {
        let state = f.state.map(JobState::as_str);
        let limit = f.limit.clamp(1, 1000);
        Ok(on!(self, p => {
            let rows = sqlx::query(
                "SELECT * FROM jobs WHERE owner = $1 AND ($2 IS NULL OR state = $2) AND ($3 IS NULL OR method = $3) \
                 AND ($4 IS NULL OR id < $4) ORDER BY id DESC LIMIT $5")
                .bind(owner).bind(state).bind(&f.method).bind(&f.before).bind(limit)
                .fetch_all(p).await?;
            let mut out = Vec::with_capacity(rows.len());
            for r in &rows { out.push(job_from_row!(r)); }
            out
        }))
    }

    /// Cancels a queued job at once, or asks the worker of a running one to stop. Returns the
    /// job as it is afterwards; `None` if `owner` has no such job.
    ///
    /// # Errors
    /// Database failures.
    pub async fn cancel_job(&self, owner: &str, id: &str) -> Result<Option<JobRecord>> {
        let now = now_ms();
        on!(self, p => {
            let n = sqlx::query("UPDATE jobs SET state = 'cancelled', stage = 'cancelled', finished_at = $3, updated_at = $3 \
                                 WHERE id = $1 AND owner = $2 AND state = 'queued'")
                .bind(id).bind(owner).bind(now).execute(p).await?.rows_affected();
            if n == 0 {
                sqlx::query("UPDATE jobs SET cancel_requested = 1, updated_at = $3 WHERE id = $1 AND owner = $2 AND state = 'running'")
                    .bind(id).bind(owner).bind(now).execute(p).await?;
            }
        });
        self.get_job(owner, id).await
    }

    /// Claims the oldest queued job for `worker` with a lease of `lease_ms`.
    ///
    /// # Errors
    /// Database failures.
    pub async fn claim(&self, worker: &str, lease_ms: i64) -> Result<Option<Claim>> {
        let now = now_ms();
        let sql = match self.db {
            Db::Sqlite(_) => CLAIM_SQLITE,
            Db::Postgres(_) => CLAIM_POSTGRES,
        };
        let row = on!(self, p => match sqlx::query(sql).bind(worker).bind(now + lease_ms).bind(now).fetch_optional(p).await? {
            Some(r) => Some(job_from_row!(&r)),
            None => None,
        });
        Ok(row.map(|job| Claim { fence: job.fence, job }))
    }

    /// Records progress and extends the lease, if `fence` still holds the job.
    ///
    /// # Errors
    /// Database failures.
    pub async fn heartbeat(
        &self,
        id: &str,
        fence: i64,
        stage: &str,
        progress: f64,
        lease_ms: i64,
    ) -> Result<Heartbeat> {
        let now = now_ms();
        let cancel: Option<i64> = on!(self, p => {
            match sqlx::query("UPDATE jobs SET stage = $3, progress = $4, lease_expires_at = $5, updated_at = $6 \
                               WHERE id = $1 AND fence = $2 AND state = 'running' RETURNING cancel_requested")
                .bind(id).bind(fence).bind(stage).bind(progress.clamp(0.0, 1.0)).bind(now + lease_ms).bind(now)
                .fetch_optional(p).await? {
                Some(r) => Some(r.try_get("cancel_requested")?),
                None => None,
            }
        });
        Ok(match cancel {
            Some(c) => Heartbeat::Extended { cancel: c != 0 },
            None => Heartbeat::Lost,
        })
    }

    /// Ends a job, fenced: `false` when the token is stale and nothing was written.
    ///
    /// # Errors
    /// Database failures.
    pub async fn complete(&self, id: &str, fence: i64, outcome: &Outcome) -> Result<bool> {
        let now = now_ms();
        let (state, code, message, result, artifacts) = match outcome {
            Outcome::Succeeded { result, artifacts } => (
                JobState::Succeeded,
                None,
                None,
                Some(result.clone()),
                Some(serde_json::to_string(artifacts).map_err(|e| StoreError::Corrupt(e.to_string()))?),
            ),
            Outcome::Failed { code, message } => {
                (JobState::Failed, Some(code.clone()), Some(message.clone()), None, None)
            }
            Outcome::Cancelled => (JobState::Cancelled, None, None, None, None),
        };
        let progress = if state == JobState::Succeeded { 1.0 } else { -1.0 };
        let n = on!(self, p => sqlx::query(
            "UPDATE jobs SET state = $3, stage = $3, progress = CASE WHEN $4 < 0 THEN progress ELSE $4 END, \
             error_code = $5, error_message = $6, result = $7, artifacts = $8, finished_at = $9, updated_at = $9, \
             lease_expires_at = NULL WHERE id = $1 AND fence = $2 AND state = 'running'")
            .bind(id).bind(fence).bind(state.as_str()).bind(progress).bind(code).bind(message).bind(result)
            .bind(artifacts).bind(now).execute(p).await?.rows_affected());
        Ok(n == 1)
    }

    /// Gives a running job back to the queue without counting the attempt (graceful shutdown).
    ///
    /// # Errors
    /// Database failures.
    pub async fn release(&self, id: &str, fence: i64) -> Result<bool> {
        let now = now_ms();
        let n = on!(self, p => sqlx::query(
            "UPDATE jobs SET state = 'queued', stage = 'released', progress = 0, lease_owner = NULL, \
             lease_expires_at = NULL, attempts = attempts - 1, updated_at = $3 \
             WHERE id = $1 AND fence = $2 AND state = 'running'")
            .bind(id).bind(fence).bind(now).execute(p).await?.rows_affected());
        Ok(n == 1)
    }

    /// Gives a running job back to the queue counting the attempt (its process crashed; the
    /// caller fails it instead once `attempts` reaches `max_attempts`).
    ///
    /// # Errors
    /// Database failures.
    pub async fn retry(&self, id: &str, fence: i64) -> Result<bool> {
        let now = now_ms();
        let n = on!(self, p => sqlx::query(
            "UPDATE jobs SET state = 'queued', stage = 'retry', progress = 0, lease_owner = NULL, \
             lease_expires_at = NULL, updated_at = $3 WHERE id = $1 AND fence = $2 AND state = 'running'")
            .bind(id).bind(fence).bind(now).execute(p).await?.rows_affected());
        Ok(n == 1)
    }

    /// Requeues running jobs whose lease expired before now; fails those out of attempts and
    /// cancels those whose cancellation was asked for.
    ///
    /// # Errors
    /// Database failures.
    pub async fn requeue_expired(&self) -> Result<Sweep> {
        let now = now_ms();
        let mut s = Sweep::default();
        on!(self, p => {
            s.cancelled = sqlx::query("UPDATE jobs SET state = 'cancelled', stage = 'cancelled', finished_at = $1, updated_at = $1, \
                 lease_owner = NULL, lease_expires_at = NULL WHERE state = 'running' AND lease_expires_at < $1 AND cancel_requested = 1")
                .bind(now).execute(p).await?.rows_affected();
            s.failed = sqlx::query("UPDATE jobs SET state = 'failed', stage = 'failed', error_code = 'attempts_exhausted', \
                 error_message = 'the lease expired on every attempt (worker lost or over its time limit)', \
                 finished_at = $1, updated_at = $1, lease_owner = NULL, lease_expires_at = NULL \
                 WHERE state = 'running' AND lease_expires_at < $1 AND attempts >= max_attempts")
                .bind(now).execute(p).await?.rows_affected();
            s.requeued = sqlx::query("UPDATE jobs SET state = 'queued', stage = 'requeued', progress = 0, lease_owner = NULL, \
                 lease_expires_at = NULL, updated_at = $1 WHERE state = 'running' AND lease_expires_at < $1")
                .bind(now).execute(p).await?.rows_affected();
        });
        Ok(s)
    }

    /// Number of jobs in each state (all owners), for metrics.
    ///
    /// # Errors
    /// Database failures.
    pub async fn count_by_state(&self) -> Result<Vec<(JobState, i64)>> {
        let rows: Vec<(String, i64)> = on!(self, p => {
            let rows = sqlx::query("SELECT state, COUNT(*) AS n FROM jobs GROUP BY state").fetch_all(p).await?;
            let mut v = Vec::with_capacity(rows.len());
            for r in &rows { v.push((r.try_get("state")?, r.try_get("n")?)); }
            v
        });
        Ok(JobState::ALL
            .into_iter()
            .map(|st| (st, rows.iter().find(|(s, _)| s == st.as_str()).map_or(0, |r| r.1)))
            .collect())
    }
}
