//! Any job the service runs, behind one call: a pair job (`voronoi`, `greedy`, `homology`) on
//! two meshes, or a `quad` job on N meshes. The worker and the server go through here so a new
//! method needs no change in them beyond its name.

use super::remesh_spec::RemeshSpec;
use super::run::Artifact;
use super::spec::JobSpec;
use crate::error::{Error, InputError, Result};
use crate::mesh::Mesh;
use crate::progress::Progress;

/// Every method a job may name.
pub const METHODS: [&str; 4] = ["voronoi", "greedy", "homology", "quad"];

/// A parsed job spec.
#[derive(Debug, Clone, PartialEq)]
pub enum Job {
    Map(Box<JobSpec>),
    Remesh(RemeshSpec),
}

/// A finished job's report (`metrics.json`), method and stage timings.
#[derive(Debug, Clone)]
pub struct JobOutput {
    pub method: &'static str,
    pub timings_ms: Vec<(String, f64)>,
    pub report: serde_json::Value,
}

impl Job {
    /// Parses a spec, dispatching on `"method"`.
    ///
    /// # Errors
    /// `InputError::Spec` naming the field at fault or an unknown method.
    pub fn from_json(bytes: &[u8]) -> Result<Job> {
        let v: serde_json::Value =
            serde_json::from_slice(bytes).map_err(|e| InputError::Spec(format!("spec is not JSON: {e}")))?;
        match v.get("method").and_then(|m| m.as_str()) {
            Some("quad") => Ok(Job::Remesh(RemeshSpec::from_json(bytes)?)),
            Some(m) if !METHODS.contains(&m) => {
                Err(InputError::Spec(format!("unknown method {m:?}; available: {}", METHODS.join(", "))).into())
            }
            _ => Ok(Job::Map(Box::new(JobSpec::from_json(bytes)?))),
        }
    }

    pub fn method(&self) -> &'static str {
        match self {
            Job::Map(s) => s.method.name(),
            Job::Remesh(_) => "quad",
        }
    }

    /// The spec as JSON.
    ///
    /// # Errors
    /// `Internal` if serialization fails.
    pub fn to_json(&self) -> Result<String> {
        match self {
            Job::Map(s) => serde_json::to_string(s),
            Job::Remesh(s) => serde_json::to_string(s),
        }
        .map_err(|e| Error::Internal(e.to_string()))
    }

    /// Checks the job against its meshes' summaries before it is queued.
    ///
    /// # Errors
    /// The spec's own checks; `InputError::Spec` when a pair job gets other than two meshes.
    pub fn check(&self, summaries: &[crate::topology::Summary]) -> Result<()> {
        match self {
            Job::Map(s) => match summaries {
                [a, b] => s.check(a, b).map(|_| ()),
                _ => Err(InputError::Spec(format!(
                    "method {} maps a source onto a target: 2 meshes, got {}",
                    s.method.name(),
                    summaries.len()
                ))
                .into()),
            },
            Job::Remesh(s) => s.check(summaries).map(|_| ()),
        }
    }
}

/// Runs any job on its meshes (two for pair jobs, in source, target order).
///
/// # Errors
/// Whatever the method reports.
pub fn run_job(job: &Job, meshes: &[Mesh], progress: &mut dyn Progress) -> Result<(JobOutput, Vec<Artifact>)> {
    fn value<T: serde::Serialize>(r: &T) -> Result<serde_json::Value> {
        serde_json::to_value(r).map_err(|e| Error::Internal(e.to_string()))
    }
    match job {
        Job::Map(spec) => {
            let [s, t] = meshes else {
                return Err(InputError::Spec(format!(
                    "a {} job needs 2 meshes, got {}",
                    spec.method.name(),
                    meshes.len()
                ))
                .into());
            };
            let (r, a) = super::run_map(spec, s, t, progress)?;
            Ok((JobOutput { method: r.method, timings_ms: r.timings_ms.clone(), report: value(&r)? }, a))
        }
        Job::Remesh(spec) => {
            let (r, a) = super::run_remesh(spec, meshes, progress)?;
            Ok((JobOutput { method: r.method, timings_ms: r.timings_ms.clone(), report: value(&r)? }, a))
        }
    }
}
