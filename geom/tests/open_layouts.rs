//! `voronoi` and `greedy` on open meshes: loops closed by cones, loop segments and spokes as
//! fixed layout paths, maps restricted to the open meshes. Invariants: 0 flips both ways,
//! anchors exact, every boundary vertex's image on the partner loop, the loop report; typed
//! errors for loop counts that differ and for anchors that run the other way round a loop.

use geom::mesh::{Mesh, P3, VertexId, shapes};
use geom::pipeline::{AnchorRow, JobReport, JobSpec, LayoutSpec, MapOptions, run_job};
use geom::progress::NoProgress;

/// An icosphere with the faces around the given vertices removed: one loop per vertex.
fn holed(holes: &[u32]) -> Mesh {
    shapes::icosphere_with_holes(3, holes)
}

fn stretched(m: &Mesh) -> Mesh {
    m.with_positions(m.positions().iter().map(|p| P3::new(1.5 * p.x, p.y + 0.2 * p.x * p.x, 0.8 * p.z)).collect())
        .unwrap()
}

fn spec(method: &str, anchors: &[u64]) -> JobSpec {
    let l = LayoutSpec {
        boundaries: Vec::new(),
        anchors: AnchorRow::ids(anchors.iter().map(|&a| [a, a])),
        options: MapOptions { metric_samples: 2000, ..Default::default() },
    };
    if method == "greedy" { JobSpec::Greedy(l) } else { JobSpec::Voronoi(l) }
}

fn layout_report(r: &JobReport) -> &geom::pipeline::layout::LayoutMapReport {
    match r {
        JobReport::Layout(l) => l,
        other => panic!("not a layout report: {other:?}"),
    }
}

#[test]
fn a_sphere_with_a_hole_maps_loop_onto_loop_both_ways() {
    let s = holed(&[0]);
    let t = stretched(&s);
    for method in ["voronoi", "greedy"] {
        // No anchor on the loop: it pairs through the nearest anchor.
        let (r, _) =
            run_job(&spec(method, &[20, 61, 100, 150, 222, 301, 400, 500]), &[s.clone(), t.clone()], &mut NoProgress)
                .unwrap_or_else(|e| panic!("{method}: {e}"));
        let l = layout_report(&r);
        for m in [&l.pair.source_to_target, &l.pair.target_to_source] {
            assert_eq!(m.flipped_faces, 0, "{method}");
            assert!(m.anchor_error_max.unwrap() <= 1e-9, "{method}");
        }
        assert_eq!(l.boundaries.len(), 1);
        let b = &l.boundaries[0];
        assert_eq!(b.paired_by, "nearest_anchor");
        assert_eq!(b.off_loop, [0, 0], "{method}: {b:?}");
        assert!(b.added >= 3, "three loop anchors at least: {b:?}");
    }
}

#[test]
fn two_holes_pair_through_their_anchors() {
    // Vertices 0 and 3 of the icosahedron are far apart; anchors on both loops pair them.
    let s = holed(&[0, 3]);
    let t = stretched(&s);
    let loops = geom::topology::boundary_loops(&s);
    assert_eq!(loops.len(), 2);
    let on_loop: Vec<u64> = loops.iter().map(|l| u64::from(s.tail(l[0]).0)).collect();
    let mut anchors = vec![20, 61, 100, 150, 222, 301];
    anchors.extend(&on_loop);
    let (r, _) = run_job(&spec("voronoi", &anchors), &[s, t], &mut NoProgress).unwrap();
    let l = layout_report(&r);
    assert_eq!(l.boundaries.len(), 2);
    for b in &l.boundaries {
        assert_eq!(b.paired_by, "anchors");
        assert_eq!(b.off_loop, [0, 0], "{b:?}");
    }
    assert_eq!(l.pair.source_to_target.flipped_faces + l.pair.target_to_source.flipped_faces, 0);
}

#[test]
fn loop_counts_that_differ_name_the_loops() {
    let (s, t) = (holed(&[0]), holed(&[0, 3]));
    let e = geom::pipeline::layout::run(
        geom::pipeline::Method::Voronoi,
        match &spec("voronoi", &[20, 61, 100, 150]) {
            JobSpec::Voronoi(l) => l,
            _ => unreachable!(),
        },
        &s,
        &t,
        &mut NoProgress,
    )
    .unwrap_err();
    assert_eq!(e.code(), "topology_mismatch");
    let m = e.to_string();
    assert!(m.contains("first_vertex") && m.contains("1 boundary loops") && m.contains("2 "), "{m}");
}

#[test]
fn anchors_running_the_other_way_round_a_loop_are_refused() {
    let s = holed(&[0]);
    let t = stretched(&s);
    let lp: Vec<VertexId> = geom::topology::boundary_loops(&s)[0].iter().map(|&h| s.tail(h)).collect();
    let n = lp.len();
    // Three loop vertices in loop order on the source, in reverse order on the target.
    let (a, b, c) = (lp[0].0 as u64, lp[n / 3].0 as u64, lp[2 * n / 3].0 as u64);
    let mut l = match spec("voronoi", &[20, 61, 100]) {
        JobSpec::Voronoi(l) => l,
        _ => unreachable!(),
    };
    l.anchors.extend(AnchorRow::ids([[a, a], [b, c], [c, b]]));
    let e = run_job(&JobSpec::Voronoi(l), &[s, t], &mut NoProgress).unwrap_err();
    assert_eq!(e.code(), "invalid_anchors", "{e}");
    assert!(e.to_string().contains("another order"), "{e}");
}

#[test]
fn an_open_part_beside_a_closed_one_maps_with_its_boundaries_row() {
    // A holed sphere plus a small closed sphere, in one mesh; the hole's loop is named by a
    // `boundaries` row in whole-mesh ids, which the part's job gets in its own ids.
    let disk = holed(&[0]);
    let small = shapes::icosphere(1);
    let n = disk.n_vertices() as u32;
    let mut pos = disk.positions().to_vec();
    pos.extend(small.positions().iter().map(|p| P3::new(4.0 + 0.3 * p.x, 0.3 * p.y, 0.3 * p.z)));
    let mut tris = disk.face_indices();
    tris.extend(small.face_indices().iter().map(|t| t.map(|v| v + n)));
    let s = Mesh::from_triangles(pos, &tris).unwrap();
    let t = stretched(&s);
    let first = u64::from(disk.tail(geom::topology::boundary_loops(&disk)[0][0]).0);
    let mut anchors: Vec<u64> = vec![20, 61, 100, 150, 222, 301];
    anchors.extend([0u64, 3, 7, 9].iter().map(|k| u64::from(n) + k));
    let JobSpec::Voronoi(mut l) = spec("voronoi", &anchors) else { unreachable!() };
    l.boundaries = vec![[first, first]];
    let (r, _) = run_job(&JobSpec::Voronoi(l), &[s, t], &mut NoProgress).unwrap();
    let JobReport::Parts(p) = &r else { panic!("not a parts report") };
    for m in [&p.pair.source_to_target, &p.pair.target_to_source] {
        assert_eq!(m.flipped_faces, 0, "{m:?}");
        assert!(m.anchor_error_max.unwrap() <= 1e-9, "{m:?}");
    }
    let open = p.parts.iter().find_map(|x| match x {
        JobReport::Layout(l) if !l.boundaries.is_empty() => Some(l),
        _ => None,
    });
    let b = &open.expect("the open part's report").boundaries[0];
    assert_eq!(b.paired_by, "boundaries");
    assert_eq!(b.off_loop, [0, 0]);
}
