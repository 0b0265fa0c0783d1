//! The one call the CLI and the worker share: a validated [`JobSpec`] and two meshes in,
//! named artifacts and metrics out. Nothing here touches files or sockets; callers write the
//! artifacts wherever they keep them.

mod artifacts;
mod run;
mod run_homology;
mod spec;

pub use run::{Artifact, MapReport, run_map};
pub use spec::{JobSpec, MAX_ANCHORS, MapOptions, Method};
