//! A mesh in two parts (the shared torus plus a small separate sphere) onto a bent copy: the
//! parts pair through the anchors, each pair is mapped on its own, and the joined map of the
//! whole is fold-free with every anchor exact. A part without anchors is named in the error.

mod common;
use geom::mesh::{Mesh, P3, V3, shapes};
use geom::pipeline::{AnchorRow, JobReport, JobSpec, LayoutSpec, MapOptions, run_job};
use geom::progress::NoProgress;

fn with_sphere(m: &Mesh) -> Mesh {
    let (lo, hi) = m.bbox();
    let r = (hi - lo).norm() * 0.05;
    let c = hi.coords + V3::new(r * 3.0, 0.0, 0.0);
    let sphere = shapes::icosphere(2);
    let mut pos = m.positions().to_vec();
    pos.extend(sphere.positions().iter().map(|p| P3::from(c + p.coords * r)));
    let n = m.n_vertices() as u32;
    let mut tris = m.face_indices();
    tris.extend(sphere.face_indices().iter().map(|t| t.map(|v| v + n)));
    Mesh::from_triangles(pos, &tris).unwrap()
}

#[test]
fn a_two_part_mesh_maps_part_by_part() {
    let torus = common::load("torus.obj");
    let s = with_sphere(&torus);
    let t = common::bent(&s);
    let n = torus.n_vertices() as u64;
    let mut anchors: Vec<[u64; 2]> =
        common::fps(&torus, 12).into_iter().map(|a| [u64::from(a), u64::from(a)]).collect();
    anchors.extend([0u64, 7, 19, 33].iter().map(|&k| [n + k, n + k]));
    let spec = JobSpec::Voronoi(LayoutSpec {
        boundaries: Vec::new(),
        anchors: AnchorRow::ids(anchors.clone()),
        options: MapOptions { metric_samples: 5000, ..Default::default() },
    });
    let (report, arts) = run_job(&spec, &[s.clone(), t.clone()], &mut NoProgress).unwrap();
    let JobReport::Parts(p) = &report else { panic!("not a parts report") };
    assert_eq!(p.part_pairs, vec![[0, 0], [1, 1]]);
    for m in [&p.pair.source_to_target, &p.pair.target_to_source] {
        assert_eq!(m.flipped_faces, 0, "{m:?}");
        assert!(m.anchor_error_max.unwrap() <= 1e-9, "{m:?}");
        assert!(m.off_surface_max <= 1e-6, "{m:?}");
    }
    let mapped = common::source_on_target(&arts, &s, &t);
    assert_eq!(mapped.faces(), s.faces());
    // Every source vertex stays on its part's partner: the small sphere maps onto the small sphere.
    let small = &t.positions()[torus.n_vertices()..];
    let lo = small.iter().fold(P3::new(f64::MAX, f64::MAX, f64::MAX), |a, p| a.inf(p));
    let hi = small.iter().fold(P3::new(f64::MIN, f64::MIN, f64::MIN), |a, p| a.sup(p));
    for p in &mapped.positions()[torus.n_vertices()..] {
        assert!((0..3).all(|k| p[k] >= lo[k] - 1e-9 && p[k] <= hi[k] + 1e-9), "{p} outside the target sphere");
    }
    for name in ["morph.glb", "part0_layout.json", "part1_metrics.json", "metrics.json"] {
        assert!(arts.iter().any(|a| a.name == name), "missing {name}");
    }

    // Without anchors on the sphere: the error names it.
    let spec = JobSpec::Voronoi(LayoutSpec {
        boundaries: Vec::new(),
        anchors: AnchorRow::ids(anchors[..12].to_vec()),
        options: MapOptions::default(),
    });
    let e = run_job(&spec, &[s.clone(), t.clone()], &mut NoProgress).unwrap_err();
    assert_eq!(e.code(), "invalid_anchors");
    assert!(e.to_string().contains("source part 1") && e.to_string().contains("no anchor"), "{e}");
}
