//! The connection loop (instead of `axum::serve`, which has neither timeouts nor a limit):
//! - a connection must send its first request within the header read timeout, and HTTP/1
//!   request headers must arrive within it (hyper's timer), so half-sent requests are closed;
//! - at most `max_connections` at once: at the limit the oldest connection with no request in
//!   flight (a slow or idle client) is closed to admit the new one, so slow clients cannot
//!   starve `/healthz`; with every connection busy the new one is closed at once;
//! - on shutdown no new connections; each connection finishes its requests (watch streams end
//!   on [`crate::stopping::Stopping`]), and whatever is still open after the grace period is
//!   closed: shutdown is bounded whatever clients do.

use axum::Router;
use axum::body::Body;
use axum::extract::Request;
use http_body_util::BodyExt;
use hyper_util::rt::{TokioExecutor, TokioIo, TokioTimer};
use hyper_util::server::conn::auto::Builder;
use std::collections::BTreeMap;
use std::future::Future;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Duration;
use tokio::net::TcpListener;
use tokio::sync::{Notify, watch};
use tower::ServiceExt;

/// Timeouts and limits of the connection loop.
#[derive(Debug, Clone)]
pub struct ServeConfig {
    /// A new connection's first request, and every HTTP/1 request's headers, within this.
    pub header_read_timeout: Duration,
    /// Open connections at most.
    pub max_connections: usize,
    /// After the shutdown signal, how long open connections may take to finish.
    pub grace: Duration,
}

/// One open connection, as admission sees it.
struct Conn {
    in_flight: AtomicUsize,
    served: AtomicBool,
    close: Notify,
}

/// Counts a request in flight until its response body is done (or dropped).
struct InFlight(Arc<Conn>);

impl Drop for InFlight {
    fn drop(&mut self) {
        self.0.in_flight.fetch_sub(1, Ordering::SeqCst);
    }
}

type Conns = Arc<Mutex<BTreeMap<u64, Arc<Conn>>>>;

/// Admits a new connection: under the limit, or by closing the oldest one with no request in
/// flight. `None`: every connection is busy.
fn admit(conns: &Conns, id: u64, max: usize) -> Option<Arc<Conn>> {
    let mut map = conns.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    if map.len() >= max.max(1) {
        let idle = map.iter().find(|(_, c)| c.in_flight.load(Ordering::SeqCst) == 0).map(|(&k, _)| k)?;
        if let Some(c) = map.remove(&idle) {
            c.close.notify_one();
            metrics::counter!("surfmap_connections_evicted_total").increment(1);
        }
    }
    let c = Arc::new(Conn { in_flight: AtomicUsize::new(0), served: AtomicBool::new(false), close: Notify::new() });
    map.insert(id, c.clone());
    Some(c)
}

/// Serves `app` on `listener` until `signal`, then drains within the grace period.
///
/// # Errors
/// None today (accept errors such as running out of descriptors are logged and retried).
pub async fn serve(
    listener: TcpListener,
    app: Router,
    cfg: ServeConfig,
    signal: impl Future<Output = ()> + Send,
) -> std::io::Result<()> {
    let conns: Conns = Arc::default();
    let (stop_tx, stop_rx) = watch::channel(false);
    let mut tasks = tokio::task::JoinSet::new();
    let mut next_id = 0u64;
    tokio::pin!(signal);
    loop {
        let sock = tokio::select! {
            r = listener.accept() => match r {
                Ok((sock, _)) => sock,
                Err(e) => {
                    tracing::warn!("accept: {e}");
                    tokio::time::sleep(Duration::from_millis(20)).await;
                    continue;
                }
            },
            () = &mut signal => break,
            Some(_) = tasks.join_next(), if !tasks.is_empty() => continue,
        };
        next_id += 1;
        let Some(conn) = admit(&conns, next_id, cfg.max_connections) else {
            metrics::counter!("surfmap_connections_refused_total").increment(1);
            continue;
        };
        let _ = sock.set_nodelay(true);
        tasks.spawn(connection(sock, app.clone(), conn, (conns.clone(), next_id), cfg.clone(), stop_rx.clone()));
    }
    drop(listener);
    let _ = stop_tx.send(true);
    let drain = async { while tasks.join_next().await.is_some() {} };
    if tokio::time::timeout(cfg.grace, drain).await.is_err() {
        tracing::warn!(open = tasks.len(), "grace period over: closing the connections still open");
        tasks.abort_all();
        while tasks.join_next().await.is_some() {}
    }
    Ok(())
}

async fn connection(
    sock: tokio::net::TcpStream,
    app: Router,
    conn: Arc<Conn>,
    (conns, id): (Conns, u64),
    cfg: ServeConfig,
    mut stop: watch::Receiver<bool>,
) {
    let svc = {
        let conn = conn.clone();
        tower::service_fn(move |req: Request<hyper::body::Incoming>| {
            conn.served.store(true, Ordering::SeqCst);
            conn.in_flight.fetch_add(1, Ordering::SeqCst);
            let guard = InFlight(conn.clone());
            let app = app.clone();
            async move {
                let res = app.oneshot(req.map(Body::new)).await?;
                Ok::<_, std::convert::Infallible>(res.map(|b| {
                    Body::new(b.map_frame(move |f| {
                        let _held = &guard;
                        f
                    }))
                }))
            }
        })
    };
    let mut builder = Builder::new(TokioExecutor::new());
    builder.http1().timer(TokioTimer::new()).header_read_timeout(cfg.header_read_timeout);
    builder.http2().timer(TokioTimer::new());
    let served =
        builder.serve_connection_with_upgrades(TokioIo::new(sock), hyper_util::service::TowerToHyperService::new(svc));
    tokio::pin!(served);
    let first_request = tokio::time::sleep(cfg.header_read_timeout);
    tokio::pin!(first_request);
    // The first-request deadline is checked once, when it passes: a connection served by then
    // keeps going (a `select!` branch's condition is read when the `select!` starts, so a
    // request that arrives while it waits does not disable the branch).
    let mut first_checked = false;
    let mut stopping = *stop.borrow();
    if stopping {
        served.as_mut().graceful_shutdown();
    }
    loop {
        tokio::select! {
            _ = served.as_mut() => break,
            () = conn.close.notified() => break,
            () = &mut first_request, if !first_checked => {
                first_checked = true;
                if !conn.served.load(Ordering::SeqCst) {
                    break;
                }
            }
            _ = stop.changed(), if !stopping => {
                stopping = true;
                if !conn.served.load(Ordering::SeqCst) {
                    break;
                }
                served.as_mut().graceful_shutdown();
            }
        }
    }
    conns.lock().unwrap_or_else(std::sync::PoisonError::into_inner).remove(&id);
}
