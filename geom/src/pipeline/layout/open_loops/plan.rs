//! What the open-loop plan hands on: the closed meshes with their anchors ([`OpenPlan`]) and,
//! per pair of loops, how it was mapped ([`BoundaryReport`]).

use crate::domain::loops::LoopAnchors;
use crate::mesh::VertexId;
use crate::mesh::cap::{CapLoop, Capped};
use serde::Serialize;

/// A boundary loop named by its first vertex and its length in vertices.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LoopName {
    pub first_vertex: u32,
    pub vertices: usize,
}

/// How one pair of loops was mapped (`metrics.json`, `boundaries`).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct BoundaryReport {
    pub source_loop: LoopName,
    pub target_loop: LoopName,
    /// `anchors` (the job's anchors on the loop), `boundaries` (a `boundaries` row) or
    /// `nearest_anchor` (the loop had neither).
    pub paired_by: &'static str,
    /// The job's anchors on the loop (indices into its anchor list).
    pub anchors: Vec<usize>,
    /// Loop anchors added at equal arc-length fractions between the given ones.
    pub added: usize,
    /// Loop vertices whose image is not on the other mesh's loop, both ways (0 when done).
    pub off_loop: [usize; 2],
}

/// The closed meshes of a job on open meshes, with every anchor the layout needs.
pub struct OpenPlan {
    pub source: Capped,
    pub target: Capped,
    /// Anchors on the closed meshes: the job's, then the added loop anchors, then the apexes.
    pub sa: Vec<VertexId>,
    pub ta: Vec<VertexId>,
    /// The job's own anchors (the first of `sa` / `ta`).
    pub job_anchors: usize,
    pub(super) s_loops: Vec<LoopAnchors>,
    pub(super) t_loops: Vec<LoopAnchors>,
    /// Interior angle at each vertex of the open meshes (the loops' turning, for alignment).
    pub(super) angles: [Vec<f64>; 2],
    pub(super) report: Vec<BoundaryReport>,
}

pub(super) fn name(l: &CapLoop) -> LoopName {
    LoopName { first_vertex: l.vertices[0].0, vertices: l.vertices.len() }
}
