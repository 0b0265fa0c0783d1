//! Map quality metrics with exactly the definitions of `shared/eval/meshmetrics.py`:
//! off-surface distance, flipped faces, area ratio, L2 / L-inf stretch, angle distortion,
//! degenerate faces, sampled Hausdorff / RMS / PSNR, anchor error and ground-truth error.
//! Distances are divided by the target's bounding-box diagonal, ground-truth error by the
//! square root of the target's area.

mod distance;
mod distortion;
mod flips;
mod numpy_rng;
mod surface_index;

pub use distance::{HausdorffResult, hausdorff, sample_surface};
pub use distortion::{Distortion, distortion};
pub use flips::flipped_faces;
pub use numpy_rng::NumpyRng;
pub(crate) use surface_index::centroid as face_centroid;
pub(crate) use surface_index::closest_point_on_triangle as closest_point;
pub use surface_index::{Nearest, SurfaceIndex};

use crate::error::{InputError, Result};
use crate::mesh::{Mesh, VertexId};
use serde::{Deserialize, Serialize};

/// Options for [`evaluate_map`].
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct MetricsOptions {
    /// Surface samples per direction for Hausdorff / RMS (the evaluator's default is 100000).
    pub samples: usize,
    /// Seeds of the sampling on the mapped and on the target surface (the evaluator's 1 and 2).
    pub seeds: (u64, u64),
}

impl Default for MetricsOptions {
    fn default() -> Self {
        Self { samples: 100_000, seeds: (1, 2) }
    }
}

/// How many flipped faces a report lists by id.
pub const MAX_LISTED_FLIPS: usize = 100;

/// The evaluator's keys.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct MapMetrics {
    pub vertices: usize,
    pub faces: usize,
    pub off_surface_max: f64,
    pub off_surface_mean: f64,
    pub flipped_faces: usize,
    /// The first [`MAX_LISTED_FLIPS`] flipped faces (face ids of the mapped mesh, increasing):
    /// where a folded map folds. Not an evaluator key; absent when there are none.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub flipped_face_ids: Vec<usize>,
    pub area_ratio: f64,
    pub l2_stretch: f64,
    pub linf_stretch: f64,
    pub angle_distortion: f64,
    pub degenerate_faces: usize,
    pub hausdorff: f64,
    pub rms: f64,
    pub psnr_db: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub anchor_error_max: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gt_error_mean: Option<f64>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gt_error_max: Option<f64>,
}

/// Measures `mapped` (the source's connectivity with vertices on the target) against `source`
/// and `target`. `anchors` are (source vertex, target vertex) pairs; `gt` gives the true target
/// vertex of every source vertex.
///
/// # Errors
/// `InputError::TopologyMismatch` when `mapped` does not have the source's vertices and faces;
/// `OutOfRange` for anchors or ground-truth entries outside the meshes.
pub fn evaluate_map(
    source: &Mesh,
    target: &Mesh,
    mapped: &Mesh,
    anchors: Option<&[(VertexId, VertexId)]>,
    gt: Option<&[VertexId]>,
    opts: &MetricsOptions,
) -> Result<MapMetrics> {
    if mapped.n_vertices() != source.n_vertices() || mapped.faces() != source.faces() {
        return Err(InputError::TopologyMismatch(format!(
            "mapped mesh must have the source mesh's vertex count and faces (source {} vertices / {} faces, mapped {} / {})",
            source.n_vertices(),
            source.n_faces(),
            mapped.n_vertices(),
            mapped.n_faces()
        ))
        .into());
    }
    let diag = target.bbox_diagonal();
    let index = SurfaceIndex::new(target)?;
    let proj: Vec<Nearest> = index.query_all(mapped.positions());
    let n = proj.len().max(1) as f64;
    let off_max = proj.iter().map(|p| p.distance).fold(0.0, f64::max);
    let dists: Vec<f64> = proj.iter().map(|p| p.distance).collect();
    let off_mean = distance::pairwise_sum(&dists) / n;
    let flipped = flipped_faces(mapped, target, &index, &proj);
    let area_ratio = mapped.area() / target.area();
    let d = distortion(source, mapped);
    let h = hausdorff(mapped, target, opts.samples, opts.seeds)?;
    let rms = h.rms / diag;
    let anchor_error_max = match anchors {
        Some(a) if !a.is_empty() => {
            let mut m: f64 = 0.0;
            for &(s, t) in a {
                check(s, source.n_vertices(), "anchor source vertex")?;
                check(t, target.n_vertices(), "anchor target vertex")?;
                m = m.max((mapped.position(s) - target.position(t)).norm() / diag);
            }
            Some(m)
        }
        _ => None,
    };
    let (gt_error_mean, gt_error_max) = match gt {
        Some(g) => {
            if g.len() != source.n_vertices() {
                return Err(InputError::Invalid(format!(
                    "ground truth has {} entries for {} source vertices",
                    g.len(),
                    source.n_vertices()
                ))
                .into());
            }
            let s = target.area().sqrt();
            let mut sum = 0.0;
            let mut mx: f64 = 0.0;
            for (i, &t) in g.iter().enumerate() {
                check(t, target.n_vertices(), "ground-truth target vertex")?;
                let e = (mapped.positions()[i] - target.position(t)).norm() / s;
                sum += e;
                mx = mx.max(e);
            }
            (Some(sum / g.len().max(1) as f64), Some(mx))
        }
        None => (None, None),
    };
    Ok(MapMetrics {
        vertices: source.n_vertices(),
        faces: source.n_faces(),
        off_surface_max: off_max / diag,
        off_surface_mean: off_mean / diag,
        flipped_faces: flipped.len(),
        flipped_face_ids: flipped.iter().copied().take(MAX_LISTED_FLIPS).collect(),
        area_ratio,
        l2_stretch: d.l2_stretch,
        linf_stretch: d.linf_stretch,
        angle_distortion: d.angle_distortion,
        degenerate_faces: d.degenerate_faces,
        hausdorff: h.hausdorff / diag,
        rms,
        psnr_db: 20.0 * (1.0 / rms.max(crate::tol::TINY)).log10(),
        anchor_error_max,
        gt_error_mean,
        gt_error_max,
    })
}

fn check(v: VertexId, n: usize, what: &'static str) -> Result<()> {
    if v.idx() >= n {
        return Err(InputError::OutOfRange { what, index: v.idx(), count: n }.into());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{P3, shapes};

    #[test]
    fn identity_map_is_perfect() {
        let s = shapes::icosphere(2);
        let m = evaluate_map(
            &s,
            &s,
            &s,
            Some(&[(VertexId(0), VertexId(0))]),
            None,
            &MetricsOptions { samples: 2000, seeds: (1, 2) },
        )
        .unwrap();
        assert_eq!(m.flipped_faces, 0);
        assert!(m.off_surface_max < 1e-12);
        assert!((m.area_ratio - 1.0).abs() < 1e-12);
        assert!((m.l2_stretch - 1.0).abs() < 1e-9);
        assert!((m.linf_stretch - 1.0).abs() < 1e-9);
        assert!(m.angle_distortion.abs() < 1e-9);
        assert_eq!(m.anchor_error_max, Some(0.0));
        assert!(m.hausdorff < 1e-12);
    }

    #[test]
    fn uniform_scaling_has_no_stretch_after_normalisation() {
        let s = shapes::icosphere(2);
        let big = s.with_positions(s.positions().iter().map(|p| P3::from(p.coords * 3.0)).collect()).unwrap();
        let m = evaluate_map(&s, &big, &big, None, None, &MetricsOptions { samples: 1000, seeds: (1, 2) }).unwrap();
        assert!((m.l2_stretch - 1.0).abs() < 1e-9);
        assert!(m.angle_distortion.abs() < 1e-9);
    }

    #[test]
    fn mismatched_connectivity_is_refused() {
        let a = shapes::icosphere(1);
        let b = shapes::icosphere(2);
        let e = evaluate_map(&a, &b, &b, None, None, &MetricsOptions::default()).unwrap_err();
        assert_eq!(e.code(), "topology_mismatch");
    }
}
