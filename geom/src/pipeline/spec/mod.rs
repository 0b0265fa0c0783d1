//! The job spec: one typed description of any job, parsed once where a request enters (the
//! server, the CLI) and carried as this type to the store, the worker and the pipeline.
//!
//! `{"method": "voronoi" | "greedy", "anchors": [[s, t], ...], "options": {...}}`,
//! `{"method": "homology", "anchors": [...], "features": [...], "options": {...}}`,
//! `{"method": "quad", "anchors": [[v_1, ..., v_N], ...], "options": {...}}`,
//! `{"method": "spherical", "anchors": [...], "options": {...}}`,
//! `{"method": "auto", "anchors": [...], "options": {...}}` (also without `method`).
//! Each method has its own options type; unknown fields are refused at every depth.

pub(crate) mod anchor_spec;
pub(crate) mod auto;
mod check;
pub(crate) mod limits;
mod memory;
pub(crate) mod quad_spec;
mod ranges;
pub(crate) mod transfer;

use crate::crossparam::PatchParamOptions;
use crate::crossparam::smooth::SmoothOptions;
use crate::domain::LayoutOptions;
use crate::error::{Error, InputError, Result};
use anchor_spec::AnchorRow;
use quad_spec::QuadSpec;
use serde::{Deserialize, Serialize};

/// Every method a job may name, in [`Method`] order.
pub const METHODS: [&str; 6] = ["voronoi", "greedy", "homology", "quad", "spherical", "auto"];

/// A job: its method, with that method's anchors and options.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "method", rename_all = "snake_case")]
pub enum JobSpec {
    /// Common base domains from Voronoi cues (Kwok, Zhang, Wang).
    Voronoi(LayoutSpec),
    /// The shortest-paths-first heuristic of Kraevoy & Sheffer 2004.
    Greedy(LayoutSpec),
    /// Canonical homology bases and the 4g-gon domain (Carner, Jin, Gu, Qin 2005), with
    /// feature curves and boundaries (their section 3.4).
    Homology(HomologySpec),
    /// Consistent quad remeshing of N models (Yu & Chuang).
    Quad(QuadSpec),
    /// Closed genus-0 pairs through bijective sphere embeddings, one injective optimization
    /// (Schmidt, Pieper & Kobbelt 2023; issue 50).
    Spherical(SphericalSpec),
    /// The pair method that fits the meshes, picked by the service ([`crate::pipeline::spec::auto`]); also a
    /// spec without `method`.
    Auto(AutoSpec),
}

/// The method of a job.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    Voronoi,
    Greedy,
    Homology,
    Quad,
    Spherical,
    Auto,
}

impl Method {
    pub fn name(self) -> &'static str {
        METHODS[self as usize]
    }
}

/// A `voronoi` or `greedy` job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LayoutSpec {
    pub anchors: Vec<AnchorRow>,
    /// Open meshes: one row `[source vertex, target vertex]` per boundary loop that no anchor
    /// lies on, naming a vertex of each loop that correspond (optional; a loop with neither
    /// pairs through the anchor nearest to it).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub boundaries: Vec<[u64; 2]>,
    #[serde(default)]
    pub options: MapOptions,
}

/// A `spherical` job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SphericalSpec {
    pub anchors: Vec<AnchorRow>,
    #[serde(default)]
    pub options: SphericalOptions,
}

/// Options of a `spherical` job. Every field has a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SphericalOptions {
    /// Surface samples per direction for the Hausdorff / RMS metrics (the evaluator's 100000).
    pub metric_samples: usize,
    /// Source attributes to carry onto the target (`target_transferred.glb`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub transfer: Vec<String>,
    /// `morph.glb` also holds the target placed on the source (the inverse pair).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub inverse_morph: bool,
}

impl Default for SphericalOptions {
    fn default() -> Self {
        Self { metric_samples: 100_000, transfer: Vec::new(), inverse_morph: false }
    }
}

/// A job whose method the service picks.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct AutoSpec {
    pub anchors: Vec<AnchorRow>,
    /// Corresponding feature curves (they pick `homology`).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub features: Vec<FeatureSpec>,
    #[serde(default)]
    pub options: AutoOptions,
}

/// The options every pair method takes: exactly `spherical`'s, which has no others.
pub type AutoOptions = SphericalOptions;

/// A `homology` job.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HomologySpec {
    pub anchors: Vec<AnchorRow>,
    /// Corresponding feature curves, mapped exactly.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub features: Vec<FeatureSpec>,
    #[serde(default)]
    pub options: HomologyOptions,
}

/// One pair of corresponding feature curves: vertex paths on the source and on the target. A
/// closed list (last = first) is a whole boundary loop.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FeatureSpec {
    pub source: Vec<u64>,
    pub target: Vec<u64>,
}

/// Options of a `voronoi` or `greedy` job. Every field has a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MapOptions {
    /// Edge nodes and search budget of the layout construction.
    pub layout: LayoutOptions,
    /// Weights of the patch parameterization (mean value by default).
    pub param: PatchParamOptions,
    /// The global map onto the base domain (closed meshes; on by default).
    pub global: GlobalOptions,
    /// Stretch-reducing relocation of vertices across patch boundaries.
    pub smoothing: SmoothOptions,
    /// Surface samples per direction for the Hausdorff / RMS metrics (the evaluator's 100000).
    pub metric_samples: usize,
    /// Source attributes to carry onto the target (`target_transferred.glb`), e.g.
    /// `["TEXCOORD_0", "JOINTS_0", "WEIGHTS_0"]`.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub transfer: Vec<String>,
    /// `morph.glb` also holds the target in its own layout with a morph target that places it
    /// on the source (the inverse pair).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub inverse_morph: bool,
}

impl Default for MapOptions {
    fn default() -> Self {
        Self {
            layout: LayoutOptions::default(),
            param: PatchParamOptions::default(),
            global: GlobalOptions::default(),
            smoothing: SmoothOptions::default(),
            metric_samples: 100_000,
            transfer: Vec::new(),
            inverse_morph: false,
        }
    }
}

/// Whether a `voronoi` / `greedy` job tries the global map onto the base domain, which frees
/// vertices from the layout paths; the per-patch maps seed it and stand in when it is worse.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GlobalOptions {
    pub enabled: bool,
}

impl Default for GlobalOptions {
    fn default() -> Self {
        Self { enabled: true }
    }
}

/// Options of a `homology` job. Every field has a default.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HomologyOptions {
    /// Basis index (0 = shortest) on the source and on the target. With neither `basis`,
    /// `rotation` nor `matching`, the job searches for the natural class
    /// ([`crate::homology::natural`]); with either, the other is 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub basis: Option<[usize; 2]>,
    /// τ rotates the source's 4g-gon by `rotation · 2π/g` (quarter turns for g = 1).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rotation: Option<usize>,
    /// Where each source loop goes, e.g. `["a1 -> b1", "b1 -> -a1"]`; overrides `basis` and
    /// `rotation` with a class that induces it on H1.
    pub matching: Option<Vec<String>>,
    /// Also merge both tessellations into the meta-mesh pair.
    pub meta_mesh: bool,
    /// With `meta_mesh`: keep only edges whose dihedral angle exceeds this many degrees on
    /// either surface (flat vertices are collapsed).
    pub dihedral_threshold_deg: Option<f64>,
    /// With feature curves or boundaries: align the target's curves to the source's vertex by
    /// vertex (dynamic time warping of arc length and boundary angle) instead of placing both
    /// by arc length alone.
    pub align_curves: bool,
    /// Stretch-reducing relocation of vertices after the domain maps.
    pub smoothing: SmoothOptions,
    /// Surface samples per direction for the Hausdorff / RMS metrics.
    pub metric_samples: usize,
    /// As [`MapOptions::transfer`].
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub transfer: Vec<String>,
    /// As [`MapOptions::inverse_morph`].
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub inverse_morph: bool,
}

impl Default for HomologyOptions {
    fn default() -> Self {
        Self {
            basis: None,
            rotation: None,
            matching: None,
            meta_mesh: false,
            dihedral_threshold_deg: None,
            align_curves: true,
            smoothing: SmoothOptions::default(),
            metric_samples: 100_000,
            transfer: Vec::new(),
            inverse_morph: false,
        }
    }
}

/// What every pair method's last stages (relaxation and metrics) take from its options.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RelaxOptions {
    pub smoothing: SmoothOptions,
    pub metric_samples: usize,
}

impl MapOptions {
    pub fn relax(&self) -> RelaxOptions {
        RelaxOptions { smoothing: self.smoothing, metric_samples: self.metric_samples }
    }
}

/// The homotopy class a `homology` job asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ClassChoice<'a> {
    /// None named: the class of least distortion among those searched.
    Natural,
    /// Basis index on each mesh and rotation τ.
    Explicit { basis: [usize; 2], rotation: usize },
    /// Where each source loop goes (`a1 -> b1`, …).
    Matching(&'a [String]),
}

impl HomologyOptions {
    pub fn relax(&self) -> RelaxOptions {
        RelaxOptions { smoothing: self.smoothing, metric_samples: self.metric_samples }
    }

    /// The class asked for: a matching first, then an explicit basis or rotation (the other at
    /// 0), else the natural one.
    pub fn class_choice(&self) -> ClassChoice<'_> {
        match (&self.matching, self.basis, self.rotation) {
            (Some(m), _, _) => ClassChoice::Matching(m),
            (None, None, None) => ClassChoice::Natural,
            (None, b, r) => ClassChoice::Explicit { basis: b.unwrap_or([0, 0]), rotation: r.unwrap_or(0) },
        }
    }
}

impl JobSpec {
    /// Parses a spec: the one place JSON becomes a job.
    ///
    /// # Errors
    /// `InputError::UnknownMethod` for an unknown `"method"`; `InputError::Spec`
    /// naming the field at fault otherwise.
    pub fn from_json(bytes: &[u8]) -> Result<JobSpec> {
        let v: serde_json::Value =
            serde_json::from_slice(bytes).map_err(|e| InputError::Spec(format!("spec is not JSON: {e}")))?;
        JobSpec::from_value(v)
    }

    /// [`JobSpec::from_json`] of a spec that arrived inside a larger JSON document.
    ///
    /// # Errors
    /// As [`JobSpec::from_json`].
    pub fn from_value(v: serde_json::Value) -> Result<JobSpec> {
        match v.get("method") {
            Some(serde_json::Value::String(m)) if !METHODS.contains(&m.as_str()) => {
                return Err(InputError::UnknownMethod(format!(
                    "unknown method {m:?}; available: {}",
                    METHODS.join(", ")
                ))
                .into());
            }
            None => {
                // No method: the service picks one.
                let mut v = v;
                if let Some(o) = v.as_object_mut() {
                    o.insert("method".into(), "auto".into());
                }
                return JobSpec::deserialize(v).map_err(|e| InputError::Spec(e.to_string()).into());
            }
            _ => {}
        }
        JobSpec::deserialize(v).map_err(|e| InputError::Spec(e.to_string()).into())
    }

    /// A `voronoi` or `greedy` spec from a bare anchors file `{"anchors": [[s, t], ...]}` or
    /// `[[s, t], ...]`, every option at its default.
    ///
    /// # Errors
    /// `InputError::Spec` when the JSON has neither form.
    pub fn from_anchors_json(bytes: &[u8], method: Method) -> Result<JobSpec> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum A {
            Obj { anchors: Vec<AnchorRow> },
            List(Vec<AnchorRow>),
        }
        let a: A = serde_json::from_slice(bytes).map_err(|e| InputError::Spec(format!("anchors file: {e}")))?;
        let (A::Obj { anchors } | A::List(anchors)) = a;
        match method {
            Method::Voronoi => {
                Ok(JobSpec::Voronoi(LayoutSpec { boundaries: Vec::new(), anchors, options: MapOptions::default() }))
            }
            Method::Greedy => {
                Ok(JobSpec::Greedy(LayoutSpec { boundaries: Vec::new(), anchors, options: MapOptions::default() }))
            }
            Method::Homology => Ok(JobSpec::Homology(HomologySpec {
                anchors,
                features: Vec::new(),
                options: HomologyOptions::default(),
            })),
            Method::Quad => Err(InputError::Spec("a quad job needs a spec (`--spec`)".into()).into()),
            Method::Spherical => {
                Ok(JobSpec::Spherical(SphericalSpec { anchors, options: SphericalOptions::default() }))
            }
            Method::Auto => {
                Ok(JobSpec::Auto(AutoSpec { anchors, features: Vec::new(), options: AutoOptions::default() }))
            }
        }
    }

    pub fn method(&self) -> Method {
        match self {
            JobSpec::Voronoi(_) => Method::Voronoi,
            JobSpec::Greedy(_) => Method::Greedy,
            JobSpec::Homology(_) => Method::Homology,
            JobSpec::Quad(_) => Method::Quad,
            JobSpec::Spherical(_) => Method::Spherical,
            JobSpec::Auto(_) => Method::Auto,
        }
    }

    /// The spec as JSON (what the store keeps; [`JobSpec::from_json`] reads it back as is).
    ///
    /// # Errors
    /// `Internal` if serialization fails.
    pub fn to_json(&self) -> Result<String> {
        serde_json::to_string(self).map_err(|e| Error::Internal(e.to_string()))
    }
}
