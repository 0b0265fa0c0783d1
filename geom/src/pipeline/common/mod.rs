//! What every method's pipeline shares: artifacts, the stage clock, the two-halves split, the
//! pair report every pair method writes, the last stages of each direction ([`relax`]), a folded
//! direction replaced by the other's inverse ([`inverse`]) and the meta-mesh outputs
//! ([`meta_mesh`]). Method files import this module and nothing else of `pipeline` but the spec.

pub mod artifacts;
pub mod inverse;
pub mod meta_mesh;
pub mod relax;

use crate::crossparam::smooth::SmoothReport;
use crate::error::{Error, Result};
use crate::map::SurfaceMap;
use crate::mesh::Mesh;
use crate::metrics::MapMetrics;
use serde::Serialize;
use std::time::Instant;

/// One output file: its name, media type and bytes.
#[derive(Debug, Clone)]
pub struct Artifact {
    pub name: String,
    pub content_type: &'static str,
    pub bytes: Vec<u8>,
}

/// Milliseconds per stage, in order.
pub struct Clock(Instant, Vec<(String, f64)>);

impl Clock {
    pub fn start() -> Clock {
        Clock(Instant::now(), Vec::new())
    }

    /// Ends the stage `stage` now.
    pub fn lap(&mut self, stage: &str) {
        let now = Instant::now();
        self.1.push((stage.to_string(), (now - self.0).as_secs_f64() * 1e3));
        self.0 = now;
    }

    /// Milliseconds since the last lap.
    pub fn elapsed_ms(&self) -> f64 {
        self.0.elapsed().as_secs_f64() * 1e3
    }

    /// The stages and their total.
    pub fn finish(mut self) -> Vec<(String, f64)> {
        let total: f64 = self.1.iter().map(|x| x.1).sum();
        self.1.push(("total".into(), total));
        self.1
    }
}

/// Runs `side` on a scoped thread while `main` runs here: the source and target halves of a
/// stage are independent. The side half reports no progress (the main half does).
///
/// # Errors
/// `Internal` when the side thread panicked.
pub fn both<A: Send, B>(side: impl FnOnce() -> A + Send, main: impl FnOnce() -> B) -> Result<(B, A)> {
    std::thread::scope(|sc| {
        let h = sc.spawn(side);
        let b = main();
        Ok((b, h.join().map_err(|_| Error::Internal("worker thread panicked".into()))?))
    })
}

/// What every pair job measures: the maps both ways under the evaluator's definitions, what
/// the relaxation did and the time per stage. Each method's report flattens it in.
#[derive(Debug, Clone, Serialize)]
pub struct PairReport {
    pub method: &'static str,
    pub anchors: usize,
    pub source_vertices: usize,
    pub target_vertices: usize,
    pub source_to_target: MapMetrics,
    pub target_to_source: MapMetrics,
    /// Milliseconds per stage.
    pub timings_ms: Vec<(String, f64)>,
    pub smoothing: SmoothReport,
    /// Vertex-map artifacts not written because that direction folds (only when a fold-free
    /// meta-mesh pair was built instead; otherwise a folded map fails the job).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub withheld: Vec<String>,
    /// The direction that folded and was replaced by the inverse of the other
    /// (`"source_to_target"` or `"target_to_source"`, see [`inverse`]), if any.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inverted: Option<&'static str>,
    /// The maps themselves (not in `metrics.json`), for the outputs `run_job` builds in the
    /// inputs' own layouts.
    #[serde(skip)]
    pub maps: Option<std::sync::Arc<PairMaps>>,
    /// Anchors given as surface points: the vertex each became, its distance from the given
    /// position, whether it was inserted.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub anchor_points: Vec<crate::pipeline::plan::anchor_points::AnchorSnap>,
    /// For a job that named no method (`auto`): the method that ran, and why.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub auto: Option<crate::pipeline::spec::auto::AutoChoice>,
}

/// Both vertex maps of a pair job.
#[derive(Debug)]
pub struct PairMaps {
    pub s2t: SurfaceMap,
    pub t2s: SurfaceMap,
}

impl PairReport {
    pub fn new(
        method: &'static str,
        anchors: usize,
        meshes: (&Mesh, &Mesh),
        metrics: (MapMetrics, MapMetrics),
        smoothing: SmoothReport,
    ) -> PairReport {
        PairReport {
            method,
            anchors,
            source_vertices: meshes.0.n_vertices(),
            target_vertices: meshes.1.n_vertices(),
            source_to_target: metrics.0,
            target_to_source: metrics.1,
            timings_ms: Vec::new(),
            smoothing,
            withheld: Vec::new(),
            inverted: None,
            maps: None,
            anchor_points: Vec::new(),
            auto: None,
        }
    }

    /// The report carrying both maps.
    pub fn with_maps(self, s2t: SurfaceMap, t2s: SurfaceMap) -> PairReport {
        PairReport { maps: Some(std::sync::Arc::new(PairMaps { s2t, t2s })), ..self }
    }
}

/// Distance from the surface, relative to the bounding-box diagonal, within which an image is
/// exact to rounding as the evaluator reads it (a visible image).
pub const VISIBLE: f64 = 1e-9;

/// Whether a direction's images all lie within `rel` times the diagonal of `onto` (the mesh
/// they lie on) of its surface, as the evaluator reads it.
pub fn on_surface(m: &MapMetrics, onto: &Mesh, rel: f64) -> bool {
    m.off_surface_max <= rel * onto.bbox_diagonal()
}

/// A JSON artifact, pretty-printed.
///
/// # Errors
/// `Internal` if the value does not serialize.
pub fn json_artifact(name: &str, v: &impl Serialize) -> Result<Artifact> {
    let bytes = serde_json::to_vec_pretty(v).map_err(|e| Error::Internal(e.to_string()))?;
    Ok(Artifact { name: name.into(), content_type: "application/json", bytes })
}
