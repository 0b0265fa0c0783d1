//! What a job's method hands to its last phase, and what a finished job reports
//! (`metrics.json`, written once by [`crate::pipeline::finish`]).

use super::homology::{self, features};
use super::{layout, quad, spherical};
use crate::pipeline::common::{Artifact, PairReport};
use serde::Serialize;

/// A finished job's report (`metrics.json`), one type per pipeline.
#[derive(Debug, Clone, Serialize)]
#[serde(untagged)]
pub enum JobReport {
    Layout(layout::LayoutMapReport),
    Homology(homology::HomologyMapReport),
    Features(features::FeatureMapReport),
    Quad(quad::QuadReport),
    Spherical(spherical::SphericalMapReport),
    /// A pair job on meshes in several parts.
    Parts(Box<PartsReport>),
}

/// The whole pair's metrics and each part pair's own report.
#[derive(Debug, Clone, Serialize)]
pub struct PartsReport {
    #[serde(flatten)]
    pub pair: PairReport,
    /// `[source part, target part]` per mapped pair, in source part order.
    pub part_pairs: Vec<[usize; 2]>,
    pub parts: Vec<JobReport>,
}

/// What a method produced: its report (with both maps, for a pair method) and its own
/// artifacts. `metrics.json` and the outputs in the inputs' own layouts are not among them.
pub struct MethodOutput {
    pub report: JobReport,
    pub artifacts: Vec<Artifact>,
}

impl JobReport {
    /// Both directions' metrics of a pair job.
    pub fn pair(&self) -> Option<&PairReport> {
        match self {
            JobReport::Layout(r) => Some(&r.pair),
            JobReport::Homology(r) => Some(&r.pair),
            JobReport::Features(r) => Some(&r.pair),
            JobReport::Parts(r) => Some(&r.pair),
            JobReport::Spherical(r) => Some(&r.pair),
            JobReport::Quad(_) => None,
        }
    }

    /// [`JobReport::pair`], mutably.
    pub fn pair_mut(&mut self) -> Option<&mut PairReport> {
        match self {
            JobReport::Layout(r) => Some(&mut r.pair),
            JobReport::Homology(r) => Some(&mut r.pair),
            JobReport::Features(r) => Some(&mut r.pair),
            JobReport::Parts(r) => Some(&mut r.pair),
            JobReport::Spherical(r) => Some(&mut r.pair),
            JobReport::Quad(_) => None,
        }
    }

    /// Milliseconds per stage.
    pub fn timings_ms(&self) -> &[(String, f64)] {
        match self {
            JobReport::Quad(r) => &r.timings_ms,
            _ => self.pair().map_or(&[], |p| &p.timings_ms),
        }
    }
}
