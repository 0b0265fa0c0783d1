//! The server's "stopping" signal as the service sees it: open watch streams (SSE, gRPC
//! `WatchJob`) send the job once more and end when it fires, so graceful shutdown is not held
//! open by a client that never hangs up.

use std::sync::Arc;
use tokio::sync::watch;

/// Fires once, on shutdown; clones share it.
#[derive(Debug, Clone)]
pub struct Stopping {
    rx: watch::Receiver<bool>,
    /// Keeps the sender of [`Stopping::never`] alive (a dropped sender would read as fired).
    _never: Option<Arc<watch::Sender<bool>>>,
}

impl Stopping {
    /// Follows `rx` (true = stopping). A sender dropped without sending true never fires.
    pub fn new(rx: watch::Receiver<bool>) -> Stopping {
        Stopping { rx, _never: None }
    }

    /// A signal that never fires (tests, tools).
    pub fn never() -> Stopping {
        let (tx, rx) = watch::channel(false);
        Stopping { rx, _never: Some(Arc::new(tx)) }
    }

    /// True once the server is stopping.
    pub fn is_set(&self) -> bool {
        *self.rx.borrow()
    }

    /// Resolves when the server starts stopping.
    pub async fn fired(&self) {
        let mut rx = self.rx.clone();
        if rx.wait_for(|&v| v).await.is_err() {
            std::future::pending::<()>().await;
        }
    }
}

impl Default for Stopping {
    fn default() -> Self {
        Stopping::never()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    #[tokio::test]
    async fn fires_once_sent_and_never_on_a_dropped_sender() {
        let (tx, rx) = watch::channel(false);
        let s = Stopping::new(rx);
        assert!(!s.is_set());
        let w = tokio::spawn({
            let s = s.clone();
            async move { s.fired().await }
        });
        tx.send(true).unwrap();
        tokio::time::timeout(Duration::from_secs(1), w).await.unwrap().unwrap();
        assert!(s.is_set());
        let (tx, rx) = watch::channel(false);
        drop(tx);
        let quiet = Stopping::new(rx);
        assert!(tokio::time::timeout(Duration::from_millis(50), quiet.fired()).await.is_err());
        assert!(tokio::time::timeout(Duration::from_millis(50), Stopping::never().fired()).await.is_err());
    }
}
