//! Path straightening, the post-process Kraevoy & Sheffer apply to their layouts and Kwok et al.
//! apply to both methods for a fair comparison: each path in turn is lifted and re-traced as the
//! shortest path that leaves and enters its anchors in the same sectors, so it stays between the
//! same neighbours (the rotation system, hence every patch, is unchanged) but runs straight
//! across the two patches beside it. Run on both meshes, it makes corresponding paths follow
//! the same rule everywhere.

use super::tracer::Tracer;
use crate::error::Result;
use crate::progress::Progress;

/// Re-traces every path, `rounds` times or until none gets shorter. Returns how many re-traces
/// shortened a path.
///
/// # Errors
/// `Cancelled`; `Error::Internal` if a path cannot be restored.
pub fn straighten(t: &mut Tracer, rounds: usize, progress: &mut dyn Progress) -> Result<usize> {
    let mut changed = 0;
    for r in 0..rounds {
        let mut this_round = 0;
        let n = t.paths().len() as u32;
        for id in 0..n {
            progress.check()?;
            if id % 32 == 0 {
                progress.report(
                    crate::progress::Stage::Straighten,
                    (r as f64 + f64::from(id) / f64::from(n.max(1))) / rounds as f64,
                );
            }
            if t.retrace(id)? {
                this_round += 1;
            }
        }
        changed += this_round;
        if this_round == 0 {
            break;
        }
    }
    Ok(changed)
}
