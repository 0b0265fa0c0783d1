//! `surfmap-server`: REST + gRPC on one port, the janitor, and N in-process workers
//! (`--workers 0` makes it API only). Prints `listening on ADDR` as its first stdout line.

use clap::Parser;
use std::io::Write;
use std::path::PathBuf;
use std::time::Duration;
use surfmap_server::service::{JobService, Limits};
use surfmap_server::{AppState, auth::Auth};
use surfmap_worker::{Worker, WorkerConfig};

#[derive(Debug, Parser)]
#[command(name = "surfmap-server", version, about = "The surfmap job server (REST and gRPC on one port)")]
struct Args {
    /// Address to bind; port 0 picks a free one.
    #[arg(long, env = "SURFMAP_LISTEN", default_value = "127.0.0.1:8080")]
    listen: String,
    /// sqlite://PATH (created on first run) or postgres://…
    #[arg(long, env = "SURFMAP_DATABASE_URL", default_value = "sqlite://surfmap.db")]
    database_url: String,
    /// Directory of the content-addressed blobs (meshes, artifacts).
    #[arg(long, env = "SURFMAP_DATA_DIR", default_value = "./surfmap-data")]
    data_dir: PathBuf,
    /// Where blobs (meshes, artifacts) live: `file:///path`, or `s3://bucket/prefix` with the
    /// standard AWS variables (AWS_ENDPOINT_URL, AWS_ACCESS_KEY_ID, AWS_SECRET_ACCESS_KEY,
    /// AWS_REGION, AWS_ALLOW_HTTP) [default: `blobs/` under --data-dir].
    #[arg(long, env = "SURFMAP_BLOB_URL")]
    blob_url: Option<String>,
    /// In-process workers [default: number of cores]; 0 serves the API only.
    #[arg(long, env = "SURFMAP_WORKERS")]
    workers: Option<usize>,
    /// Bearer token a client must present (repeatable). With tokens, clients see only their own jobs.
    #[arg(long = "api-token", env = "SURFMAP_API_TOKENS", value_delimiter = ',')]
    api_tokens: Vec<String>,
    /// Bearer token that `/metrics` requires. With API tokens and none of this, `/metrics`
    /// is closed (its figures span every tenant).
    #[arg(long, env = "SURFMAP_METRICS_TOKEN")]
    metrics_token: Option<String>,
    /// Largest request body in MiB.
    #[arg(long, env = "SURFMAP_MAX_BODY_MB", default_value_t = 256)]
    max_body_mb: usize,
    /// Largest JSON request body (a job's spec with its anchors and features) in MiB.
    #[arg(long, env = "SURFMAP_MAX_JSON_MB", default_value_t = 8)]
    max_json_mb: usize,
    /// Memory that concurrent uploads may hold while they are read and parsed, in MiB (an
    /// upload reserves four times its body; over the budget: 429 with Retry-After).
    #[arg(long, env = "SURFMAP_UPLOAD_MEMORY_MB", default_value_t = 1024)]
    upload_memory_mb: usize,
    /// Largest mesh in vertices.
    #[arg(long, env = "SURFMAP_MAX_VERTICES", default_value_t = 2_000_000)]
    max_vertices: u64,
    /// Attempts per job before an expired lease fails it.
    #[arg(long, env = "SURFMAP_MAX_ATTEMPTS", default_value_t = 3)]
    max_attempts: i64,
    /// Lease length of the in-process workers, in seconds.
    #[arg(long, env = "SURFMAP_LEASE_SECS", default_value_t = 30.0)]
    lease_secs: f64,
    /// Wall-clock limit per job, in seconds.
    #[arg(long, env = "SURFMAP_TIME_LIMIT_SECS", default_value_t = 1800)]
    time_limit_secs: u64,
    /// On SIGTERM, how long running jobs may finish before their leases are released.
    #[arg(long, env = "SURFMAP_SHUTDOWN_GRACE_SECS", default_value_t = 60)]
    shutdown_grace_secs: u64,
    /// Memory budget of one job in MiB: jobs estimated above it are refused, and each job's
    /// process is capped at it (an allocation beyond it fails the job, not the service).
    #[arg(long, env = "SURFMAP_JOB_MEMORY_MB", default_value_t = 8192)]
    job_memory_mb: u64,
    /// A connection's first request, and every HTTP/1 request's headers, must arrive within
    /// this many seconds, or the connection is closed.
    #[arg(long, env = "SURFMAP_HEADER_READ_TIMEOUT_SECS", default_value_t = 10.0)]
    header_read_timeout_secs: f64,
    /// Open connections at most (at the limit the oldest connection with no request in flight
    /// is closed to admit a new one). Capped below the process's descriptor limit.
    #[arg(long, env = "SURFMAP_MAX_CONNECTIONS", default_value_t = 4096)]
    max_connections: usize,
}

fn main() -> std::process::ExitCode {
    surfmap_worker::binary_main("surfmap-server", Args::parse, run)
}

async fn run(a: Args) -> anyhow::Result<()> {
    if !(a.lease_secs.is_finite() && a.lease_secs > 0.0) || a.max_attempts < 1 {
        anyhow::bail!("--lease-secs must be positive and --max-attempts at least 1");
    }
    if !(a.header_read_timeout_secs.is_finite() && a.header_read_timeout_secs > 0.0) || a.max_connections < 1 {
        anyhow::bail!("--header-read-timeout-secs must be positive and --max-connections at least 1");
    }
    // Connections must run out before descriptors do (the store, blobs and jobs need some).
    let descriptors = rlimit::increase_nofile_limit(u64::MAX).unwrap_or(1024);
    let max_connections =
        a.max_connections.min(usize::try_from(descriptors.saturating_sub(256)).unwrap_or(usize::MAX).max(16));
    if max_connections < a.max_connections {
        tracing::warn!(max_connections, descriptors, "--max-connections lowered to fit the descriptor limit");
    }
    surfmap_worker::telemetry::prometheus();
    let store = surfmap_store::Store::connect(&a.database_url).await?;
    let blobs = surfmap_store::BlobStore::from_url(a.blob_url.as_deref(), &a.data_dir)?;
    let limits = Limits {
        max_body_bytes: a.max_body_mb.saturating_mul(1 << 20),
        max_json_bytes: a.max_json_mb.saturating_mul(1 << 20),
        uploads: surfmap_server::service::UploadBudget::new(a.upload_memory_mb.saturating_mul(1 << 20)),
        max_vertices: a.max_vertices,
        max_attempts: a.max_attempts,
        job_memory_bytes: a.job_memory_mb.saturating_mul(1 << 20),
        ..Limits::default()
    };
    let (tx, rx) = tokio::sync::watch::channel(false);
    let stopping = surfmap_server::stopping::Stopping::new(rx.clone());
    let service = JobService { store: store.clone(), blobs: blobs.clone(), limits, stopping };
    let auth = Auth::new(&a.api_tokens).with_metrics_token(a.metrics_token.as_deref());
    let state = AppState { service, auth };
    let listener = tokio::net::TcpListener::bind(&a.listen).await?;
    let addr = listener.local_addr()?;
    println!("listening on {addr}");
    std::io::stdout().flush()?;
    tracing::info!(%addr, store = store.dialect(), auth = state.auth.enabled(), "serving REST and gRPC");

    let lease = Duration::from_secs_f64(a.lease_secs);
    let mut tasks = Vec::new();
    tasks.push(tokio::spawn(surfmap_server::janitor(
        store.clone(),
        (lease / 2).max(Duration::from_millis(200)),
        rx.clone(),
    )));
    let n = a.workers.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    let runner = surfmap_worker::Runner::current_exe()?;
    for i in 0..n {
        let config = WorkerConfig {
            id: format!("{}-w{i}", WorkerConfig::default_id()),
            lease,
            time_limit: Duration::from_secs(a.time_limit_secs),
            max_vertices: a.max_vertices,
            shutdown_grace: Duration::from_secs(a.shutdown_grace_secs),
            runner: runner.clone(),
            job_memory_bytes: a.job_memory_mb.saturating_mul(1 << 20),
            ..WorkerConfig::default()
        };
        let w = Worker { store: store.clone(), blobs: blobs.clone(), config };
        let rx = rx.clone();
        tasks.push(tokio::spawn(async move { w.run(rx).await }));
    }
    tracing::info!(workers = n, "in-process workers started");
    let cfg = surfmap_server::serve::ServeConfig {
        header_read_timeout: Duration::from_secs_f64(a.header_read_timeout_secs),
        max_connections,
        grace: Duration::from_secs(a.shutdown_grace_secs),
    };
    let signal = async move {
        surfmap_worker::shutdown_signal().await;
        tracing::info!("shutdown requested: no new requests or jobs; open streams end");
        let _ = tx.send(true);
    };
    surfmap_server::serve::serve(listener, surfmap_server::app(state), cfg, signal).await?;
    for t in tasks {
        let _ = t.await;
    }
    tracing::info!("stopped cleanly");
    Ok(())
}
