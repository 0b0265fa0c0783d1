//! One job's pipeline while it runs, on a thread or in a child process ([`crate::Runner`]):
//! started, waited on (cancel-safe, for `select!`), stopped, and collected into one outcome.

use crate::child::{CHILD_ARG, ChildInput, ChildOutput};
use crate::config::{Runner, WorkerConfig};
use crate::progress::Shared;
use geom::pipeline::JobSpec;
use std::process::{ExitStatus, Stdio};
use tokio::io::AsyncBufReadExt;
use tokio::task::JoinHandle;

/// A finished pipeline's report and artifacts.
pub(crate) struct Finished {
    pub timings_ms: Vec<(String, f64)>,
    pub report: serde_json::Value,
    pub artifacts: Vec<(String, String, Vec<u8>)>,
}

/// Why a run did not finish.
pub(crate) enum RunError {
    /// The pipeline's own error (typed input, numerical, internal) on this thread.
    Geom(geom::Error),
    /// The pipeline's own error as the child reported it.
    Failed { code: String, message: String, internal: bool },
    /// The child process died (a signal, an allocation over the budget, a panic).
    Crashed(String),
    /// The worker stopped the run (cancel, time limit, shutdown, lost lease).
    Stopped,
}

type ThreadResult = geom::Result<(Box<geom::pipeline::JobReport>, Vec<geom::pipeline::Artifact>)>;

pub(crate) enum Running {
    Thread {
        handle: JoinHandle<ThreadResult>,
        result: Option<Result<ThreadResult, tokio::task::JoinError>>,
    },
    Process {
        child: tokio::process::Child,
        /// Held until the run is collected: the child exits when it closes (and
        /// `Child::wait` would close it if it stayed in `child`).
        _stdin: Option<tokio::process::ChildStdin>,
        dir: tempfile::TempDir,
        status: Option<std::io::Result<ExitStatus>>,
    },
}

impl Running {
    /// Starts `job` on `meshes` (bytes, read by the runner under the vertex cap).
    pub async fn start(
        config: &WorkerConfig,
        job: JobSpec,
        meshes: Vec<Vec<u8>>,
        shared: &Shared,
    ) -> Result<Running, RunError> {
        let internal = |e: std::io::Error| RunError::Geom(geom::Error::Internal(format!("job child: {e}")));
        match &config.runner {
            Runner::Thread => {
                let limits = geom::mesh::MeshLimits {
                    max_vertices: config.max_vertices,
                    max_faces: 2 * config.max_vertices + 8,
                };
                let mut progress = shared.clone();
                let handle = tokio::task::spawn_blocking(move || {
                    let opts = geom::io::ReadOptions { limits, hint: None };
                    let (meshes, layouts): (Vec<_>, Vec<_>) = meshes
                        .iter()
                        .map(|b| geom::io::read(b, &opts).map(|r| (r.mesh, r.layout)))
                        .collect::<geom::Result<Vec<_>>>()?
                        .into_iter()
                        .unzip();
                    geom::pipeline::run_with_layouts(&job, &meshes, &layouts, &mut progress)
                        .map(|(r, a)| (Box::new(r), a))
                });
                Ok(Running::Thread { handle, result: None })
            }
            Runner::Process { exe } => {
                let dir = tempfile::Builder::new().prefix("surfmap-job-").tempdir().map_err(internal)?;
                let input = ChildInput {
                    job,
                    meshes: meshes.len(),
                    max_vertices: config.max_vertices,
                    memory_bytes: config.job_memory_bytes,
                };
                let json = serde_json::to_vec(&input).map_err(|e| internal(e.into()))?;
                tokio::fs::write(dir.path().join("job.json"), json).await.map_err(internal)?;
                for (i, m) in meshes.iter().enumerate() {
                    tokio::fs::write(dir.path().join(format!("mesh_{i}")), m).await.map_err(internal)?;
                }
                drop(meshes);
                let mut child = tokio::process::Command::new(exe)
                    .arg(CHILD_ARG)
                    .arg(dir.path())
                    // Two malloc arenas: the address-space cap then measures the heap, not
                    // 64 MiB of reserved arena per thread.
                    .env("MALLOC_ARENA_MAX", "2")
                    .stdin(Stdio::piped())
                    .stdout(Stdio::piped())
                    .stderr(Stdio::inherit())
                    .kill_on_drop(true)
                    .spawn()
                    .map_err(internal)?;
                if let Some(out) = child.stdout.take() {
                    let mut progress = shared.clone();
                    tokio::spawn(async move {
                        let mut lines = tokio::io::BufReader::new(out).lines();
                        while let Ok(Some(line)) = lines.next_line().await {
                            if let Some((stage, f)) = line.split_once('\t')
                                && let Ok(f) = f.parse::<f64>()
                                && let Some(stage) = geom::progress::Stage::from_name(stage)
                            {
                                geom::progress::Progress::report(&mut progress, stage, f);
                            }
                        }
                    });
                }
                let _stdin = child.stdin.take();
                Ok(Running::Process { child, _stdin, dir, status: None })
            }
        }
    }

    /// Resolves once the run has ended. Cancel-safe: a dropped call loses nothing.
    pub async fn ended(&mut self) {
        match self {
            Running::Thread { handle, result } => {
                if result.is_none() {
                    *result = Some(handle.await);
                }
            }
            Running::Process { child, status, .. } => {
                if status.is_none() {
                    *status = Some(child.wait().await);
                }
            }
        }
    }

    /// Asks the run to stop: the thread's pipeline at its next cancellation check (through
    /// `shared`), the child process at once (SIGKILL).
    pub fn stop(&mut self, shared: &Shared) {
        shared.cancel();
        if let Running::Process { child, status: None, .. } = self {
            let _ = child.start_kill();
        }
    }

    /// The outcome of an ended run (`stopped`: the worker asked it to stop).
    pub async fn collect(mut self, stopped: bool) -> Result<Finished, RunError> {
        self.ended().await;
        match self {
            Running::Thread { result, .. } => match result {
                Some(Ok(Ok((report, arts)))) => Ok(Finished {
                    timings_ms: report.timings_ms().to_vec(),
                    report: serde_json::to_value(&report)
                        .map_err(|e| RunError::Geom(geom::Error::Internal(e.to_string())))?,
                    artifacts: arts.into_iter().map(|a| (a.name, a.content_type.to_string(), a.bytes)).collect(),
                }),
                Some(Ok(Err(geom::Error::Cancelled))) if stopped => Err(RunError::Stopped),
                Some(Ok(Err(e))) => Err(RunError::Geom(e)),
                Some(Err(e)) => Err(RunError::Geom(geom::Error::Internal(format!("pipeline thread panicked: {e}")))),
                None => Err(RunError::Geom(geom::Error::Internal("pipeline thread lost".into()))),
            },
            Running::Process { dir, status, .. } => {
                let status = status.and_then(Result::ok);
                if stopped {
                    return Err(RunError::Stopped);
                }
                match status {
                    Some(s) if s.success() => read_output(dir.path()).await,
                    Some(s) => Err(RunError::Crashed(describe(s))),
                    None => Err(RunError::Crashed("the job child could not be waited on".into())),
                }
            }
        }
    }
}

fn describe(s: ExitStatus) -> String {
    use std::os::unix::process::ExitStatusExt;
    match (s.code(), s.signal()) {
        (_, Some(6)) => {
            "the job process aborted (signal 6: most often an allocation over the job memory budget)".into()
        }
        (_, Some(sig)) => format!("the job process was killed by signal {sig}"),
        (Some(c), _) => format!("the job process exited with status {c}"),
        _ => "the job process ended abnormally".into(),
    }
}

async fn read_output(dir: &std::path::Path) -> Result<Finished, RunError> {
    let internal = |e: String| RunError::Geom(geom::Error::Internal(format!("job child output: {e}")));
    let bytes = tokio::fs::read(dir.join("result.json")).await.map_err(|e| internal(e.to_string()))?;
    let out: ChildOutput = serde_json::from_slice(&bytes).map_err(|e| internal(e.to_string()))?;
    match out {
        ChildOutput::Succeeded { timings_ms, report, artifacts } => {
            let mut arts = Vec::with_capacity(artifacts.len());
            for (k, a) in artifacts.into_iter().enumerate() {
                let b = tokio::fs::read(dir.join(format!("out_{k}"))).await.map_err(|e| internal(e.to_string()))?;
                arts.push((a.name, a.content_type, b));
            }
            Ok(Finished { timings_ms, report, artifacts: arts })
        }
        ChildOutput::Failed { code, message, internal } => Err(RunError::Failed { code, message, internal }),
    }
}
