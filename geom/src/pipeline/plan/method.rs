//! The method a plan runs: the job's spec with `auto` resolved, as the method's own spec.

use crate::error::{Error, Result};
use crate::pipeline::spec::anchor_spec::{AnchorRow, id_rows};
use crate::pipeline::spec::quad_spec::QuadSpec;
use crate::pipeline::spec::{HomologySpec, JobSpec, LayoutSpec, Method, SphericalSpec};

/// The method to run and its own spec: a [`JobSpec`] with `auto` resolved, whose vertex ids
/// are the welded meshes' and whose anchors are all vertex ids.
#[derive(Debug, Clone)]
pub enum MethodPlan {
    /// `voronoi` or `greedy`.
    Layout(Method, LayoutSpec),
    Homology(HomologySpec),
    Quad(QuadSpec),
    Spherical(SphericalSpec),
}

impl MethodPlan {
    pub(super) fn new(spec: JobSpec) -> Result<MethodPlan> {
        Ok(match spec {
            JobSpec::Voronoi(s) => MethodPlan::Layout(Method::Voronoi, s),
            JobSpec::Greedy(s) => MethodPlan::Layout(Method::Greedy, s),
            JobSpec::Homology(s) => MethodPlan::Homology(s),
            JobSpec::Quad(s) => MethodPlan::Quad(s),
            JobSpec::Spherical(s) => MethodPlan::Spherical(s),
            JobSpec::Auto(_) => return Err(Error::Internal("an auto job reached its plan unresolved".into())),
        })
    }

    pub fn method(&self) -> Method {
        match self {
            MethodPlan::Layout(m, _) => *m,
            MethodPlan::Homology(_) => Method::Homology,
            MethodPlan::Quad(_) => Method::Quad,
            MethodPlan::Spherical(_) => Method::Spherical,
        }
    }

    /// A pair method's anchor rows (`quad` has none).
    pub fn anchor_rows(&self) -> Option<&[AnchorRow]> {
        match self {
            MethodPlan::Layout(_, s) => Some(&s.anchors),
            MethodPlan::Homology(s) => Some(&s.anchors),
            MethodPlan::Spherical(s) => Some(&s.anchors),
            MethodPlan::Quad(_) => None,
        }
    }

    pub(crate) fn anchor_rows_mut(&mut self) -> Option<&mut Vec<AnchorRow>> {
        match self {
            MethodPlan::Layout(_, s) => Some(&mut s.anchors),
            MethodPlan::Homology(s) => Some(&mut s.anchors),
            MethodPlan::Spherical(s) => Some(&mut s.anchors),
            MethodPlan::Quad(_) => None,
        }
    }

    /// The anchor and boundary rows of a method that maps meshes in several parts part by part
    /// (`voronoi`, `greedy`, `homology` without feature curves).
    pub(super) fn parts_rows(&self) -> Option<(&[AnchorRow], &[[u64; 2]])> {
        match self {
            MethodPlan::Layout(_, s) => Some((&s.anchors, &s.boundaries)),
            MethodPlan::Homology(s) if s.features.is_empty() => Some((&s.anchors, &[])),
            _ => None,
        }
    }

    /// The plan of one part pair: these anchors and boundary rows, the job's options.
    pub fn for_part(&self, anchors: &[[u64; 2]], boundaries: &[[u64; 2]]) -> MethodPlan {
        let mut p = self.clone();
        if let MethodPlan::Layout(_, s) = &mut p {
            s.boundaries = boundaries.to_vec();
        }
        if let Some(rows) = p.anchor_rows_mut() {
            *rows = AnchorRow::ids(anchors.iter().copied());
        }
        p
    }

    /// The anchors as `[source, target]` vertex ids (empty for `quad`).
    pub fn anchor_ids(&self) -> Vec<[u64; 2]> {
        self.anchor_rows().and_then(|r| id_rows(r).ok()).unwrap_or_default()
    }
}
