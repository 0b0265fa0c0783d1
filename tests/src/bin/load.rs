//! `surfmap-load`: the load bench against a running server.
//!
//! Phase 1 submits `--submissions` jobs from `--clients` concurrent clients, each with its own
//! Idempotency-Key, re-sending a fifth of them as a client retry would; then pages through
//! `GET /v1/jobs` and checks that every job is there exactly once (none lost, none duplicated).
//! Phase 2 polls job status from `--pollers` concurrent connections for `--poll-secs` and
//! reports throughput and latency percentiles. Prints one JSON report.

use clap::Parser;
use serde_json::{Value, json};
use std::collections::HashSet;
use std::time::{Duration, Instant};

#[derive(Debug, Parser)]
struct Args {
    /// Base URL of the server, e.g. http://127.0.0.1:8080
    #[arg(long)]
    base: String,
    #[arg(long)]
    source: std::path::PathBuf,
    #[arg(long)]
    target: std::path::PathBuf,
    /// Anchors as "s:t,s:t,...".
    #[arg(long)]
    anchors: String,
    #[arg(long, default_value_t = 500)]
    submissions: usize,
    #[arg(long, default_value_t = 50)]
    clients: usize,
    #[arg(long, default_value_t = 32)]
    pollers: usize,
    #[arg(long, default_value_t = 10.0)]
    poll_secs: f64,
}

fn pct(sorted: &[f64], p: f64) -> f64 {
    if sorted.is_empty() {
        return f64::NAN;
    }
    sorted[((sorted.len() - 1) as f64 * p).round() as usize]
}

#[tokio::main]
async fn main() -> anyhow::Result<()> {
    let a = Args::parse();
    let http = reqwest::Client::builder().pool_max_idle_per_host(256).build()?;
    let mut ids = Vec::new();
    for p in [&a.source, &a.target] {
        let r: Value = http.post(format!("{}/v1/meshes", a.base)).body(std::fs::read(p)?).send().await?.json().await?;
        ids.push(r["id"].as_str().ok_or_else(|| anyhow::anyhow!("upload failed: {r}"))?.to_string());
    }
    let anchors: Vec<[u64; 2]> = a
        .anchors
        .split(',')
        .map(|p| {
            let (s, t) = p.split_once(':').unwrap_or((p, p));
            Ok([s.trim().parse()?, t.trim().parse()?])
        })
        .collect::<anyhow::Result<_>>()?;
    let body = json!({"source": ids[0], "target": ids[1], "spec": {"method": "voronoi", "anchors": anchors}});
    let run = std::process::id();

    // Phase 1: concurrent submissions with retries.
    let t0 = Instant::now();
    let per = a.submissions.div_ceil(a.clients);
    let mut tasks = Vec::new();
    for c in 0..a.clients {
        let (http, base, body) = (http.clone(), a.base.clone(), body.clone());
        let n = per.min(a.submissions.saturating_sub(c * per));
        tasks.push(tokio::spawn(async move {
            let mut got = Vec::new();
            let mut mismatched_retries = 0;
            for i in 0..n {
                let key = format!("load-{run}-{c}-{i}");
                let send = || http.post(format!("{base}/v1/jobs")).header("Idempotency-Key", &key).json(&body).send();
                let r = send().await?;
                anyhow::ensure!(r.status() == 202, "submit: HTTP {}", r.status());
                let id = r.json::<Value>().await?["id"].as_str().unwrap_or_default().to_string();
                if (c + i) % 5 == 0 {
                    let again = send().await?.json::<Value>().await?;
                    if again["id"].as_str() != Some(id.as_str()) {
                        mismatched_retries += 1;
                    }
                }
                got.push(id);
            }
            Ok::<_, anyhow::Error>((got, mismatched_retries))
        }));
    }
    let (mut submitted, mut mismatched) = (Vec::new(), 0);
    for t in tasks {
        let (g, m) = t.await??;
        submitted.extend(g);
        mismatched += m;
    }
    let submit_secs = t0.elapsed().as_secs_f64();
    let mut listed = Vec::new();
    let mut cursor: Option<String> = None;
    loop {
        let mut url = format!("{}/v1/jobs?limit=500", a.base);
        if let Some(c) = &cursor {
            url.push_str(&format!("&cursor={c}"));
        }
        let page: Value = http.get(url).send().await?.json().await?;
        for j in page["jobs"].as_array().into_iter().flatten() {
            listed.push(j["id"].as_str().unwrap_or_default().to_string());
        }
        match page["next_cursor"].as_str() {
            Some(c) => cursor = Some(c.to_string()),
            None => break,
        }
    }
    let sub: HashSet<&String> = submitted.iter().collect();
    let lis: HashSet<&String> = listed.iter().collect();
    let lost = sub.difference(&lis).count();
    let extra = lis.difference(&sub).count();
    let duplicated = listed.len() - lis.len();

    // Phase 2: status polling.
    let deadline = Instant::now() + Duration::from_secs_f64(a.poll_secs);
    let mut pollers = Vec::new();
    for p in 0..a.pollers {
        let (http, base) = (http.clone(), a.base.clone());
        let ids = submitted.clone();
        pollers.push(tokio::spawn(async move {
            let (mut lat, mut errors, mut k) = (Vec::with_capacity(1 << 16), 0u64, p * 7919);
            while Instant::now() < deadline {
                let id = &ids[k % ids.len()];
                k += 31;
                let t = Instant::now();
                match http.get(format!("{base}/v1/jobs/{id}")).send().await {
                    Ok(r) if r.status() == 200 => {
                        let _ = r.bytes().await;
                        lat.push(t.elapsed().as_secs_f64() * 1e3);
                    }
                    _ => errors += 1,
                }
            }
            (lat, errors)
        }));
    }
    let (mut lat, mut errors) = (Vec::new(), 0);
    for p in pollers {
        let (l, e) = p.await?;
        lat.extend(l);
        errors += e;
    }
    lat.sort_by(f64::total_cmp);
    let running = http.get(format!("{}/v1/jobs?state=running&limit=500", a.base)).send().await?.json::<Value>().await?;
    let report = json!({
        "submissions": submitted.len(), "clients": a.clients, "submit_secs": submit_secs,
        "listed": listed.len(), "lost": lost, "duplicated": duplicated, "unexpected": extra,
        "retries_with_a_different_id": mismatched,
        "poll": {"pollers": a.pollers, "secs": a.poll_secs, "requests": lat.len(), "errors": errors,
                 "req_per_sec": lat.len() as f64 / a.poll_secs,
                 "p50_ms": pct(&lat, 0.5), "p90_ms": pct(&lat, 0.9), "p99_ms": pct(&lat, 0.99), "max_ms": lat.last()},
        "running_after_poll": running["jobs"].as_array().map_or(0, Vec::len),
    });
    println!("{}", serde_json::to_string_pretty(&report)?);
    anyhow::ensure!(lost == 0 && duplicated == 0 && extra == 0 && mismatched == 0, "jobs lost or duplicated");
    Ok(())
}
