//! The bridge between the pipeline's `Progress` calls (on the blocking thread) and the
//! heartbeat (on the runtime): stage names map onto one monotone job fraction.

use geom::progress::CancelToken;
use std::sync::{Arc, Mutex};

/// Where each pipeline stage starts and how much of the job it spans.
const STAGES: &[(&str, f64, f64)] = &[
    ("layout", 0.0, 0.02),
    // `quad` jobs: partition -> parameterize -> remesh -> images -> metrics -> morph.
    ("partition", 0.0, 0.05),
    ("layout_source", 0.02, 0.13),
    ("layout_target", 0.15, 0.2),
    ("layout_greedy", 0.02, 0.33),
    ("straighten", 0.35, 0.05),
    ("parameterize", 0.40, 0.15),
    ("compose", 0.55, 0.05),
    ("smooth", 0.60, 0.20),
    // The opt-in global Newton steps after the sweeps.
    ("newton", 0.78, 0.02),
    ("remesh", 0.60, 0.10),
    ("images", 0.70, 0.10),
    ("metrics", 0.80, 0.18),
    ("morph", 0.98, 0.02),
    ("done", 1.0, 0.0),
];

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
    fn report(&mut self, stage: &str, fraction: f64) {
        let overall =
            STAGES.iter().find(|s| s.0 == stage).map(|&(_, base, span)| base + span * fraction.clamp(0.0, 1.0));
        if let Ok(mut s) = self.state.lock() {
            s.0 = stage.to_string();
            if let Some(o) = overall {
                s.1 = s.1.max(o);
            }
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
        s.report("smooth", 0.5);
        assert_eq!(s.snapshot(), ("smooth".to_string(), 0.7));
        s.report("layout", 1.0);
        assert_eq!(s.snapshot().1, 0.7);
        assert!(s.check().is_ok());
        let side = s.silent();
        assert!(side.check().is_ok());
        s.clone().cancel();
        assert!(s.check().is_err());
        assert!(side.check().is_err(), "the silent half of a split sees the cancel");
    }
}
