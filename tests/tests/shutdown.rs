//! The server against clients that hold on (issue 51): SIGTERM ends open SSE streams with a
//! final event and exits within the grace period; half-sent requests are closed after the
//! header read timeout, streams are not; a crowd of slow connections leaves `/healthz` answering at once.

mod common;

use common::{Api, Env};
use serde_json::json;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

fn addr(base: &str) -> String {
    base.trim_start_matches("http://").to_string()
}

/// A connection that sends half a request and stops.
fn half_sent(addr: &str) -> TcpStream {
    let mut s = TcpStream::connect(addr).expect("connect");
    s.write_all(b"GET /healthz HTTP/1.1\r\nHost: x\r\n").expect("write");
    s
}

/// Uploads a sphere pair and queues a job no worker takes.
async fn queued_job(api: &Api) -> String {
    let s = geom::mesh::shapes::icosphere(2);
    let t = s.with_positions(s.positions().iter().map(|p| geom::mesh::P3::from(p.coords * 1.5)).collect()).unwrap();
    let (_, a) = api.upload_bytes(geom::io::write(&s, geom::io::Format::Off)).await;
    let (_, b) = api.upload_bytes(geom::io::write(&t, geom::io::Format::Off)).await;
    let spec = json!({"method": "voronoi", "anchors": [[0, 0], [5, 5], [9, 9]]});
    let (st, j) = api.submit(a["id"].as_str().unwrap(), b["id"].as_str().unwrap(), &spec).await;
    assert_eq!(st, 202, "{j}");
    j["id"].as_str().unwrap().to_string()
}

#[tokio::test]
async fn sigterm_ends_an_open_sse_stream_and_exits_within_the_grace_period() {
    let env = Env::sqlite();
    let (mut server, base) = env.server(&["--workers", "0", "--shutdown-grace-secs", "3"]);
    let api = Api::new(&base);
    let id = queued_job(&api).await;
    // An SSE stream held open, a half-sent request and an idle connection.
    let mut sse = TcpStream::connect(addr(&base)).unwrap();
    write!(sse, "GET /v1/jobs/{id}/events HTTP/1.1\r\nHost: x\r\n\r\n").unwrap();
    sse.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    let mut seen = Vec::new();
    let mut buf = [0u8; 4096];
    while !String::from_utf8_lossy(&seen).contains("event: job") {
        let n = sse.read(&mut buf).expect("the first event");
        assert!(n > 0, "stream closed early");
        seen.extend_from_slice(&buf[..n]);
    }
    let _half = half_sent(&addr(&base));
    let _idle = TcpStream::connect(addr(&base)).unwrap();
    tokio::time::sleep(Duration::from_millis(300)).await;

    let t0 = Instant::now();
    server.signal("TERM");
    // The stream gets the job once more and `event: shutdown`, then ends.
    loop {
        match sse.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => seen.extend_from_slice(&buf[..n]),
            Err(e) => panic!("the stream did not end: {e}"),
        }
    }
    let text = String::from_utf8_lossy(&seen);
    assert!(text.matches("event: job").count() >= 2, "{text}");
    assert!(text.contains("event: shutdown") && text.contains("shutting_down"), "{text}");
    let status = server.wait_exit(Duration::from_secs(4)).unwrap_or_else(|| panic!("no exit within grace + 1 s"));
    assert!(status.success(), "{status:?}\n{}", server.log_text());
    assert!(t0.elapsed() < Duration::from_secs(4), "{:?}", t0.elapsed());
}

/// The header read timeout bounds a connection's first request, not a response it serves: an
/// SSE stream opened at once stays open well past it (it used to be cut at that moment).
#[tokio::test]
async fn an_event_stream_outlives_the_header_read_timeout() {
    let env = Env::sqlite();
    let (_server, base) = env.server(&["--workers", "0", "--header-read-timeout-secs", "1"]);
    let api = Api::new(&base);
    let id = queued_job(&api).await;
    let mut sse = TcpStream::connect(addr(&base)).unwrap();
    write!(sse, "GET /v1/jobs/{id}/events HTTP/1.1\r\nHost: x\r\n\r\n").unwrap();
    let mut buf = [0u8; 4096];
    let n = sse.read(&mut buf).expect("the first event");
    assert!(String::from_utf8_lossy(&buf[..n]).contains("200 OK"), "{}", String::from_utf8_lossy(&buf[..n]));
    // Nothing more comes for 15 s (the keep-alive comment); 3.5 s of silence, not an end.
    sse.set_read_timeout(Some(Duration::from_millis(3500))).unwrap();
    let t0 = Instant::now();
    loop {
        match sse.read(&mut buf) {
            Ok(0) => panic!("the stream was closed after {:?}", t0.elapsed()),
            Ok(_) => continue,
            Err(e) => {
                assert!(matches!(e.kind(), std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut), "{e}");
                break;
            }
        }
    }
    assert!(t0.elapsed() >= Duration::from_secs(3), "{:?}", t0.elapsed());
}

#[tokio::test]
async fn half_sent_requests_are_closed_after_the_header_read_timeout() {
    let env = Env::sqlite();
    let (_server, base) = env.server(&["--workers", "0", "--header-read-timeout-secs", "1"]);
    let mut slow = half_sent(&addr(&base));
    let mut silent = TcpStream::connect(addr(&base)).unwrap();
    let t0 = Instant::now();
    for s in [&mut slow, &mut silent] {
        s.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let mut buf = [0u8; 1024];
        // Closed (EOF or reset), possibly after a 408: never left open.
        loop {
            match s.read(&mut buf) {
                Ok(0) | Err(_) => break,
                Ok(_) => {}
            }
        }
    }
    assert!(t0.elapsed() < Duration::from_secs(4), "closed after {:?}", t0.elapsed());
}

#[tokio::test]
async fn eleven_hundred_slow_connections_leave_healthz_answering() {
    // The client side needs 1,100 descriptors too.
    let _ = rlimit::increase_nofile_limit(4096);
    let env = Env::sqlite();
    let (_server, base) =
        env.server(&["--workers", "0", "--max-connections", "256", "--header-read-timeout-secs", "30"]);
    let a = addr(&base);
    let slow: Vec<TcpStream> = (0..1100).map(|_| half_sent(&a)).collect();
    let http = reqwest::Client::builder().timeout(Duration::from_secs(1)).build().unwrap();
    for _ in 0..3 {
        let t0 = Instant::now();
        let r = http.get(format!("{base}/healthz")).send().await.expect("/healthz within 1 s");
        assert_eq!(r.status(), 200);
        assert!(t0.elapsed() < Duration::from_secs(1), "{:?}", t0.elapsed());
    }
    drop(slow);
}
