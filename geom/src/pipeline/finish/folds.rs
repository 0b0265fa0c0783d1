//! No folded map is returned as a success. After a job's pipeline has run, a pair map with
//! flipped faces in either direction (the evaluator's count), or a `quad` parameterization with
//! flipped triangles, turns into [`Error::MapFolds`], which says how many, where (face ids and
//! the anchor nearest to each) and what to try; a fold-free one with an image off the surface
//! fails as `Numerical`. The one exception: a `homology` job that built
//! its meta-mesh pair, which is fold-free by construction, succeeds with the folded direction's
//! vertex-map artifacts withheld (listed in the report's `withheld`).

use crate::error::{Error, Result};
use crate::mesh::{Mesh, VertexId};
use crate::pipeline::common::{Artifact, on_surface};
use crate::pipeline::plan::{MethodPlan, Plan};
use crate::pipeline::report::JobReport;

/// Faces named per direction in the message.
const NAMED: usize = 3;

/// The vertex-map artifacts of each direction (source -> target, target -> source).
const VERTEX_MAPS: [[&str; 2]; 2] =
    [["source_on_target.obj", "source_to_target.csv"], ["target_on_source.obj", "target_to_source.csv"]];

/// Fails a folded result, or withholds the folded vertex maps of a meta-mesh job.
///
/// # Errors
/// `MapFolds` when a direction folds and no fold-free meta-mesh stands in for it.
pub(super) fn refuse_folds(plan: &Plan, report: &mut JobReport, arts: &mut Vec<Artifact>) -> Result<()> {
    let meshes = &*plan.meshes;
    if let JobReport::Quad(q) = report {
        let bad: Vec<String> = q
            .per_model
            .iter()
            .enumerate()
            .flat_map(|(m, r)| r.patches.iter().enumerate().map(move |(p, x)| (m, p, x.flipped_uv)))
            .filter(|x| x.2 > 0)
            .map(|(m, p, n)| format!("model {m} patch {p}: {n}"))
            .collect();
        let n: usize = q.per_model.iter().flat_map(|r| &r.patches).map(|x| x.flipped_uv).sum();
        if n == 0 {
            return Ok(());
        }
        return Err(Error::MapFolds {
            flipped: n,
            detail: format!(
                "parameter triangles flip ({}); try other partition points or more anchors near those patches",
                bad.join(", ")
            ),
        });
    }
    let meta_built = match report {
        JobReport::Homology(r) => r.homology.meta_mesh.as_ref().is_some_and(|m| m.error.is_none()),
        JobReport::Features(r) => r.features.meta_mesh.as_ref().is_some_and(|m| m.error.is_none()),
        _ => false,
    };
    let Some(pair) = report.pair_mut() else { return Ok(()) };
    let counts = [pair.source_to_target.flipped_faces, pair.target_to_source.flipped_faces];
    if counts == [0, 0] {
        return refuse_off_surface(pair, meshes);
    }
    if meta_built {
        for (d, names) in VERTEX_MAPS.iter().enumerate() {
            if counts[d] > 0 {
                arts.retain(|a| !names.contains(&a.name.as_str()));
                pair.withheld.extend(names.iter().map(|n| n.to_string()));
            }
        }
        return Ok(());
    }
    let [s, t] = meshes else { return Ok(()) };
    let anchors = plan.method.anchor_ids();
    let where_ = [(&pair.source_to_target, s, 0, "source"), (&pair.target_to_source, t, 1, "target")]
        .iter()
        .filter(|(m, ..)| m.flipped_faces > 0)
        .map(|(m, mesh, side, name)| {
            let faces: Vec<String> =
                m.flipped_face_ids.iter().take(NAMED).map(|&f| locate(mesh, f, &anchors, *side, name)).collect();
            format!(
                "{} -> {}: {} ({})",
                name,
                if *side == 0 { "target" } else { "source" },
                m.flipped_faces,
                faces.join("; ")
            )
        })
        .collect::<Vec<_>>()
        .join("; ");
    Err(Error::MapFolds { flipped: counts[0] + counts[1], detail: format!("{where_}. {}", remedies(&plan.method)) })
}

/// Largest distance of an image from the surface, as the evaluator reads it, relative to the
/// bounding-box diagonal of the mesh it lies on, that a success may have (a visible image is
/// exact to rounding; a hidden one is off by 1e-5 and more).
const OFF_SURFACE: f64 = 1e-6;

/// A fold-free pair map with an image off the surface is as wrong as a folded one: `Numerical`.
fn refuse_off_surface(pair: &crate::pipeline::common::PairReport, meshes: &[Mesh]) -> Result<()> {
    let [s, t] = meshes else { return Ok(()) };
    let bad: Vec<String> =
        [(&pair.source_to_target, t, "source -> target"), (&pair.target_to_source, s, "target -> source")]
            .iter()
            .filter(|(m, onto, _)| !on_surface(m, onto, OFF_SURFACE))
            .map(|(m, _, name)| format!("{name}: {:.3e}", m.off_surface_max))
            .collect();
    if bad.is_empty() {
        return Ok(());
    }
    Err(Error::Numerical(format!(
        "the map places images off the surface ({}); add anchors near them or try the other method",
        bad.join(", ")
    )))
}

/// "`name` face f at vertex v, nearest anchor #i (vertex w)".
fn locate(mesh: &Mesh, f: usize, anchors: &[[u64; 2]], side: usize, name: &str) -> String {
    let Some(&v) = mesh.faces().get(f).map(|tri| &tri[0]) else { return format!("{name} face {f}") };
    let p = mesh.position(v);
    let nearest = anchors
        .iter()
        .enumerate()
        .filter_map(|(i, a)| {
            let w = usize::try_from(a[side]).ok().filter(|&w| w < mesh.n_vertices())?;
            Some((i, w, (mesh.position(VertexId::from_idx(w)) - p).norm()))
        })
        .min_by(|a, b| a.2.total_cmp(&b.2));
    match nearest {
        Some((i, w, _)) => format!("{name} face {f} at vertex {}, nearest anchor #{i} ({name} vertex {w})", v.idx()),
        None => format!("{name} face {f} at vertex {}", v.idx()),
    }
}

fn remedies(plan: &MethodPlan) -> &'static str {
    match plan {
        MethodPlan::Layout(..) => {
            "Add anchors near these faces, or check that the anchors keep the same order around each other on both meshes (anchors that cross on one mesh and not the other fold any map); for two closed genus-0 meshes of different shapes, try method spherical"
        }
        MethodPlan::Spherical(_) => {
            "Add anchors near these faces (they sit where a thin part of one surface meets a thick part of the other), or try method voronoi"
        }
        MethodPlan::Homology(s) if !s.features.is_empty() => {
            "Set options.meta_mesh: true (its overlay is fold-free by construction), add anchors near these faces, or check the feature curves' order on both meshes"
        }
        _ => {
            "Try another homotopy class (options.basis, options.rotation or options.matching), set options.meta_mesh: true (its overlay is fold-free by construction), or add anchors near these faces"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::pipeline::report::MethodOutput;
    use crate::pipeline::{HomologyOptions, HomologySpec, JobSpec, LayoutSpec, MapOptions, run};
    use crate::progress::NoProgress;

    fn stretched(s: &Mesh) -> Mesh {
        s.with_positions(s.positions().iter().map(|p| crate::mesh::P3::new(1.3 * p.x, p.y, 0.8 * p.z)).collect())
            .unwrap()
    }

    /// A clean job passes untouched; the same report with flips in one direction fails with
    /// `map_folds`, naming the faces, their nearest anchor and the remedies.
    #[test]
    fn a_folded_layout_map_is_a_typed_failure() {
        let s = shapes::icosphere(2);
        let t = stretched(&s);
        let anchors: Vec<[u64; 2]> = [0u64, 5, 9, 13, 21, 40].iter().map(|&i| [i, i]).collect();
        let spec = JobSpec::Voronoi(LayoutSpec {
            boundaries: Vec::new(),
            anchors: crate::pipeline::AnchorRow::ids(anchors),
            options: MapOptions { metric_samples: 1000, ..Default::default() },
        });
        let meshes = [s, t];
        let plan = Plan::new(&spec, &meshes, &[]).unwrap();
        let MethodOutput { mut report, artifacts: mut arts } = run::run(&plan, &mut NoProgress).unwrap();
        assert!(refuse_folds(&plan, &mut report, &mut arts).is_ok());
        let JobReport::Layout(r) = &mut report else { panic!("a layout report") };
        // Fold-free with an image off the surface: a typed failure too.
        r.pair.source_to_target.off_surface_max = 0.01;
        let e = refuse_folds(&plan, &mut report, &mut arts).unwrap_err();
        assert_eq!(e.code(), "numerical");
        assert!(e.to_string().contains("off the surface (source -> target: 1.000e-2)"), "{e}");
        let JobReport::Layout(r) = &mut report else { panic!("a layout report") };
        r.pair.source_to_target.off_surface_max = 0.0;
        r.pair.target_to_source.flipped_faces = 2;
        r.pair.target_to_source.flipped_face_ids = vec![7, 11];
        let e = refuse_folds(&plan, &mut report, &mut arts).unwrap_err();
        assert_eq!(e.code(), "map_folds");
        let m = e.to_string();
        assert!(m.contains("(2 flipped faces)") && m.contains("target -> source: 2"), "{m}");
        assert!(m.contains("target face 7") && m.contains("target face 11") && m.contains("nearest anchor #"), "{m}");
        assert!(m.contains("Add anchors") && m.contains("try method spherical"), "{m}");
    }

    /// A `homology` job whose meta-mesh was built keeps its fold-free overlay: the folded
    /// direction's vertex maps are withheld and named in the report, and the job succeeds.
    #[test]
    fn a_meta_mesh_job_withholds_the_folded_vertex_maps() {
        let s = shapes::torus(16, 8, 1.0, 0.35);
        let t = stretched(&s);
        let options = HomologyOptions { meta_mesh: true, metric_samples: 1000, ..Default::default() };
        let spec = JobSpec::Homology(HomologySpec {
            anchors: crate::pipeline::AnchorRow::ids(vec![[0, 0]]),
            features: Vec::new(),
            options,
        });
        let meshes = [s, t];
        let plan = Plan::new(&spec, &meshes, &[]).unwrap();
        let MethodOutput { mut report, artifacts: mut arts } = run::run(&plan, &mut NoProgress).unwrap();
        let JobReport::Homology(r) = &mut report else { panic!("a homology report") };
        assert!(r.homology.meta_mesh.as_ref().is_some_and(|m| m.error.is_none()), "meta-mesh built");
        r.pair.source_to_target.flipped_faces = 1;
        r.pair.source_to_target.flipped_face_ids = vec![3];
        refuse_folds(&plan, &mut report, &mut arts).unwrap();
        let names: Vec<&str> = arts.iter().map(|a| a.name.as_str()).collect();
        assert!(!names.contains(&"source_on_target.obj") && !names.contains(&"source_to_target.csv"), "{names:?}");
        assert!(names.contains(&"target_on_source.obj") && names.contains(&"meta_source.obj"), "{names:?}");
        let withheld = &report.pair().unwrap().withheld;
        assert_eq!(withheld, &["source_on_target.obj", "source_to_target.csv"]);
    }
}
