//! The one call the CLI and the worker share: a validated [`JobSpec`] and two meshes in,
//! named artifacts and metrics out. Nothing here touches files or sockets; callers write the
//! artifacts wherever they keep them.

mod artifacts;
mod global_choice;
mod job;
mod memory;
mod ranges;
mod remesh_spec;
mod run;
mod run_features;
mod run_homology;
mod run_quad;
mod spec;

pub use job::{Job, JobOutput, METHODS, run_job};
pub use ranges::{MAX_EDGE_NODES, MAX_METRIC_SAMPLES, MAX_MORPH_FRAMES};
pub use remesh_spec::{
    Interpolation, LevelSchedule, MAX_MODELS, MorphDomain, MorphOptions, QuadMethod, QuadOptions, RemeshSpec,
};
pub use run::{Artifact, MapReport, run_map};
pub use run_quad::{RemeshReport, Remeshes, remesh_all_for_bench, run_remesh};
pub use spec::{FeatureSpec, JobSpec, MAX_ANCHORS, MAX_FEATURES, MapOptions, Method};
