//! `auto` between `voronoi` and `spherical` on two closed genus-0 meshes: are they the same
//! shape? Measured from the anchors: the graph-geodesic distance between every two anchors on
//! each mesh, in units of `√area`, and the median relative difference over the pairs.
//!
//! A smooth deformation or another triangulation of one shape keeps geodesic distances nearly
//! (`mkcase.py`'s twist, bend and scaling of each axis by up to 20%, at full strength: medians
//! 0.019-0.072 over 104 cases of every closed genus-0 shared mesh; SMPL man -> woman, whose
//! body shapes differ little, 0.008-0.013); different shapes do not (plane -> bird 0.113,
//! cat -> horse 0.102; cat -> lion, 0.065, stays with `voronoi`). `voronoi` maps same-shape cases that `spherical`
//! still folds; `spherical` maps the peer's different shapes with less distortion and cat ->
//! horse, which `voronoi` folds.

use crate::geodesic::{VertexDijkstraOptions, vertex_dijkstra};
use crate::mesh::{Mesh, VertexId};
use rayon::prelude::*;

/// Median relative difference of anchor geodesics above which two meshes are different shapes.
pub const DIFFERENT: f64 = 0.09;

/// At most this many anchors are measured (the first ones): `k` Dijkstra searches per mesh.
const MAX_ANCHORS: usize = 24;

/// The median over anchor pairs of `|d_s − d_t| / max(d_s, d_t)`, each distance along mesh
/// edges over `√area`; `None` with fewer than 3 anchors or an anchor out of range.
pub fn anchor_geodesic_difference(source: &Mesh, target: &Mesh, pairs: &[(VertexId, VertexId)]) -> Option<f64> {
    let pairs = &pairs[..pairs.len().min(MAX_ANCHORS)];
    if pairs.len() < 3 || pairs.iter().any(|(s, t)| s.idx() >= source.n_vertices() || t.idx() >= target.n_vertices()) {
        return None;
    }
    let ds = between(source, &pairs.iter().map(|p| p.0).collect::<Vec<_>>());
    let dt = between(target, &pairs.iter().map(|p| p.1).collect::<Vec<_>>());
    let mut r: Vec<f64> = (0..pairs.len())
        .flat_map(|i| ((i + 1)..pairs.len()).map(move |j| (i, j)))
        .map(|(i, j)| {
            let (a, b) = (ds[i][j], dt[i][j]);
            let m = a.max(b);
            if m > 0.0 && m.is_finite() { (a - b).abs() / m } else { 1.0 }
        })
        .collect();
    r.sort_by(f64::total_cmp);
    r.get(r.len() / 2).copied()
}

/// Per anchor, its distance along edges to every other anchor, over `√area`
/// ([`vertex_dijkstra`] from each, stopped once the anchors after it are settled: the
/// distances are symmetric, so anchor `i` measures the pairs `(i, j > i)`).
fn between(mesh: &Mesh, anchors: &[VertexId]) -> Vec<Vec<f64>> {
    let scale = mesh.area().sqrt().max(f64::MIN_POSITIVE);
    let k = anchors.len();
    let rows: Vec<Vec<f64>> = (0..k)
        .into_par_iter()
        .map(|i| {
            let later = &anchors[i + 1..];
            if later.is_empty() {
                return Vec::new();
            }
            let opts = VertexDijkstraOptions { until_settled: Some(later), ..Default::default() };
            vertex_dijkstra(mesh, &[(anchors[i], 0.0)], &opts).map_or_else(
                |_| vec![f64::INFINITY; later.len()],
                |r| later.iter().map(|b| r.dist[b.idx()] / scale).collect(),
            )
        })
        .collect();
    let mut d = vec![vec![0.0; k]; k];
    for (i, row) in rows.iter().enumerate() {
        for (j, &x) in row.iter().enumerate() {
            d[i][i + 1 + j] = x;
            d[i + 1 + j][i] = x;
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn a_turned_and_scaled_copy_is_the_same_shape_and_a_stretched_one_is_not() {
        let a = shapes::icosphere(3);
        let twisted = turned(&a);
        let pairs: Vec<(VertexId, VertexId)> =
            [0u32, 7, 40, 300, 500, 600].iter().map(|&v| (VertexId(v), VertexId(v))).collect();
        let same = anchor_geodesic_difference(&a, &twisted, &pairs).unwrap();
        assert!(same < DIFFERENT, "{same}");
        let long = a
            .with_positions(a.positions().iter().map(|p| crate::mesh::P3::new(3.0 * p.x, p.y, 0.5 * p.z)).collect())
            .unwrap();
        let differ = anchor_geodesic_difference(&a, &long, &pairs).unwrap();
        assert!(differ > DIFFERENT, "{differ}");
        assert_eq!(anchor_geodesic_difference(&a, &long, &pairs[..2]), None);
    }

    /// A copy turned about an axis and scaled: the same shape, at another size and place.
    fn turned(m: &Mesh) -> Mesh {
        let r = nalgebra::Rotation3::from_axis_angle(&crate::mesh::V3::y_axis(), 0.7);
        m.with_positions(m.positions().iter().map(|p| r * crate::mesh::P3::from(p.coords * 2.5)).collect()).unwrap()
    }

    /// `auto` on two closed spheres: `voronoi` for a turned copy, `spherical` for a stretched
    /// one, each with the figure in its reason.
    #[test]
    fn auto_picks_voronoi_for_the_same_shape_and_spherical_for_different_shapes() {
        use crate::pipeline::plan::{MethodPlan, Plan};
        use crate::pipeline::spec::JobSpec;
        let a = shapes::icosphere(3);
        let long = a
            .with_positions(a.positions().iter().map(|p| crate::mesh::P3::new(3.0 * p.x, p.y, 0.5 * p.z)).collect())
            .unwrap();
        let spec = JobSpec::from_json(br#"{"anchors": [[0, 0], [7, 7], [40, 40], [300, 300], [500, 500]]}"#).unwrap();
        let same = [a.clone(), turned(&a)];
        let plan = Plan::new(&spec, &same, &[]).unwrap();
        assert!(matches!(plan.method, MethodPlan::Layout(..)), "{:?}", plan.method);
        let why = plan.auto.as_ref().unwrap();
        assert!(why.method == "voronoi" && why.reason.contains("the same shape"), "{why:?}");
        let differ = [a, long];
        let plan = Plan::new(&spec, &differ, &[]).unwrap();
        assert!(matches!(plan.method, MethodPlan::Spherical(_)), "{:?}", plan.method);
        let why = plan.auto.as_ref().unwrap();
        assert!(why.method == "spherical" && why.reason.contains("different shapes"), "{why:?}");
    }
}
