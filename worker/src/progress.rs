//! The bridge between the pipeline's `Progress` calls (on the blocking thread) and the
//! heartbeat (on the runtime): stage names map onto one monotone job fraction.

use geom::progress::{CancelToken, Stage};
use std::sync::{Arc, Mutex};

/// Where each pipeline stage starts in the job and how much of it it spans (`quad` jobs:
/// partition -> parameterize -> remesh -> images -> metrics -> morph; `homology`: basis or
/// feature_cut -> parameterize -> compose -> smooth -> metrics -> meta_mesh). Exhaustive, so a
/// new stage cannot be left out.
fn span(stage: Stage) -> (f64, f64) {
    match stage {
        Stage::Layout => (0.0, 0.02),
        Stage::Partition => (0.0, 0.05),
        Stage::Basis | Stage::FeatureCut => (0.0, 0.10),
        Stage::LayoutSource => (0.02, 0.13),
        Stage::LayoutTarget => (0.15, 0.2),
        Stage::LayoutGreedy => (0.02, 0.33),
        Stage::Straighten => (0.35, 0.05),
        Stage::Parameterize => (0.40, 0.15),
        Stage::Compose => (0.55, 0.03),
        Stage::Global => (0.58, 0.02),
        Stage::Optimize => (0.60, 0.05),
        Stage::Smooth => (0.65, 0.15),
        Stage::Remesh => (0.60, 0.10),
        Stage::Images => (0.70, 0.10),
        Stage::Metrics => (0.80, 0.15),
        Stage::MetaMesh => (0.95, 0.03),
        Stage::Morph => (0.98, 0.02),
        Stage::Done => (1.0, 0.0),
    }
}

/// Shared between the pipeline thread and the heartbeat task.
#[derive(Debug, Clone, Default)]
pub struct Shared {
    state: Arc<Mutex<(String, f64)>>,
    cancel: CancelToken,
}

impl Shared {
    pub fn snapshot(&self) -> (String, f64) {
        self.state.lock().map(|s| s.clone()).unwrap_or_else(|p| p.into_inner().clone())
    }
    pub fn cancel(&self) {
        self.cancel.cancel();
    }
}

impl geom::progress::Progress for Shared {
    fn report(&mut self, stage: Stage, fraction: f64) {
        let (base, width) = span(stage);
        let overall = base + width * fraction.clamp(0.0, 1.0);
        if let Ok(mut s) = self.state.lock() {
            s.0 = stage.name().to_string();
            s.1 = s.1.max(overall);
        }
    }
    fn cancelled(&self) -> bool {
        self.cancel.is_cancelled()
    }
    fn token(&self) -> Option<CancelToken> {
        Some(self.cancel.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use geom::progress::Progress;

    #[test]
    fn fraction_is_monotone_and_cancel_is_seen() {
        let mut s = Shared::default();
        s.report(Stage::Smooth, 0.5);
        assert_eq!(s.snapshot(), ("smooth".to_string(), 0.725));
        s.report(Stage::Layout, 1.0);
        assert_eq!(s.snapshot().1, 0.725);
        assert!(s.check().is_ok());
        let side = s.silent();
        assert!(side.check().is_ok());
        s.clone().cancel();
        assert!(s.check().is_err());
        assert!(side.check().is_err(), "the silent half of a split sees the cancel");
    }
}
