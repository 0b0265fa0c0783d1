//! The job spec: the one description of a mapping job that the CLI (`surfmap map --spec`) and
//! the server accept, validated here against the two meshes before any work starts.

use crate::crossparam::PatchParamOptions;
use crate::crossparam::smooth::SmoothOptions;
use crate::domain::LayoutOptions;
use crate::error::{InputError, Result};
use crate::homology::features::{Curve, check_disjoint, validate_curve};
use crate::mesh::{Mesh, VertexId};
use crate::topology;
use serde::{Deserialize, Serialize};

/// The mapping method.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Method {
    /// Common base domains from Voronoi cues (Kwok, Zhang, Wang).
    Voronoi,
    /// The shortest-paths-first heuristic of Kraevoy & Sheffer 2004.
    Greedy,
    /// Canonical homology bases and the 4g-gon domain (Carner, Jin, Gu, Qin 2005).
    Homology,
}

impl Method {
    pub fn name(self) -> &'static str {
        match self {
            Method::Voronoi => "voronoi",
            Method::Greedy => "greedy",
            Method::Homology => "homology",
        }
    }
}

/// Options of a `voronoi` or `greedy` job. Every field has a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapOptions {
    /// Edge nodes and search budget of the layout construction.
    pub layout: LayoutOptions,
    /// Weights of the patch parameterization (mean value by default).
    pub param: PatchParamOptions,
    /// The global map onto the base domain that frees vertices from the layout paths (closed
    /// meshes; on by default). The per-patch maps seed it and stand in when it fails.
    pub global: crate::crossparam::global::GlobalParamOptions,
    /// Stretch-reducing relocation of vertices across patch boundaries.
    pub smoothing: SmoothOptions,
    /// Global projected-Newton relaxation after the smoothing sweeps (moves whole regions).
    pub newton: crate::crossparam::newton::NewtonOptions,
    /// Re-embedding of regions around folds that the one-vertex repairs leave.
    pub untangle: crate::crossparam::untangle::UntangleOptions,
    /// Surface samples per direction for the Hausdorff / RMS metrics (the evaluator's 100000).
    pub metric_samples: usize,
    /// `homology`: basis index (0 = shortest) on the source and on the target.
    pub basis: [usize; 2],
    /// `homology`: τ rotates the source's 4g-gon by `rotation · 2π/g` (quarter turns for g = 1).
    pub rotation: usize,
    /// `homology`: also merge both tessellations into the meta-mesh pair.
    pub meta_mesh: bool,
    /// `homology`: Yoshizawa–Belyaev–Seidel stretch-minimizing reweighting rounds of each
    /// planar domain (0 = the plain mean-value map). Spreads protrusions that the harmonic map
    /// crushes (a hand cut at the wrist) at the price of more folds between different shapes.
    pub domain_stretch_iterations: usize,
    /// `homology` with feature curves or boundaries: align the target's curves to the source's
    /// vertex by vertex (dynamic time warping of arc length and boundary angle) instead of
    /// placing both by arc length alone.
    pub align_curves: bool,
    /// `homology` with `meta_mesh`: prune the meta-mesh, keeping only edges whose dihedral
    /// angle exceeds this many degrees on either surface (flat vertices are collapsed).
    pub dihedral_threshold_deg: Option<f64>,
    /// `homology`: where each source loop goes, e.g. `["a1 -> b1", "b1 -> -a1"]` or
    /// `["a1 -> a1+b1", "b1 -> b1"]`; overrides `basis` and `rotation` with a class that induces
    /// it on H1 (searched over the first few bases and every rotation).
    pub matching: Option<Vec<String>>,
}

impl Default for MapOptions {
    fn default() -> Self {
        Self {
            layout: LayoutOptions::default(),
            param: PatchParamOptions::default(),
            global: Default::default(),
            smoothing: SmoothOptions::default(),
            newton: Default::default(),
            untangle: Default::default(),
            metric_samples: 100_000,
            basis: [0, 0],
            rotation: 0,
            meta_mesh: false,
            domain_stretch_iterations: 0,
            align_curves: true,
            dihedral_threshold_deg: None,
            matching: None,
        }
    }
}

/// One pair of corresponding feature curves: vertex paths on the source and on the target. A
/// closed list (last = first) is a whole boundary loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeatureSpec {
    pub source: Vec<u64>,
    pub target: Vec<u64>,
}

/// `{"method": ..., "anchors": [[s, t], ...], "features": [...], "options": {...}}`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct JobSpec {
    pub method: Method,
    pub anchors: Vec<[u64; 2]>,
    /// `homology`: corresponding feature curves, mapped exactly.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub features: Vec<FeatureSpec>,
    #[serde(default)]
    pub options: MapOptions,
}

/// Most anchors a job may have.
pub const MAX_ANCHORS: usize = 4096;
/// Most feature curves a job may have.
pub const MAX_FEATURES: usize = 256;

impl JobSpec {
    /// Parses a spec from JSON.
    ///
    /// # Errors
    /// `InputError::Spec` naming the field at fault.
    pub fn from_json(bytes: &[u8]) -> Result<JobSpec> {
        serde_json::from_slice(bytes).map_err(|e| InputError::Spec(e.to_string()).into())
    }

    /// A spec from a bare anchors file `{"anchors": [[s, t], ...]}` or `[[s, t], ...]`.
    ///
    /// # Errors
    /// `InputError::Spec` when the JSON has neither form.
    pub fn from_anchors_json(bytes: &[u8], method: Method) -> Result<JobSpec> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum A {
            Obj { anchors: Vec<[u64; 2]> },
            List(Vec<[u64; 2]>),
        }
        let a: A = serde_json::from_slice(bytes).map_err(|e| InputError::Spec(format!("anchors file: {e}")))?;
        let anchors = match a {
            A::Obj { anchors } | A::List(anchors) => anchors,
        };
        Ok(JobSpec { method, anchors, features: Vec::new(), options: MapOptions::default() })
    }

    /// Checks the spec against the meshes: same genus, closed surfaces, anchors in range and
    /// distinct, enough anchors. Returns the anchors as vertex pairs.
    ///
    /// # Errors
    /// `InputError::TopologyMismatch`, `InputError::Anchors`.
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

    /// [`JobSpec::validate`] from the meshes' summaries alone, so a server can answer before
    /// it queues a job without rebuilding the meshes.
    ///
    /// # Errors
    /// `InputError::TopologyMismatch`, `InputError::Anchors`.
    pub fn check(&self, ss: &topology::Summary, ts: &topology::Summary) -> Result<Vec<(VertexId, VertexId)>> {
        if ss.components != 1 || ts.components != 1 {
            return Err(InputError::TopologyMismatch(format!(
                "both meshes must be connected (source has {} components, target {})",
                ss.components, ts.components
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
        let curves = self.features.len() + ss.boundary_loops;
        if self.method != Method::Homology && !self.features.is_empty() {
            return Err(InputError::Features(format!(
                "method {} takes no feature curves (method homology does)",
                self.method.name()
            ))
            .into());
        }
        if ss.boundary_loops > 0 && ss.genus > 0 {
            return Err(InputError::TopologyMismatch(format!(
                "boundary loops are supported on genus-0 surfaces (features on closed surfaces of any genus); these have genus {} and {} boundary loops",
                ss.genus, ss.boundary_loops
            ))
            .into());
        }
        if ss.boundary_loops != 0 && self.method != Method::Homology {
            return Err(InputError::TopologyMismatch(format!(
                "method {} maps closed surfaces; source has {} boundary loops, target {}",
                self.method.name(),
                ss.boundary_loops,
                ts.boundary_loops
            ))
            .into());
        }
        let n = self.anchors.len();
        self.options.check_ranges()?;
        if self.features.len() > MAX_FEATURES {
            return Err(InputError::Features(format!(
                "{} feature curves exceed the limit {MAX_FEATURES}",
                self.features.len()
            ))
            .into());
        }
        if n > MAX_ANCHORS {
            return Err(InputError::Anchors(format!("{n} anchors exceed the limit {MAX_ANCHORS}")).into());
        }
        let need = match (self.method, ss.genus) {
            (Method::Homology, 0) if curves == 0 => {
                return Err(InputError::TopologyMismatch(
                    "method homology on a closed genus-0 surface needs feature curves: each becomes a handle".into(),
                )
                .into());
            }
            // A disk without features: the anchor fixes where its boundary starts.
            (Method::Homology, 0) if self.features.is_empty() => 1,
            (Method::Homology, 0) => 0,
            // The base vertex of both canonical bases.
            (Method::Homology, _) => 1,
            (_, 0) => 3,
            _ => 6,
        };
        if n < need {
            return Err(InputError::Anchors(format!(
                "too few anchors: {n} given, method {} on genus {} needs at least {need}",
                self.method.name(),
                ss.genus
            ))
            .into());
        }
        let mut out = Vec::with_capacity(n);
        let (mut seen_s, mut seen_t) = (std::collections::HashMap::new(), std::collections::HashMap::new());
        for (i, &[s, t]) in self.anchors.iter().enumerate() {
            if s >= ss.vertices as u64 {
                return Err(InputError::Anchors(format!(
                    "anchor {i}: source vertex {s} is out of range (source has {} vertices)",
                    ss.vertices
                ))
                .into());
            }
            if t >= ts.vertices as u64 {
                return Err(InputError::Anchors(format!(
                    "anchor {i}: target vertex {t} is out of range (target has {} vertices)",
                    ts.vertices
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn a_negative_area_weight_is_a_spec_error() {
        let m = shapes::icosphere(1);
        let mut spec = JobSpec {
            method: Method::Voronoi,
            anchors: vec![[0, 0], [3, 3], [7, 7]],
            features: Vec::new(),
            options: MapOptions::default(),
        };
        assert!(spec.validate(&m, &m).is_ok());
        spec.options.smoothing.area_weight = -1.0;
        let e = spec.validate(&m, &m).unwrap_err();
        assert_eq!(e.code(), "option_out_of_range", "{e}");
        assert!(e.to_string().contains("area_weight"), "{e}");
    }

    #[test]
    fn newton_options_out_of_range_are_spec_errors() {
        let m = shapes::icosphere(1);
        let spec = JobSpec {
            method: Method::Voronoi,
            anchors: vec![[0, 0], [3, 3], [7, 7]],
            features: Vec::new(),
            options: MapOptions::default(),
        };
        type Set = fn(&mut crate::crossparam::newton::NewtonOptions);
        let cases: [(&str, Set); 4] = [
            ("tolerance", |o| o.tolerance = f64::NAN),
            ("max_move", |o| o.max_move = 0.0),
            ("max_density", |o| o.max_density = -1.0),
            ("min_cos", |o| o.min_cos = 2.0),
        ];
        for (name, set) in cases {
            let mut bad = spec.clone();
            set(&mut bad.options.newton);
            let e = bad.validate(&m, &m).unwrap_err();
            assert_eq!(e.code(), "option_out_of_range", "{e}");
            assert!(e.to_string().contains(name), "{name}: {e}");
        }
    }
}
