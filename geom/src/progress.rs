//! Progress reporting and cooperative cancellation: long loops call [`Progress::report`]
//! and return `Error::Cancelled` when [`Progress::cancelled`] says so.

use crate::error::{Error, Result};

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
}

/// Ignores progress and never cancels.
#[derive(Debug, Default, Clone, Copy)]
pub struct NoProgress;

impl Progress for NoProgress {
    fn report(&mut self, _stage: &str, _fraction: f64) {}
}
