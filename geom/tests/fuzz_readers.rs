//! Property tests: mutated bytes of real files, fed to every reader, never panic. Each input
//! either reads into a valid mesh or fails with a typed input error; a mesh read passes the
//! upload checks with finite summary numbers or is refused as input.

mod common;
use geom::io::{self, Format, ReadOptions};
use proptest::prelude::*;
use std::sync::OnceLock;

fn seeds() -> &'static Vec<(Format, Vec<u8>)> {
    static S: OnceLock<Vec<(Format, Vec<u8>)>> = OnceLock::new();
    S.get_or_init(|| {
        let hand = common::load("hand_lowres.obj");
        let small = geom::mesh::shapes::subdivide(&geom::mesh::shapes::tetrahedron(), 2);
        let mut v = vec![
            (Format::Obj, std::fs::read(common::shared_mesh("hand_lowres.obj")).unwrap()),
            (Format::Off, std::fs::read(common::shared_mesh("eight_lowres.off")).unwrap()),
            (Format::Ply, io::write(&hand, Format::Ply)),
            (Format::Stl, io::write(&small, Format::Stl)),
            (Format::Off, io::write(&small, Format::Off)),
        ];
        // An ascii PLY and an ascii STL.
        let mut ply = format!("ply\nformat ascii 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n", small.n_vertices(), small.n_faces());
        for p in small.positions() {
            ply.push_str(&format!("{} {} {}\n", p.x, p.y, p.z));
        }
        for f in small.faces() {
            ply.push_str(&format!("3 {} {} {}\n", f[0], f[1], f[2]));
        }
        v.push((Format::Ply, ply.into_bytes()));
        let mut stl = String::from("solid s\n");
        for f in small.faces() {
            stl.push_str("facet normal 0 0 1\nouter loop\n");
            for i in f {
                let p = small.position(*i);
                stl.push_str(&format!("vertex {} {} {}\n", p.x, p.y, p.z));
            }
            stl.push_str("endloop\nendfacet\n");
        }
        stl.push_str("endsolid s\n");
        v.push((Format::Stl, stl.into_bytes()));
        // glTF: a GLB of a mesh with seams and attributes (spot), and the small mesh's GLB.
        v.push((Format::Gltf, std::fs::read(common::shared_mesh("spot.obj")).map(|b| common::glb_of_obj(&b)).unwrap()));
        v.push((Format::Gltf, io::write(&small, Format::Gltf)));
        v
    })
}

#[derive(Debug, Clone)]
enum Mutation {
    Flip(usize, u8),
    Truncate(usize),
    Insert(usize, Vec<u8>),
    Delete(usize, usize),
    Digit(usize, u8),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Mutation::Flip(i, b)),
        any::<usize>().prop_map(Mutation::Truncate),
        (any::<usize>(), proptest::collection::vec(any::<u8>(), 1..16)).prop_map(|(i, b)| Mutation::Insert(i, b)),
        (any::<usize>(), 1usize..64).prop_map(|(i, n)| Mutation::Delete(i, n)),
        (any::<usize>(), b'0'..=b'9').prop_map(|(i, d)| Mutation::Digit(i, d)),
    ]
}

fn apply(mut b: Vec<u8>, muts: &[Mutation]) -> Vec<u8> {
    for m in muts {
        let n = b.len().max(1);
        match m {
            Mutation::Flip(i, x) if !b.is_empty() => b[i % n] ^= x | 1,
            Mutation::Truncate(i) => b.truncate(i % n),
            Mutation::Insert(i, s) => {
                let at = i % (b.len() + 1);
                b.splice(at..at, s.iter().copied());
            }
            Mutation::Delete(i, k) if !b.is_empty() => {
                let at = i % n;
                let end = (at + k).min(b.len());
                b.drain(at..end);
            }
            Mutation::Digit(i, d) if !b.is_empty() => b[i % n] = *d,
            _ => {}
        }
    }
    b
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, failure_persistence: None, .. ProptestConfig::default() })]

    #[test]
    fn mutated_files_never_panic(which in 0usize..7, muts in proptest::collection::vec(mutation(), 1..4), hinted in any::<bool>()) {
        let (fmt, bytes) = &seeds()[which % seeds().len()];
        let data = apply(bytes.clone(), &muts);
        let opts = ReadOptions { hint: hinted.then_some(*fmt), ..ReadOptions::default() };
        match io::read(&data, &opts) {
            Ok(r) => {
                // Whatever was accepted is a valid manifold mesh.
                prop_assert!(r.mesh.n_faces() > 0);
                prop_assert!(r.mesh.positions().iter().all(|p| p.coords.iter().all(|c| c.is_finite())));
                let _ = geom::topology::summary(&r.mesh);
                // The upload checks accept it with finite numbers, or refuse it as bad input.
                match geom::topology::checked_summary(&r.mesh, None) {
                    Ok(s) => {
                        let nums = s.bbox.iter().flatten().chain([&s.bbox_diagonal, &s.area]);
                        prop_assert!(nums.clone().all(|v| v.is_finite()), "{s:?}");
                    }
                    Err(e) => prop_assert!(e.is_input(), "non-input error {e:?}"),
                }
            }
            Err(e) => prop_assert!(e.is_input(), "non-input error {e:?}"),
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 1500, failure_persistence: None, .. ProptestConfig::default() })]

    /// Random triangle soups: construction never panics, and every accepted mesh satisfies the
    /// half-edge invariants (twins are mutual, every vertex has a fan of faces).
    #[test]
    fn random_triangle_soups_build_or_fail_cleanly(tris in proptest::collection::vec([0u32..12, 0u32..12, 0u32..12], 1..30)) {
        let pos: Vec<[f64; 3]> = (0..12).map(|i| { let t = i as f64; [t.cos(), t.sin(), (t * 0.7).sin()] }).collect();
        let raw = geom::mesh::RawMesh::from_triangles(pos, &tris);
        match geom::Mesh::from_raw(raw) {
            Ok((m, _)) => {
                for h in 0..m.n_halfedges() {
                    let h = geom::HalfedgeId::from_idx(h);
                    if let Some(t) = m.twin(h) {
                        prop_assert_eq!(m.twin(t), Some(h));
                        prop_assert_eq!(m.tail(t), m.head(h));
                    }
                }
                for v in 0..m.n_vertices() {
                    prop_assert!(m.vertex_faces(geom::VertexId::from_idx(v)).count() > 0);
                }
            }
            Err(e) => prop_assert!(e.is_input()),
        }
    }
}
