//! The worker: claim a job -> load its meshes -> run `geom::pipeline::run_map` on a blocking
//! thread while heartbeating -> store artifacts -> complete, fenced. Owns the job execution
//! rules (time limit, vertex cap, cancellation, graceful shutdown); the SQL is the store's.

mod config;
mod execute;
mod progress;

pub use config::WorkerConfig;
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
