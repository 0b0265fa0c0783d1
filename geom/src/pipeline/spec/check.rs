//! A job checked against its meshes' summaries before any work starts (the server answers
//! with these errors before it queues a job; the pipeline checks again on the meshes).

use crate::error::{InputError, Result};
use crate::homology::features::{Curve, check_disjoint, validate_curve};
use crate::mesh::{Mesh, VertexId};
use crate::pipeline::spec::anchor_spec::AnchorRow;
use crate::pipeline::spec::limits::{MAX_ANCHORS, MAX_FEATURES};
use crate::pipeline::spec::{HomologySpec, JobSpec, LayoutSpec, Method, SphericalSpec};
use crate::topology::{self, Summary};

impl JobSpec {
    /// Checks the job against its meshes' summaries (two for pair jobs, in source, target
    /// order; 1 to 16 for `quad`).
    ///
    /// # Errors
    /// `InputError::Spec` for the wrong number of meshes; the method's own checks.
    pub fn check(&self, summaries: &[Summary]) -> Result<()> {
        let pair = |n: usize| -> Result<(&Summary, &Summary)> {
            match summaries {
                [a, b] => Ok((a, b)),
                _ => Err(InputError::Spec(format!(
                    "method {} maps a source onto a target: 2 meshes, got {n}",
                    self.method().name()
                ))
                .into()),
            }
        };
        let transfer = match self {
            JobSpec::Voronoi(s) | JobSpec::Greedy(s) => {
                let (a, b) = pair(summaries.len())?;
                s.check(self.method(), a, b)?;
                &s.options.transfer
            }
            JobSpec::Homology(s) => {
                let (a, b) = pair(summaries.len())?;
                s.check(a, b)?;
                &s.options.transfer
            }
            JobSpec::Quad(s) => return s.check(summaries).map(|_| ()),
            JobSpec::Spherical(s) => {
                let (a, b) = pair(summaries.len())?;
                s.check(a, b)?;
                &s.options.transfer
            }
            // The chosen method's checks, as if it had been named.
            JobSpec::Auto(s) => return s.resolve(summaries)?.0.check(summaries),
        };
        // The attributes `transfer` carries, when the source's summary records them.
        match summaries.first().and_then(|s| s.attribute_names.as_deref()) {
            Some(names) if !transfer.is_empty() => {
                crate::pipeline::spec::transfer::check_names(&crate::pipeline::spec::transfer::parse(transfer)?, names)
            }
            _ => Ok(()),
        }
    }
}

impl LayoutSpec {
    /// Meshes of one genus and boundary count, options in range, `boundaries` rows in range,
    /// enough anchors (3 on a closed genus-0 surface, 1 on an open one, 6 above), in range and
    /// distinct. Returns the anchors as vertex pairs.
    ///
    /// # Errors
    /// `InputError::TopologyMismatch`, `InputError::Anchors`, `InputError::OptionRange`.
    pub fn check(&self, method: Method, ss: &Summary, ts: &Summary) -> Result<Vec<(VertexId, VertexId)>> {
        same_topology(ss, ts, true)?;
        self.options.check_ranges()?;
        if self.boundaries.len() > ss.boundary_loops {
            return Err(InputError::Anchors(format!(
                "{} boundaries rows, but the meshes have {} boundary loops",
                self.boundaries.len(),
                ss.boundary_loops
            ))
            .into());
        }
        for (i, &[s, t]) in self.boundaries.iter().enumerate() {
            if s >= ss.id_count() as u64 || t >= ts.id_count() as u64 {
                return Err(InputError::Anchors(format!(
                    "boundaries row {i}: vertex out of range (source has {}, target {} vertices)",
                    ss.id_count(),
                    ts.id_count()
                ))
                .into());
            }
        }
        // A loop's own anchors (added along it) and its cone's apex shape the layout near it: a
        // disk needs one anchor, to pair and orient its loop.
        let need = match (ss.genus, ss.boundary_loops) {
            (0, 0) => 3,
            (0, _) => 1,
            _ => 6,
        };
        anchor_pairs(&self.anchors, method, need, ss, ts)
    }

    /// [`LayoutSpec::check`] on the meshes themselves.
    ///
    /// # Errors
    /// As [`LayoutSpec::check`].
    pub fn validate(&self, method: Method, source: &Mesh, target: &Mesh) -> Result<Vec<(VertexId, VertexId)>> {
        self.check(method, &topology::summary(source), &topology::summary(target))
    }
}

impl SphericalSpec {
    /// Two connected closed genus-0 meshes, options in range, at least 3 anchors in range and
    /// distinct. Returns the anchors as vertex pairs.
    ///
    /// # Errors
    /// `InputError::TopologyMismatch`, `InputError::Anchors`, `InputError::OptionRange`.
    pub fn check(&self, ss: &Summary, ts: &Summary) -> Result<Vec<(VertexId, VertexId)>> {
        same_topology(ss, ts, false)?;
        if ss.genus != 0 || ss.boundary_loops != 0 {
            return Err(InputError::TopologyMismatch(format!(
                "method spherical maps closed genus-0 surfaces; these have genus {} and {} boundary loops (voronoi and greedy map the others)",
                ss.genus, ss.boundary_loops
            ))
            .into());
        }
        self.options.check_ranges()?;
        anchor_pairs(&self.anchors, Method::Spherical, 3, ss, ts)
    }

    /// [`SphericalSpec::check`] on the meshes themselves.
    ///
    /// # Errors
    /// As [`SphericalSpec::check`].
    pub fn validate(&self, source: &Mesh, target: &Mesh) -> Result<Vec<(VertexId, VertexId)>> {
        self.check(&topology::summary(source), &topology::summary(target))
    }
}

impl HomologySpec {
    /// Connected meshes of one genus and boundary count (boundaries on genus 0 only), options
    /// in range, feature curves within the limit, the anchors the domain needs. Returns the
    /// anchors as vertex pairs.
    ///
    /// # Errors
    /// `InputError::TopologyMismatch`, `InputError::Anchors`, `InputError::Features`,
    /// `InputError::OptionRange`.
    pub fn check(&self, ss: &Summary, ts: &Summary) -> Result<Vec<(VertexId, VertexId)>> {
        same_topology(ss, ts, self.features.is_empty())?;
        if ss.boundary_loops > 0 && ss.genus > 0 {
            return Err(InputError::TopologyMismatch(format!(
                "method homology maps boundary loops on genus-0 surfaces (features on closed surfaces of any genus); these have genus {} and {} boundary loops (methods voronoi and greedy map open surfaces of any genus)",
                ss.genus, ss.boundary_loops
            ))
            .into());
        }
        self.options.check_ranges()?;
        if self.features.len() > MAX_FEATURES {
            return Err(InputError::Features(format!(
                "{} feature curves exceed the limit {MAX_FEATURES}",
                self.features.len()
            ))
            .into());
        }
        for (i, f) in self.features.iter().enumerate() {
            feature_ids(&f.source, ss, &format!("feature {i} (source)"))?;
            feature_ids(&f.target, ts, &format!("feature {i} (target)"))?;
        }
        let curves = self.features.len() + ss.boundary_loops;
        let need = match ss.genus {
            0 if curves == 0 => {
                return Err(InputError::TopologyMismatch(
                    "method homology on a closed genus-0 surface needs feature curves: each becomes a handle".into(),
                )
                .into());
            }
            // A disk without features: the anchor fixes where its boundary starts.
            0 if self.features.is_empty() => 1,
            0 => 0,
            // The base vertex of both canonical bases.
            _ => 1,
        };
        anchor_pairs(&self.anchors, Method::Homology, need, ss, ts)
    }

    /// [`HomologySpec::check`] on the meshes themselves.
    ///
    /// # Errors
    /// As [`HomologySpec::check`].
    pub fn validate(&self, source: &Mesh, target: &Mesh) -> Result<Vec<(VertexId, VertexId)>> {
        self.check(&topology::summary(source), &topology::summary(target))
    }

    /// The feature curves, checked against both meshes: vertex paths along edges, simple,
    /// pairwise disjoint, open ones off the boundary, closed ones whole boundary loops.
    ///
    /// # Errors
    /// `InputError::Features` naming the curve and the fault.
    pub fn curves(&self, source: &Mesh, target: &Mesh) -> Result<(Vec<Curve>, Vec<Curve>)> {
        let mut s = Vec::with_capacity(self.features.len());
        let mut t = Vec::with_capacity(self.features.len());
        for (i, f) in self.features.iter().enumerate() {
            s.push(validate_curve(source, &f.source, &format!("feature {i} (source)"))?);
            t.push(validate_curve(target, &f.target, &format!("feature {i} (target)"))?);
        }
        check_disjoint(&s, source.n_vertices(), "source")?;
        check_disjoint(&t, target.n_vertices(), "target")?;
        Ok((s, t))
    }
}

/// What a feature curve's vertex list must satisfy on any mesh of this summary (the rest,
/// edges between consecutive vertices and disjoint curves, is checked on the meshes): at least
/// two vertices, each in range, none repeated but the first as the last of a closed curve.
fn feature_ids(raw: &[u64], s: &Summary, what: &str) -> Result<()> {
    let bad = |m: String| InputError::Features(format!("{what}: {m}")).into();
    let n = s.id_count() as u64;
    if raw.len() < 2 {
        return Err(bad(format!("needs at least 2 vertices, has {}", raw.len())));
    }
    if let Some(r) = raw.iter().find(|&&r| r >= n) {
        return Err(bad(format!("vertex {r} is out of range (the mesh has {n} vertices)")));
    }
    let open = if raw.len() > 2 && raw[0] == raw[raw.len() - 1] { &raw[..raw.len() - 1] } else { raw };
    let mut seen = std::collections::HashSet::with_capacity(open.len());
    match open.iter().find(|r| !seen.insert(**r)) {
        Some(r) => Err(bad(format!("repeats vertex {r}"))),
        None => Ok(()),
    }
}

/// Both meshes connected, of one genus and one number of boundary loops.
/// Equal genus and boundary counts; one part each, or (`parts_ok`: a job `pipeline::parts`
/// runs part by part) as many parts on both.
fn same_topology(ss: &Summary, ts: &Summary, parts_ok: bool) -> Result<()> {
    if ss.components != ts.components || (!parts_ok && ss.components != 1) {
        return Err(InputError::TopologyMismatch(format!(
            "the source has {} parts (connected components), the target {}: {}",
            ss.components,
            ts.components,
            if parts_ok { "parts map one to one" } else { "this job maps connected meshes (voronoi, greedy and homology without feature curves map several parts, pairing them through the anchors)" }
        ))
        .into());
    }
    if ss.genus != ts.genus {
        return Err(InputError::TopologyMismatch(format!(
            "genus mismatch: source has genus {}, target genus {}",
            ss.genus, ts.genus
        ))
        .into());
    }
    if ss.boundary_loops != ts.boundary_loops {
        return Err(InputError::TopologyMismatch(format!(
            "boundary mismatch: source has {} boundary loops, target {}",
            ss.boundary_loops, ts.boundary_loops
        ))
        .into());
    }
    Ok(())
}

/// At least `need` and at most [`MAX_ANCHORS`] anchors, each in range on its mesh, no vertex
/// used twice on one mesh.
fn anchor_pairs(
    anchors: &[AnchorRow],
    method: Method,
    need: usize,
    ss: &Summary,
    ts: &Summary,
) -> Result<Vec<(VertexId, VertexId)>> {
    let n = anchors.len();
    if n > MAX_ANCHORS {
        return Err(InputError::Anchors(format!("{n} anchors exceed the limit {MAX_ANCHORS}")).into());
    }
    if n < need {
        return Err(InputError::Anchors(format!(
            "too few anchors: {n} given, method {} on genus {} needs at least {need}",
            method.name(),
            ss.genus
        ))
        .into());
    }
    let mut out = Vec::with_capacity(n);
    let (mut seen_s, mut seen_t) = (std::collections::HashMap::new(), std::collections::HashMap::new());
    for (i, row) in anchors.iter().enumerate() {
        // Point rows are checked here as far as the summaries allow; they become vertex ids
        // (inserted vertices included) before a method runs, and are checked again then.
        let &[s, t] = match row {
            AnchorRow::Ids(x) => x,
            AnchorRow::Points(p) => {
                p.source.check(i, "source", ss.faces)?;
                p.target.check(i, "target", ts.faces)?;
                continue;
            }
        };
        if s >= ss.id_count() as u64 {
            return Err(InputError::Anchors(format!(
                "anchor {i}: source vertex {s} is out of range (source has {} vertices)",
                ss.id_count()
            ))
            .into());
        }
        if t >= ts.id_count() as u64 {
            return Err(InputError::Anchors(format!(
                "anchor {i}: target vertex {t} is out of range (target has {} vertices)",
                ts.id_count()
            ))
            .into());
        }
        if let Some(j) = seen_s.insert(s, i) {
            return Err(InputError::Anchors(format!("anchors {j} and {i} repeat source vertex {s}")).into());
        }
        if let Some(j) = seen_t.insert(t, i) {
            return Err(InputError::Anchors(format!("anchors {j} and {i} repeat target vertex {t}")).into());
        }
        out.push((VertexId(s as u32), VertexId(t as u32)));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn a_negative_smoothing_step_is_out_of_range() {
        let m = shapes::icosphere(1);
        let mut spec = LayoutSpec {
            boundaries: Vec::new(),
            anchors: crate::pipeline::AnchorRow::ids(vec![[0, 0], [3, 3], [7, 7]]),
            options: Default::default(),
        };
        assert!(spec.validate(Method::Voronoi, &m, &m).is_ok());
        spec.options.smoothing.step = -1.0;
        let e = spec.validate(Method::Voronoi, &m, &m).unwrap_err();
        assert_eq!(e.code(), "option_out_of_range", "{e}");
        assert!(e.to_string().contains("smoothing.step"), "{e}");
    }

    #[test]
    fn the_wrong_number_of_meshes_is_a_spec_error() {
        let m = topology::summary(&shapes::icosphere(1));
        let spec = JobSpec::Greedy(LayoutSpec {
            boundaries: Vec::new(),
            anchors: crate::pipeline::AnchorRow::ids(vec![[0, 0], [3, 3], [7, 7]]),
            options: Default::default(),
        });
        assert!(spec.check(&[m.clone(), m.clone()]).is_ok());
        assert_eq!(spec.check(&[m.clone(), m.clone(), m]).unwrap_err().code(), "invalid_spec");
    }
}
