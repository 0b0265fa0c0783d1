//! The job child: each job's pipeline runs in a child process of the worker (the same binary,
//! started as `<exe> __run-job DIR`), so that nothing a job does can take the worker or the API
//! server down with it. The child caps its own address space (`RLIMIT_AS`), so an allocation
//! beyond the job's memory budget aborts the child alone; cancel, time limit and shutdown kill
//! it at once, whatever stage it is in.
//!
//! The protocol is a scratch directory the worker creates and deletes:
//! - `job.json`: [`ChildInput`] (the typed spec, as JSON, and the limits); `mesh_<i>`: the
//!   meshes' bytes.
//! - stdout: one `stage<TAB>fraction` line per progress report.
//! - `result.json`: [`ChildOutput`]; `out_<k>`: the artifacts' bytes.
//!
//! The child also exits when its stdin closes: the worker holds the pipe, so a worker that
//! dies (even by SIGKILL) leaves no job running behind it.

use geom::io::ReadOptions;
use geom::mesh::MeshLimits;
use geom::pipeline::JobSpec;
use geom::progress::Stage;
use serde::{Deserialize, Serialize};
use std::io::{Read, Write};
use std::path::Path;

/// The hidden first argument that makes a worker or server binary run one job and exit.
pub const CHILD_ARG: &str = "__run-job";

/// What the worker hands the child in `job.json`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct ChildInput {
    /// The job's typed spec.
    pub job: JobSpec,
    pub meshes: usize,
    pub max_vertices: u64,
    /// Address-space limit of the child in bytes (0: none).
    pub memory_bytes: u64,
}

/// One artifact written by the child as `out_<k>`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) struct ChildArtifact {
    pub name: String,
    pub content_type: String,
}

/// What the child leaves in `result.json`.
#[derive(Debug, Serialize, Deserialize)]
pub(crate) enum ChildOutput {
    Succeeded { timings_ms: Vec<(String, f64)>, report: serde_json::Value, artifacts: Vec<ChildArtifact> },
    Failed { code: String, message: String, internal: bool },
}

/// Runs one job when `args` are `[exe, CHILD_ARG, DIR]`, then returns the exit code; `None`
/// for any other command line (the binary goes on to its own `main`).
pub fn main_if_child() -> Option<std::process::ExitCode> {
    let args: Vec<std::ffi::OsString> = std::env::args_os().collect();
    if args.get(1).and_then(|a| a.to_str()) != Some(CHILD_ARG) {
        return None;
    }
    let Some(dir) = args.get(2) else {
        eprintln!("{CHILD_ARG} needs the job directory");
        return Some(std::process::ExitCode::from(2));
    };
    // `geom`'s debug events (`RUST_LOG=geom=debug`) go to the inherited stderr, the worker's log.
    if std::env::var_os("RUST_LOG").is_some() {
        tracing_subscriber::fmt()
            .with_env_filter(tracing_subscriber::EnvFilter::from_default_env())
            .with_writer(std::io::stderr)
            .with_ansi(false)
            .init();
    }
    // The parent holds our stdin; when it goes away, so do we.
    std::thread::spawn(|| {
        let mut sink = [0u8; 64];
        while matches!(std::io::stdin().read(&mut sink), Ok(n) if n > 0) {}
        std::process::exit(3);
    });
    Some(match run(Path::new(dir)) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("job child: {e}");
            std::process::ExitCode::from(1)
        }
    })
}

/// Prints each report as a line the worker reads; never cancels (the worker kills instead).
struct StdoutProgress {
    last: Option<(Stage, std::time::Instant)>,
}

impl geom::progress::Progress for StdoutProgress {
    fn report(&mut self, stage: Stage, fraction: f64) {
        // At most about twenty lines a second per stage: the heartbeat reads one a second.
        let now = std::time::Instant::now();
        if let Some((s, t)) = &self.last
            && *s == stage
            && now.duration_since(*t).as_millis() < 50
            && fraction < 1.0
        {
            return;
        }
        self.last = Some((stage, now));
        let mut out = std::io::stdout().lock();
        let _ = writeln!(out, "{stage}\t{fraction}");
        let _ = out.flush();
    }
}

fn run(dir: &Path) -> std::io::Result<()> {
    let input: ChildInput = serde_json::from_slice(&std::fs::read(dir.join("job.json"))?)?;
    if input.memory_bytes > 0 {
        rlimit::setrlimit(rlimit::Resource::AS, input.memory_bytes, input.memory_bytes)?;
    }
    let output = match execute(dir, &input) {
        Ok(o) => o,
        // A solver that reports its allocation failing under the cap (faer does) is the budget,
        // not the numerics. Allocations that cannot report it abort the process instead.
        Err(e) if e.to_string().contains("OutOfMemory") => ChildOutput::Failed {
            code: "out_of_memory".into(),
            message: format!("the job needs more than its memory budget of {} MiB ({e})", input.memory_bytes >> 20),
            internal: false,
        },
        Err(e) => ChildOutput::Failed {
            code: e.code().to_string(),
            message: e.to_string(),
            internal: matches!(e, geom::Error::Internal(_)),
        },
    };
    let tmp = dir.join("result.json.tmp");
    std::fs::write(&tmp, serde_json::to_vec(&output)?)?;
    std::fs::rename(tmp, dir.join("result.json"))
}

fn execute(dir: &Path, input: &ChildInput) -> geom::Result<ChildOutput> {
    let io = |e: std::io::Error| geom::Error::Internal(format!("job directory: {e}"));
    let limits = MeshLimits { max_vertices: input.max_vertices, max_faces: 2 * input.max_vertices + 8 };
    let mut meshes = Vec::with_capacity(input.meshes);
    let mut layouts = Vec::with_capacity(input.meshes);
    for i in 0..input.meshes {
        let bytes = std::fs::read(dir.join(format!("mesh_{i}"))).map_err(io)?;
        let r = geom::io::read(&bytes, &ReadOptions { limits, hint: None })?;
        meshes.push(r.mesh);
        layouts.push(r.layout);
    }
    let mut progress = StdoutProgress { last: None };
    let (report, artifacts) = geom::pipeline::run_with_layouts(&input.job, &meshes, &layouts, &mut progress)?;
    let mut listed = Vec::with_capacity(artifacts.len());
    for (k, a) in artifacts.into_iter().enumerate() {
        std::fs::write(dir.join(format!("out_{k}")), &a.bytes).map_err(io)?;
        listed.push(ChildArtifact { name: a.name, content_type: a.content_type.to_string() });
    }
    Ok(ChildOutput::Succeeded {
        timings_ms: report.timings_ms().to_vec(),
        report: serde_json::to_value(&report).map_err(|e| geom::Error::Internal(e.to_string()))?,
        artifacts: listed,
    })
}
