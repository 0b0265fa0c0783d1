//! `surfmap-worker`: a separate process that claims and runs jobs from the store. Run any
//! number of them, on any machine that reaches the database and the data directory.

use clap::Parser;
use std::path::PathBuf;
use std::time::Duration;
use surfmap_worker::{Worker, WorkerConfig};

#[derive(Debug, Parser)]
#[command(name = "surfmap-worker", version, about = "Claims surfmap jobs from the store and runs them")]
struct Args {
    /// sqlite://PATH or postgres://…
    #[arg(long, env = "SURFMAP_DATABASE_URL", default_value = "sqlite://surfmap.db")]
    database_url: String,
    /// Directory of the content-addressed blobs (shared with the server).
    #[arg(long, env = "SURFMAP_DATA_DIR", default_value = "./surfmap-data")]
    data_dir: PathBuf,
    /// Where blobs (meshes, artifacts) live: `file:///path`, or `s3://bucket/prefix` with the
    /// standard AWS variables (AWS_ENDPOINT_URL, AWS_ACCESS_KEY_ID, AWS_SECRET_ACCESS_KEY,
    /// AWS_REGION, AWS_ALLOW_HTTP) [default: `blobs/` under --data-dir].
    #[arg(long, env = "SURFMAP_BLOB_URL")]
    blob_url: Option<String>,
    /// Lease owner name [default: host-pid-random].
    #[arg(long, env = "SURFMAP_WORKER_ID")]
    worker_id: Option<String>,
    /// Lease length in seconds; heartbeats extend it.
    #[arg(long, env = "SURFMAP_LEASE_SECS", default_value_t = 30.0)]
    lease_secs: f64,
    /// Idle wait between claims, in milliseconds.
    #[arg(long, env = "SURFMAP_POLL_MS", default_value_t = 500)]
    poll_ms: u64,
    /// Wall-clock limit per job, in seconds.
    #[arg(long, env = "SURFMAP_TIME_LIMIT_SECS", default_value_t = 1800)]
    time_limit_secs: u64,
    /// Largest mesh, in vertices.
    #[arg(long, env = "SURFMAP_MAX_VERTICES", default_value_t = 2_000_000)]
    max_vertices: u64,
    /// On SIGTERM, how long the current job may finish before its lease is released.
    #[arg(long, env = "SURFMAP_SHUTDOWN_GRACE_SECS", default_value_t = 60)]
    shutdown_grace_secs: u64,
    /// Memory budget of one job in MiB: jobs estimated above it are refused, and each job's
    /// process is capped at it (an allocation beyond it fails the job, not the service).
    #[arg(long, env = "SURFMAP_JOB_MEMORY_MB", default_value_t = 8192)]
    job_memory_mb: u64,
    /// Serve this worker's Prometheus metrics (stage and job durations, failures by code) at
    /// `http://ADDR/metrics`.
    #[arg(long, env = "SURFMAP_METRICS_LISTEN")]
    metrics_listen: Option<String>,
}

fn main() -> std::process::ExitCode {
    surfmap_worker::binary_main("surfmap-worker", Args::parse, run)
}

async fn run(a: Args) -> anyhow::Result<()> {
    if !(a.lease_secs.is_finite() && a.lease_secs > 0.0) {
        anyhow::bail!("--lease-secs must be positive");
    }
    let store = surfmap_store::Store::connect(&a.database_url).await?;
    let blobs = surfmap_store::BlobStore::from_url(a.blob_url.as_deref(), &a.data_dir)?;
    let config = WorkerConfig {
        id: a.worker_id.unwrap_or_else(WorkerConfig::default_id),
        lease: Duration::from_secs_f64(a.lease_secs),
        poll: Duration::from_millis(a.poll_ms),
        time_limit: Duration::from_secs(a.time_limit_secs),
        max_vertices: a.max_vertices,
        shutdown_grace: Duration::from_secs(a.shutdown_grace_secs),
        runner: surfmap_worker::Runner::current_exe()?,
        job_memory_bytes: a.job_memory_mb.saturating_mul(1 << 20),
    };
    surfmap_worker::telemetry::prometheus();
    let (tx, rx) = tokio::sync::watch::channel(false);
    if let Some(addr) = &a.metrics_listen {
        let listener = tokio::net::TcpListener::bind(addr).await?;
        tracing::info!(addr = %listener.local_addr()?, "metrics at /metrics");
        let rx = rx.clone();
        tokio::spawn(async move {
            if let Err(e) = surfmap_worker::telemetry::serve_metrics(listener, rx).await {
                tracing::warn!("metrics listener: {e}");
            }
        });
    }
    println!("worker {} ready", config.id);
    tokio::spawn(async move {
        surfmap_worker::shutdown_signal().await;
        let _ = tx.send(true);
    });
    Worker { store, blobs, config }.run(rx).await;
    Ok(())
}
