//! Progress reporting and cooperative cancellation: long loops call [`Progress::report`]
//! and return `Error::Cancelled` when [`Progress::cancelled`] says so.

use crate::error::{Error, Result};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};

/// A cancellation flag shared across threads and owners.
#[derive(Debug, Clone, Default)]
pub struct CancelToken(Arc<AtomicBool>);

impl CancelToken {
    pub fn cancel(&self) {
        self.0.store(true, Ordering::Relaxed);
    }
    pub fn is_cancelled(&self) -> bool {
        self.0.load(Ordering::Relaxed)
    }
}

/// Receives stage and fraction updates and answers whether to stop.
pub trait Progress {
    /// The current stage and its completed fraction in [0, 1].
    fn report(&mut self, stage: &str, fraction: f64);
    /// True when the caller wants the work to stop.
    fn cancelled(&self) -> bool {
        false
    }
    /// `Err(Cancelled)` when cancelled.
    ///
    /// # Errors
    /// `Error::Cancelled`.
    fn check(&self) -> Result<()> {
        if self.cancelled() { Err(Error::Cancelled) } else { Ok(()) }
    }
    /// The token behind [`Progress::cancelled`], when there is one.
    fn token(&self) -> Option<CancelToken> {
        None
    }
    /// A progress for the other half of a parallel split: it reports nothing but stops when
    /// this one is cancelled.
    fn silent(&self) -> Silent {
        Silent(self.token())
    }
}

/// Reports nothing; cancelled with its token (see [`Progress::silent`]).
#[derive(Debug, Default, Clone)]
pub struct Silent(pub Option<CancelToken>);

impl Progress for Silent {
    fn report(&mut self, _stage: &str, _fraction: f64) {}
    fn cancelled(&self) -> bool {
        self.0.as_ref().is_some_and(CancelToken::is_cancelled)
    }
    fn token(&self) -> Option<CancelToken> {
        self.0.clone()
    }
}

/// Ignores progress and never cancels.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn report(&mut self, _stage: &str, _fraction: f64) {}
}
