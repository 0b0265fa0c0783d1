//! The end-to-end harness, shared by the test files (each uses part of it): start the real
//! binaries (found next to this test in the target directory; `cargo test --workspace` builds
//! them, since the server and worker packages have tests of their own) on port 0, talk to them,
//! and check results with the shared evaluator. Failures here panic: they fail the test.

#![allow(dead_code)]

use serde_json::{Value, json};
use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// `../shared` beside the clone (or `$SURFMAP_SHARED`), as the geometry tests find it.
pub fn shared(rel: &str) -> PathBuf {
    let root = std::env::var_os("SURFMAP_SHARED")
        .map(PathBuf::from)
        .unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared"));
    root.join(rel)
}

/// The directory holding the workspace's binaries (`target/<profile>`).
pub fn bin_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("current exe");
    let mut dir = exe.parent().expect("exe dir").to_path_buf();
    if dir.ends_with("deps") {
        dir.pop();
    }
    dir
}

/// A binary of the workspace; panics with the fix when it has not been built.
pub fn binary(name: &str) -> PathBuf {
    let p = bin_dir().join(name);
    assert!(
        p.exists(),
        "{} is missing: run `cargo build --workspace --bins` (cargo test --workspace does)",
        p.display()
    );
    p
}

/// A child process killed when dropped; its stderr goes to a log file.
pub struct Proc {
    pub child: Child,
    pub log: PathBuf,
    pub first_line: String,
}

impl Proc {
    pub fn pid(&self) -> u32 {
        self.child.id()
    }
    /// Sends a signal by name (`KILL`, `TERM`, `STOP`, `CONT`) with the `kill` command.
    pub fn signal(&self, sig: &str) {
        let ok = Command::new("kill").arg(format!("-{sig}")).arg(self.pid().to_string()).status().map(|s| s.success());
        assert!(ok.unwrap_or(false), "kill -{sig} {}", self.pid());
    }
    /// Waits for exit, up to `timeout`.
    pub fn wait_exit(&mut self, timeout: Duration) -> Option<std::process::ExitStatus> {
        let end = Instant::now() + timeout;
        while Instant::now() < end {
            if let Ok(Some(s)) = self.child.try_wait() {
                return Some(s);
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        None
    }
    pub fn log_text(&self) -> String {
        std::fs::read_to_string(&self.log).unwrap_or_default()
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn spawn(bin: &str, args: &[String], log: PathBuf, vars: &[(String, String)]) -> Proc {
    let err = std::fs::File::create(&log).expect("log file");
    let mut child = Command::new(binary(bin))
        .args(args)
        .envs(vars.iter().map(|(k, v)| (k, v)))
        .env("RUST_LOG", "info,sqlx=warn")
        .stdout(Stdio::piped())
        .stderr(err)
        .spawn()
        .expect("spawn");
    let stdout = child.stdout.take().expect("stdout");
    let (tx, rx) = std::sync::mpsc::channel();
    std::thread::spawn(move || {
        let mut r = BufReader::new(stdout);
        let mut line = String::new();
        let _ = r.read_line(&mut line);
        let _ = tx.send(line);
        // Keep draining so the child never blocks on a full pipe.
        let mut sink = String::new();
        while r.read_line(&mut sink).map(|n| n > 0).unwrap_or(false) {
            sink.clear();
        }
    });
    let first_line = rx.recv_timeout(Duration::from_secs(60)).unwrap_or_default().trim().to_string();
    Proc { child, log, first_line }
}

/// A scratch directory with a database URL and a data dir that servers and workers share.
pub struct Env {
    pub dir: tempfile::TempDir,
    pub database_url: String,
    /// Environment variables of every process started (the AWS ones for an S3 blob store).
    pub vars: Vec<(String, String)>,
}

impl Env {
    /// A fresh SQLite file.
    pub fn sqlite() -> Env {
        let dir = tempfile::tempdir().expect("tempdir");
        let database_url = format!("sqlite://{}", dir.path().join("surfmap.db").display());
        Env { dir, database_url, vars: Vec::new() }
    }

    /// A fresh PostgreSQL database, when `SURFMAP_TEST_POSTGRES_URL` is set.
    pub async fn postgres() -> Option<Env> {
        let base = surfmap_store::testing::postgres_base_url()?;
        let database_url = surfmap_store::testing::fresh_postgres_database(&base).await.expect("create test database");
        Some(Env { dir: tempfile::tempdir().expect("tempdir"), database_url, vars: Vec::new() })
    }

    /// Both stores this machine offers.
    pub async fn all() -> Vec<Env> {
        let mut v = vec![Env::sqlite()];
        v.extend(Env::postgres().await);
        v
    }

    fn common(&self) -> Vec<String> {
        self.common_in("data")
    }

    /// The database and `--data-dir` `data` under the scratch directory.
    fn common_in(&self, data: &str) -> Vec<String> {
        vec![
            "--database-url".into(),
            self.database_url.clone(),
            "--data-dir".into(),
            self.dir.path().join(data).display().to_string(),
        ]
    }

    /// Starts `surfmap-server` on 127.0.0.1:0; returns it and its base URL.
    pub fn server(&self, extra: &[&str]) -> (Proc, String) {
        self.server_in("data", extra)
    }

    /// [`Env::server`] with its own `--data-dir`.
    pub fn server_in(&self, data: &str, extra: &[&str]) -> (Proc, String) {
        let mut args = vec!["--listen".to_string(), "127.0.0.1:0".into()];
        args.extend(self.common_in(data));
        args.extend(extra.iter().map(|s| s.to_string()));
        let n = std::fs::read_dir(self.dir.path()).map(|d| d.count()).unwrap_or(0);
        let p = spawn("surfmap-server", &args, self.dir.path().join(format!("server-{n}.log")), &self.vars);
        let addr = p
            .first_line
            .strip_prefix("listening on ")
            .unwrap_or_else(|| panic!("server did not print its address: {:?}\n{}", p.first_line, p.log_text()));
        let base = format!("http://{addr}");
        (p, base)
    }

    /// Starts a `surfmap-worker` with the given id.
    pub fn worker(&self, id: &str, extra: &[&str]) -> Proc {
        self.worker_in("data", id, extra)
    }

    /// [`Env::worker`] with its own `--data-dir`.
    pub fn worker_in(&self, data: &str, id: &str, extra: &[&str]) -> Proc {
        let mut args = self.common_in(data);
        args.extend(["--worker-id".to_string(), id.to_string(), "--poll-ms".into(), "100".into()]);
        args.extend(extra.iter().map(|s| s.to_string()));
        let p = spawn("surfmap-worker", &args, self.dir.path().join(format!("worker-{id}.log")), &self.vars);
        assert!(p.first_line.contains("ready"), "worker did not start: {:?}\n{}", p.first_line, p.log_text());
        p
    }
}

/// A port that was free a moment ago (for listeners that do not report the port they got).
pub fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").and_then(|l| l.local_addr()).map(|a| a.port()).expect("free port")
}

/// A registered pair with ground truth: the SMPL man and woman (same connectivity).
pub const SMPL: (&str, &str) =
    ("meshes/registered/smpl_human/human_man.obj", "meshes/registered/smpl_human/human_woman.obj");

/// `k` farthest-point samples (Euclidean, from vertex 0) of a mesh file.
pub fn fps_anchors(path: &Path, k: usize) -> Vec<u32> {
    let m = geom::io::read_path(path, &geom::io::ReadOptions::default()).expect("mesh").mesh;
    let p: Vec<[f64; 3]> = (0..m.n_vertices())
        .map(|i| {
            let q = m.position(geom::VertexId(i as u32));
            [q.x, q.y, q.z]
        })
        .collect();
    let d2 = |a: &[f64; 3], b: &[f64; 3]| (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2);
    let mut out = vec![0u32];
    let mut dist: Vec<f64> = p.iter().map(|q| d2(q, &p[0])).collect();
    while out.len() < k {
        let (i, _) = dist.iter().enumerate().fold((0, -1.0), |b, (i, &d)| if d > b.1 { (i, d) } else { b });
        out.push(i as u32);
        for (j, q) in p.iter().enumerate() {
            dist[j] = dist[j].min(d2(q, &p[i]));
        }
    }
    out
}

/// The spec of an identity-registered pair with `k` FPS anchors.
pub fn identity_spec(method: &str, k: usize) -> Value {
    let a = fps_anchors(&shared(SMPL.0), k);
    json!({"method": method, "anchors": a.iter().map(|&i| [i, i]).collect::<Vec<_>>()})
}

/// Runs `../shared/eval/meshmetrics.py` and returns its JSON.
pub fn evaluate(source: &Path, target: &Path, mapped: &Path, anchors: &Value, gt: Option<&Path>) -> Value {
    let dir = tempfile::tempdir().expect("tempdir");
    let af = dir.path().join("anchors.json");
    std::fs::write(&af, json!({"anchors": anchors}).to_string()).expect("anchors");
    let mut cmd = Command::new("python3");
    cmd.arg(shared("eval/meshmetrics.py")).arg(source).arg(target).arg(mapped).arg("--anchors").arg(&af);
    if let Some(g) = gt {
        cmd.arg("--gt").arg(g);
    }
    let out = cmd.output().expect("python3");
    assert!(
        out.status.success(),
        "the shared evaluator failed (needs numpy and scipy: python3 -m pip install numpy scipy):\n{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).expect("evaluator JSON")
}

/// Asserts that every metric the evaluator and surfmap both report agrees.
pub fn assert_metrics_agree(ours: &Value, theirs: &Value) {
    let mut compared = 0;
    for (k, v) in theirs.as_object().expect("object") {
        let (Some(a), Some(b)) = (ours.get(k).and_then(Value::as_f64), v.as_f64()) else { continue };
        let tol = 1e-6 * a.abs().max(b.abs()) + 1e-12;
        assert!((a - b).abs() <= tol, "metric {k}: surfmap {a} vs evaluator {b}");
        compared += 1;
    }
    assert!(compared >= 10, "only {compared} metrics compared");
}

/// Polls `until` every 50 ms up to `timeout`.
pub async fn wait_for<T, F, Fut>(timeout: Duration, mut until: F) -> Option<T>
where
    F: FnMut() -> Fut,
    Fut: std::future::Future<Output = Option<T>>,
{
    let end = Instant::now() + timeout;
    while Instant::now() < end {
        if let Some(t) = until().await {
            return Some(t);
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
    None
}

/// A small REST client.
#[derive(Clone)]
pub struct Api {
    pub base: String,
    pub http: reqwest::Client,
    pub token: Option<String>,
}

impl Api {
    pub fn new(base: &str) -> Api {
        Api { base: base.to_string(), http: reqwest::Client::new(), token: None }
    }
    pub fn req(&self, method: reqwest::Method, path: &str) -> reqwest::RequestBuilder {
        let r = self.http.request(method, format!("{}{path}", self.base));
        match &self.token {
            Some(t) => r.bearer_auth(t),
            None => r,
        }
    }
    /// Uploads a file; returns (status, body).
    pub async fn upload(&self, path: &Path) -> (u16, Value) {
        let bytes = std::fs::read(path).expect("mesh file");
        self.upload_bytes(bytes).await
    }
    pub async fn upload_bytes(&self, bytes: Vec<u8>) -> (u16, Value) {
        let r = self.req(reqwest::Method::POST, "/v1/meshes").body(bytes).send().await.expect("upload");
        (r.status().as_u16(), r.json().await.unwrap_or(Value::Null))
    }
    pub async fn submit(&self, source: &str, target: &str, spec: &Value) -> (u16, Value) {
        let r = self
            .req(reqwest::Method::POST, "/v1/jobs")
            .json(&json!({"source": source, "target": target, "spec": spec}))
            .send()
            .await
            .expect("submit");
        (r.status().as_u16(), r.json().await.unwrap_or(Value::Null))
    }
    pub async fn get(&self, path: &str) -> (u16, Value) {
        let r = self.req(reqwest::Method::GET, path).send().await.expect("get");
        (r.status().as_u16(), r.json().await.unwrap_or(Value::Null))
    }
    pub async fn job(&self, id: &str) -> Value {
        self.get(&format!("/v1/jobs/{id}")).await.1
    }
    /// Waits for a terminal state; `None` after `timeout`.
    pub async fn poll_done(&self, id: &str, timeout: Duration) -> Option<Value> {
        let api = self.clone();
        let id = id.to_string();
        wait_for(timeout, || {
            let (api, id) = (api.clone(), id.clone());
            async move {
                let j = api.job(&id).await;
                matches!(j["state"].as_str(), Some("succeeded" | "failed" | "cancelled")).then_some(j)
            }
        })
        .await
    }
    /// Waits for a terminal state.
    pub async fn wait_done(&self, id: &str, timeout: Duration) -> Value {
        self.poll_done(id, timeout).await.unwrap_or_else(|| panic!("job {id} did not finish within {timeout:?}"))
    }
    pub async fn bytes(&self, path: &str) -> (u16, Vec<u8>, String) {
        let r = self.req(reqwest::Method::GET, path).send().await.expect("get");
        let ct = r.headers().get("content-type").and_then(|v| v.to_str().ok()).unwrap_or_default().to_string();
        (r.status().as_u16(), r.bytes().await.map(|b| b.to_vec()).unwrap_or_default(), ct)
    }
}

/// Runs pytest on `dir` (relative to the workspace) with the server binary and the client's
/// source on the path; fails with pytest's output.
pub fn pytest(dir: &str, extra: &[&str]) {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let out = Command::new("python3")
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", dir])
        .args(extra)
        .current_dir(&root)
        .env("SURFMAP_SERVER_BIN", binary("surfmap-server"))
        .env("PYTHONPATH", root.join("clients/python/src"))
        .output()
        .expect("python3");
    let (so, se) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    println!("{so}");
    assert!(
        out.status.success(),
        "pytest {dir} failed (scripts/test-setup.sh installs pytest, httpx, playwright and chromium):\n{so}\n{se}"
    );
    assert!(so.contains(" passed"), "pytest ran no test:\n{so}");
}
