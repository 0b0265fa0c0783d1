//! The two face tiers of the small-ball search ([`super::small_ball`]): the small faces, by
//! their largest radius, and the few large faces, with a k-d tree of their own.

use crate::error::{Error, Result};
use kiddo::ImmutableKdTree;

/// A face is large when its radius exceeds this multiple of the median.
const LARGE: f64 = 2.0;

/// Most large faces, as a fraction of all, for the tiers to pay (`1 / LARGE_SHARE`).
const LARGE_SHARE: usize = 16;

/// The two face tiers.
pub(super) struct Tiers {
    /// The largest radius of a small face.
    pub(super) small_max: f64,
    /// The largest radius of any face.
    pub(super) all_max: f64,
    /// Centroids of the large faces, and their face ids.
    pub(super) large: Option<(ImmutableKdTree<f64, 3>, Vec<u32>)>,
}

impl Tiers {
    /// The tiers of faces with these centroids and radii, or `None` when more than one face in
    /// [`LARGE_SHARE`] is large.
    ///
    /// # Errors
    /// `Error::Internal` if the large faces' tree cannot be built.
    pub(super) fn new(centroids: &[[f64; 3]], radius: &[f64]) -> Result<Option<Self>> {
        if radius.is_empty() {
            return Ok(None);
        }
        let mut sorted = radius.to_vec();
        let median = *sorted.select_nth_unstable_by(radius.len() / 2, f64::total_cmp).1;
        let cut = LARGE * median;
        let large: Vec<u32> = (0..radius.len()).filter(|&f| radius[f] > cut).map(|f| f as u32).collect();
        if large.len() * LARGE_SHARE > radius.len() {
            return Ok(None);
        }
        let small_max = radius.iter().copied().filter(|&r| r <= cut).fold(0.0, f64::max);
        let all_max = radius.iter().copied().fold(0.0, f64::max);
        let large = if large.is_empty() {
            None
        } else {
            let pts: Vec<[f64; 3]> = large.iter().map(|&f| centroids[f as usize]).collect();
            let tree =
                ImmutableKdTree::new_from_slice(&pts).map_err(|e| Error::Internal(format!("k-d tree: {e:?}")))?;
            Some((tree, large))
        };
        Ok(Some(Self { small_max, all_max, large }))
    }

    /// Whether some faces are large.
    #[cfg(test)]
    pub(super) fn has_large(&self) -> bool {
        self.large.is_some()
    }
}
