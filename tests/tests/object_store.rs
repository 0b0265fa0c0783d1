//! Blobs on an S3-compatible object store: a server and a worker with different `--data-dir`s
//! and one `--blob-url s3://…` run a job end to end; the artifacts download and the bucket holds
//! the blobs. The S3 server is moto's (`python3 -m pip install "moto[server]"`, which the
//! README's test command runs), started here on a free port.

mod common;

use common::{Api, Env, Proc, SMPL, identity_spec, shared, wait_for};
use std::time::Duration;

/// `moto_server` on a free port, with a fresh bucket.
async fn s3(env: &Env, bucket: &str) -> (Proc, String) {
    let port = common::free_port();
    let log = env.dir.path().join("moto.log");
    let child = std::process::Command::new("python3")
        .args(["-m", "moto.server", "-H", "127.0.0.1", "-p", &port.to_string()])
        .stdout(std::process::Stdio::null())
        .stderr(std::fs::File::create(&log).unwrap())
        .spawn()
        .expect("moto's S3 server (python3 -m pip install \"moto[server]\")");
    let proc = Proc { child, log, first_line: String::new() };
    let endpoint = format!("http://127.0.0.1:{port}");
    let http = reqwest::Client::new();
    let url = format!("{endpoint}/{bucket}");
    let made = wait_for(Duration::from_secs(60), || {
        let (http, url) = (http.clone(), url.clone());
        async move { http.put(&url).send().await.ok().filter(|r| r.status().is_success()).map(|_| ()) }
    })
    .await;
    assert!(made.is_some(), "moto did not start: {}", proc.log_text());
    (proc, endpoint)
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn server_and_worker_share_a_bucket_not_a_directory() {
    let mut env = Env::sqlite();
    let (_moto, endpoint) = s3(&env, "surfmap-test").await;
    env.vars = [
        ("AWS_ENDPOINT_URL", endpoint.as_str()),
        ("AWS_ACCESS_KEY_ID", "test"),
        ("AWS_SECRET_ACCESS_KEY", "test"),
        ("AWS_REGION", "us-east-1"),
        ("AWS_ALLOW_HTTP", "true"),
    ]
    .map(|(k, v)| (k.to_string(), v.to_string()))
    .to_vec();
    let url = "s3://surfmap-test/blobs";
    let (_server, base) = env.server_in("server-data", &["--workers", "0", "--blob-url", url]);
    let _worker = env.worker_in("worker-data", "w", &["--blob-url", url]);
    let api = Api::new(&base);
    let (st, a) = api.upload(&shared(SMPL.0)).await;
    assert_eq!(st, 201, "{a}");
    let (_, b) = api.upload(&shared(SMPL.1)).await;
    let (st, j) = api.submit(a["id"].as_str().unwrap(), b["id"].as_str().unwrap(), &identity_spec("voronoi", 12)).await;
    assert_eq!(st, 202, "{j}");
    let done = api.wait_done(j["id"].as_str().unwrap(), Duration::from_secs(300)).await;
    assert_eq!(done["state"], "succeeded", "{done}");
    let (st, obj, _) =
        api.bytes(&format!("/v1/jobs/{}/artifacts/source_on_target.obj", done["id"].as_str().unwrap())).await;
    assert_eq!(st, 200);
    assert!(obj.starts_with(b"v ") || obj.starts_with(b"#"), "an OBJ file");
    // The bucket holds the meshes and the artifacts under the prefix; neither data dir does.
    let list =
        reqwest::get(format!("{endpoint}/surfmap-test?list-type=2&prefix=blobs/")).await.unwrap().text().await.unwrap();
    let id = a["id"].as_str().unwrap();
    assert!(list.contains(&format!("blobs/{}/{}", &id[..2], &id[2..])), "{list}");
    let keys = list.matches("<Key>").count();
    assert!(keys >= 2 + 8, "{keys} objects: {list}");
    for d in ["server-data", "worker-data"] {
        assert!(!env.dir.path().join(d).join("blobs").exists(), "{d} holds blobs");
    }
}
