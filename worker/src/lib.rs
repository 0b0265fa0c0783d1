//! The worker: claim a job -> load its meshes -> run `geom::pipeline::run_job` in a child
//! process (or on a blocking thread) while heartbeating -> store artifacts -> complete, fenced. Owns the job execution
//! rules (time limit, vertex cap, cancellation, graceful shutdown); the SQL is the store's.

pub mod child;
mod config;
mod execute;
mod progress;
mod running;
pub mod telemetry;

pub use child::main_if_child;
pub use config::{DEFAULT_JOB_MEMORY_BYTES, Runner, WorkerConfig};
pub use execute::{Ran, Worker};

/// A shutdown signal: `true` once the process should stop taking work.
pub type Shutdown = tokio::sync::watch::Receiver<bool>;

/// Resolves on SIGTERM or Ctrl-C.
pub async fn shutdown_signal() {
    let ctrl_c = tokio::signal::ctrl_c();
    let Ok(mut term) = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) else {
        let _ = ctrl_c.await;
        return;
    };
    tokio::select! {
        _ = ctrl_c => {}
        _ = term.recv() => {}
    }
}

/// The whole `main` of both binaries: a job's child process (`<exe> __run-job DIR`) runs its
/// job and exits; otherwise `args` parses the command line and `run` runs on a multi-threaded
/// runtime under [`process_main`].
pub fn binary_main<A, F>(name: &str, args: impl FnOnce() -> A, run: impl FnOnce(A) -> F) -> std::process::ExitCode
where
    F: std::future::Future<Output = anyhow::Result<()>>,
{
    if let Some(code) = main_if_child() {
        return code;
    }
    let args = args();
    match tokio::runtime::Builder::new_multi_thread().enable_all().build() {
        Ok(rt) => rt.block_on(process_main(name, run(args))),
        Err(e) => {
            eprintln!("{name}: cannot start the runtime: {e}");
            std::process::ExitCode::from(1)
        }
    }
}

/// The body of both binaries' `main`: stderr logging (`RUST_LOG`, default `info`), then `run`;
/// an error is printed with its causes and exits 1.
pub async fn process_main(
    name: &str,
    run: impl std::future::Future<Output = anyhow::Result<()>>,
) -> std::process::ExitCode {
    tracing_subscriber::fmt()
        .with_env_filter(
            tracing_subscriber::EnvFilter::try_from_default_env().unwrap_or_else(|_| "info,sqlx=warn".into()),
        )
        .with_writer(std::io::stderr)
        .with_ansi(std::io::IsTerminal::is_terminal(&std::io::stderr()))
        .init();
    match run.await {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("{name}: {e:#}");
            std::process::ExitCode::from(1)
        }
    }
}
