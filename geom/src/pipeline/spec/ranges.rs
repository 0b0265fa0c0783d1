//! Every job option's accepted range, in one table per job kind, checked when a job is
//! submitted (server and CLI) and again before it runs. A value outside its range is an
//! `option_out_of_range` error that names the field and the range, so that no option value can make a
//! job allocate without bound or loop for ever (a `min_nodes` of 10⁹ once asked for 62 GB).
//!
//! The bounds are generous: each is one to two orders of magnitude above anything a measured
//! case has needed, and small enough that the job's memory stays proportional to its meshes
//! (see [`crate::pipeline::spec::memory`]).

use crate::crossparam::smooth::SmoothOptions;
use crate::error::{InputError, Result};
use crate::pipeline::spec::quad_spec::QuadOptions;
use crate::pipeline::spec::{HomologyOptions, MapOptions, SphericalOptions};

use crate::pipeline::spec::limits::{MAX_ANCHORS, MAX_EDGE_NODES, MAX_METRIC_SAMPLES, MAX_MORPH_FRAMES};

fn out_of_range(field: &str, value: impl std::fmt::Display, range: &str) -> crate::error::Error {
    InputError::OptionRange(format!("options.{field} = {value} is outside its range {range}")).into()
}

/// `lo <= v <= hi` for an integer option.
fn int(field: &str, v: impl Into<u64>, lo: u64, hi: u64) -> Result<()> {
    let v = v.into();
    if (lo..=hi).contains(&v) { Ok(()) } else { Err(out_of_range(field, v, &format!("[{lo}, {hi}]"))) }
}

/// `lo <= v <= hi` (or `lo < v` when `open_lo`) for a real option; NaN and infinities fail.
fn real(field: &str, v: f64, lo: f64, hi: f64, open_lo: bool) -> Result<()> {
    let above = if open_lo { v > lo } else { v >= lo };
    if v.is_finite() && above && v <= hi {
        Ok(())
    } else {
        Err(out_of_range(field, v, &format!("{}{lo}, {hi}]", if open_lo { "(" } else { "[" })))
    }
}

fn size(field: &str, v: usize, lo: u64, hi: u64) -> Result<()> {
    int(field, u64::try_from(v).unwrap_or(u64::MAX), lo, hi)
}

impl MapOptions {
    /// Checks every option of a `voronoi` or `greedy` job against its range.
    ///
    /// # Errors
    /// `InputError::OptionRange` naming the first field out of range and the range.
    pub fn check_ranges(&self) -> Result<()> {
        let l = &self.layout;
        int("layout.edge_nodes.min_nodes", l.edge_nodes.min_nodes, 1, 64)?;
        int(
            "layout.edge_nodes.max_nodes",
            l.edge_nodes.max_nodes,
            u64::from(l.edge_nodes.min_nodes),
            u64::from(MAX_EDGE_NODES),
        )?;
        int("layout.edge_nodes.ring_factor", l.edge_nodes.ring_factor, 1, 16)?;
        size("layout.max_attempts", l.max_attempts, 1, 1_000_000)?;
        int("layout.rebuilds", l.rebuilds, 0, 8)?;
        size("layout.straighten_rounds", l.straighten_rounds, 0, 100)?;
        size("layout.flip.rounds", l.flip.rounds, 0, 100)?;
        real("layout.flip.threshold", l.flip.threshold, 0.0, 2.0, false)?;
        real("layout.flip.max_end_angle", l.flip.max_end_angle, 0.0, 1.0, true)?;
        size("param.stretch_iterations", self.param.stretch_iterations, 0, 100)?;
        smoothing(&self.smoothing)?;
        crate::pipeline::spec::transfer::parse(&self.transfer)?;
        size("metric_samples", self.metric_samples, 100, MAX_METRIC_SAMPLES as u64)
    }
}

impl HomologyOptions {
    /// Checks every option of a `homology` job against its range.
    ///
    /// # Errors
    /// `InputError::OptionRange` naming the first field out of range and the range.
    pub fn check_ranges(&self) -> Result<()> {
        if let Some([s, t]) = self.basis {
            size("basis[0]", s, 0, 64)?;
            size("basis[1]", t, 0, 64)?;
        }
        if let Some(r) = self.rotation {
            size("rotation", r, 0, 1_000)?;
        }
        crate::pipeline::spec::transfer::parse(&self.transfer)?;
        if let Some(d) = self.dihedral_threshold_deg {
            real("dihedral_threshold_deg", d, 0.0, 180.0, true)?;
        }
        if let Some(m) = &self.matching {
            size("matching (entries)", m.len(), 0, 64)?;
            if let Some(e) = m.iter().find(|e| e.len() > 256) {
                return Err(out_of_range("matching (entry length)", e.len(), "[0, 256]"));
            }
        }
        smoothing(&self.smoothing)?;
        size("metric_samples", self.metric_samples, 100, MAX_METRIC_SAMPLES as u64)
    }
}

impl SphericalOptions {
    /// Checks every option of a `spherical` job against its range.
    ///
    /// # Errors
    /// `InputError::OptionRange` naming the first field out of range and the range.
    pub fn check_ranges(&self) -> Result<()> {
        crate::pipeline::spec::transfer::parse(&self.transfer)?;
        size("metric_samples", self.metric_samples, 100, MAX_METRIC_SAMPLES as u64)
    }
}

fn smoothing(s: &SmoothOptions) -> Result<()> {
    size("smoothing.iterations", s.iterations, 0, 10_000)?;
    real("smoothing.tolerance", s.tolerance, 0.0, 1.0, false)?;
    real("smoothing.step", s.step, 0.0, 1.0, true)
}

impl QuadOptions {
    /// Checks every option of a `quad` job on `models` meshes against its range.
    ///
    /// # Errors
    /// `InputError::OptionRange` naming the first field out of range and the range.
    pub fn check_ranges(&self, models: usize) -> Result<()> {
        int("level", self.level, 1, u64::from(crate::quad::remesh::MAX_LEVEL))?;
        if let Some(e) = self.adaptive_epsilon {
            real("adaptive_epsilon", e, 0.0, 1.0, true)?;
        }
        if let Some(l) = self.image_level {
            int("image_level", l, 0, u64::from(crate::quad::remesh::MAX_LEVEL))?;
        }
        size("base_vertices", self.base_vertices, 0, 100_000)?;
        size("metric_samples", self.metric_samples, 100, MAX_METRIC_SAMPLES as u64)?;
        size("feature_anchors (rows)", self.feature_anchors.len(), 0, MAX_ANCHORS as u64)?;
        let m = &self.morph;
        size("morph.frames", m.frames, 0, MAX_MORPH_FRAMES as u64)?;
        size("morph.schedule (levels)", m.schedule.len(), 0, 16)?;
        for (k, s) in m.schedule.iter().enumerate() {
            real(&format!("morph.schedule[{k}].start"), s.start, 0.0, 1.0, false)?;
            real(&format!("morph.schedule[{k}].speed"), s.speed, 0.0, 1e6, true)?;
        }
        size("morph.weights (vectors)", m.weights.len(), 0, 256)?;
        for (k, w) in m.weights.iter().enumerate() {
            if w.len() != models {
                return Err(InputError::OptionRange(format!(
                    "options.morph.weights[{k}] has {} weights for {models} meshes",
                    w.len()
                ))
                .into());
            }
            for (i, &x) in w.iter().enumerate() {
                real(&format!("morph.weights[{k}][{i}]"), x, -1e3, 1e3, false)?;
            }
        }
        // The wavelet morph analyses the uniform grid: an adaptive remesh has none (the run
        // would fail after the whole parameterization).
        if m.frames > 0
            && m.domain == crate::pipeline::spec::quad_spec::MorphDomain::Wavelet
            && self.adaptive_epsilon.is_some()
        {
            return Err(InputError::OptionRange(
                "options.morph.domain = \"wavelet\" needs uniform remeshing: drop options.adaptive_epsilon, or use the spatial morph".into(),
            )
            .into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_in_range() {
        MapOptions::default().check_ranges().unwrap();
        HomologyOptions::default().check_ranges().unwrap();
        QuadOptions::default().check_ranges(2).unwrap();
    }

    /// The spec bombs that once crashed the server are refused, naming the field and range.
    #[test]
    fn spec_bombs_name_the_field_and_range() {
        let mut o = MapOptions::default();
        o.layout.edge_nodes.min_nodes = 1_000_000_000;
        let e = o.check_ranges().unwrap_err().to_string();
        assert!(e.contains("options.layout.edge_nodes.min_nodes = 1000000000") && e.contains("[1, 64]"), "{e}");
        let o = MapOptions { metric_samples: 1_000_000_000_000, ..Default::default() };
        let e = o.check_ranges().unwrap_err().to_string();
        assert!(e.contains("options.metric_samples") && e.contains("[100, 1000000]"), "{e}");
        let mut o = MapOptions::default();
        o.smoothing.step = f64::NAN;
        let e = o.check_ranges().unwrap_err().to_string();
        assert!(e.contains("options.smoothing.step = NaN") && e.contains("(0, 1]"), "{e}");
        let mut q = QuadOptions::default();
        q.morph.frames = 10_000;
        let e = q.check_ranges(2).unwrap_err().to_string();
        assert!(e.contains("options.morph.frames") && e.contains("[0, 1000]"), "{e}");
    }

    #[test]
    fn a_wavelet_morph_of_an_adaptive_remesh_is_refused_before_running() {
        let mut q = QuadOptions { adaptive_epsilon: Some(0.01), ..Default::default() };
        q.morph.frames = 3;
        q.morph.domain = crate::pipeline::spec::quad_spec::MorphDomain::Wavelet;
        let e = q.check_ranges(2).unwrap_err();
        assert_eq!(e.code(), "option_out_of_range");
        assert!(e.to_string().contains("adaptive_epsilon"), "{e}");
        q.morph.frames = 0;
        assert!(q.check_ranges(2).is_ok(), "no morph, no wavelets");
    }

    #[test]
    fn max_nodes_below_min_nodes_is_refused() {
        let mut o = MapOptions::default();
        o.layout.edge_nodes.min_nodes = 8;
        o.layout.edge_nodes.max_nodes = 4;
        let e = o.check_ranges().unwrap_err().to_string();
        assert!(e.contains("max_nodes = 4") && e.contains("[8, 256]"), "{e}");
    }
}
