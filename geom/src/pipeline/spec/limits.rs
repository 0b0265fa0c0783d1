//! The size limits of a job, one table for every method: what a spec may ask for at most.
//! Checked before a job is queued ([`crate::pipeline::spec::check`], [`crate::pipeline::spec::ranges`]).

/// Most anchors (anchor rows of a `quad` job) a job may have.
pub const MAX_ANCHORS: usize = 4096;
/// Most feature curves a job may have.
pub const MAX_FEATURES: usize = 256;
/// Most models one `quad` job may remesh together.
pub const MAX_MODELS: usize = 16;
/// Most surface samples per direction for the distortion metrics (10× the evaluator's).
pub const MAX_METRIC_SAMPLES: usize = 1_000_000;
/// Most edge nodes per mesh edge in the layout construction.
pub const MAX_EDGE_NODES: u32 = 256;
/// Most OBJ frames a `quad` morph writes.
pub const MAX_MORPH_FRAMES: usize = 1_000;
