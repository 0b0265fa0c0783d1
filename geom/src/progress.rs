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

/// A stage of a job, as progress reports name it. The names (`Stage::name`) are what the
/// service shows in a job's `stage` field and what a job's child process prints.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Stage {
    Layout,
    LayoutSource,
    LayoutTarget,
    LayoutGreedy,
    Straighten,
    Parameterize,
    Compose,
    Global,
    Optimize,
    Smooth,
    Basis,
    FeatureCut,
    MetaMesh,
    Partition,
    Remesh,
    Images,
    Metrics,
    Morph,
    Done,
}

impl Stage {
    /// Every stage.
    pub const ALL: [Stage; 19] = [
        Stage::Layout,
        Stage::LayoutSource,
        Stage::LayoutTarget,
        Stage::LayoutGreedy,
        Stage::Straighten,
        Stage::Parameterize,
        Stage::Compose,
        Stage::Global,
        Stage::Optimize,
        Stage::Smooth,
        Stage::Basis,
        Stage::FeatureCut,
        Stage::MetaMesh,
        Stage::Partition,
        Stage::Remesh,
        Stage::Images,
        Stage::Metrics,
        Stage::Morph,
        Stage::Done,
    ];

    /// The snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Layout => "layout",
            Stage::LayoutSource => "layout_source",
            Stage::LayoutTarget => "layout_target",
            Stage::LayoutGreedy => "layout_greedy",
            Stage::Straighten => "straighten",
            Stage::Parameterize => "parameterize",
            Stage::Compose => "compose",
            Stage::Global => "global",
            Stage::Optimize => "optimize",
            Stage::Smooth => "smooth",
            Stage::Basis => "basis",
            Stage::FeatureCut => "feature_cut",
            Stage::MetaMesh => "meta_mesh",
            Stage::Partition => "partition",
            Stage::Remesh => "remesh",
            Stage::Images => "images",
            Stage::Metrics => "metrics",
            Stage::Morph => "morph",
            Stage::Done => "done",
        }
    }

    /// The stage with this name.
    pub fn from_name(name: &str) -> Option<Stage> {
        Self::ALL.into_iter().find(|s| s.name() == name)
    }
}

impl std::fmt::Display for Stage {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.pad(self.name())
    }
}

/// Receives stage and fraction updates and answers whether to stop.
pub trait Progress {
    /// The current stage and its completed fraction in [0, 1].
    fn report(&mut self, stage: Stage, fraction: f64);
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
    fn report(&mut self, _stage: Stage, _fraction: f64) {}
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
    fn report(&mut self, _stage: Stage, _fraction: f64) {}
}
