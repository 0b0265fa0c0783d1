//! Property tests of the inspect path (issue 51): meshes with extreme coordinates (overflowing,
//! underflowing, coincident, flat), written in every format (OBJ, OFF, PLY, STL, glTF) and as
//! OBJ/OFF text with hostile number tokens, read back and summarized. Nothing panics; every
//! mesh either passes `checked_summary` with finite numbers, an extent and (closed) no flat
//! face, or is refused with a typed input error.

use geom::io::{self, Format, ReadOptions};
use geom::mesh::{MeshLimits, P3};
use proptest::prelude::*;

/// A coordinate from the ranges that break arithmetic, or an ordinary one.
fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![
        -10.0f64..10.0,
        Just(0.0),
        Just(-0.0),
        prop_oneof![Just(1e200), Just(-1e200), Just(1e308), Just(-1.7e308), Just(1e75), Just(1.01e75), Just(3e38)],
        prop_oneof![Just(1e-300), Just(5e-324), Just(1e-160), Just(1e-80)],
        (-1.0f64..1.0, -320i32..320).prop_map(|(m, e)| m * 10f64.powi(e)),
    ]
}

/// Text tokens a hostile file may hold where a number belongs.
fn token() -> impl Strategy<Value = String> {
    prop_oneof![
        coordinate().prop_map(|c| format!("{c:e}")),
        prop_oneof![
            Just("1e400"),
            Just("-1e400"),
            Just("1e-400"),
            Just("nan"),
            Just("inf"),
            Just("-0"),
            Just("0x10"),
            Just("1e")
        ]
        .prop_map(str::to_string),
    ]
}

/// The tetrahedron's faces (closed) or three of them (open), on `positions`.
fn tetra_faces(closed: bool) -> Vec<[u32; 3]> {
    let all = [[0, 2, 1], [0, 1, 3], [1, 2, 3], [0, 3, 2]];
    all[..if closed { 4 } else { 3 }].to_vec()
}

fn check(bytes: &[u8], hint: Option<Format>) -> Result<(), TestCaseError> {
    let opts = ReadOptions { limits: MeshLimits { max_vertices: 10_000, max_faces: 20_000 }, hint };
    let r = match io::read(bytes, &opts) {
        Ok(r) => r,
        Err(e) => {
            prop_assert!(e.is_input(), "non-input error {e:?}");
            return Ok(());
        }
    };
    let plain = geom::topology::summary(&r.mesh);
    match geom::topology::checked_summary(&r.mesh, None) {
        Ok(s) => {
            prop_assert_eq!(&s, &plain);
            let nums: Vec<f64> = s.bbox.iter().flatten().copied().chain([s.bbox_diagonal, s.area]).collect();
            prop_assert!(nums.iter().all(|v| v.is_finite()), "{:?}", s);
            prop_assert!(s.bbox_diagonal > 0.0 && s.area > 0.0, "{:?}", s);
            // The JSON the server stores reads back (no null), finite.
            let back: geom::topology::Summary = serde_json::from_str(&serde_json::to_string(&s).unwrap()).unwrap();
            prop_assert!(back.check_finite().is_ok() && back.faces == s.faces, "{:?}", back);
        }
        Err(e) => prop_assert!(
            e.is_input() && ["mesh_not_finite", "mesh_no_extent", "zero_area_face"].contains(&e.code()),
            "unexpected refusal {e:?}"
        ),
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, failure_persistence: None, .. ProptestConfig::default() })]

    /// Extreme coordinates through every writer and reader.
    #[test]
    fn extreme_meshes_in_every_format_inspect_cleanly(
        coords in proptest::collection::vec([coordinate(), coordinate(), coordinate()], 4),
        closed in any::<bool>(),
        scale in prop_oneof![Just(1.0), Just(1e-300), Just(1e300)],
    ) {
        let pos: Vec<P3> = coords.iter().map(|c| P3::new(c[0] * scale, c[1] * scale, c[2] * scale)).collect();
        if pos.iter().any(|p| p.coords.iter().any(|c| !c.is_finite())) {
            return Ok(());
        }
        let Ok(mesh) = geom::Mesh::from_triangles(pos, &tetra_faces(closed)) else { return Ok(()) };
        check_mesh_formats(&mesh)?;
    }

    /// OBJ and OFF text with hostile number tokens.
    #[test]
    fn hostile_number_tokens_inspect_cleanly(toks in proptest::collection::vec(token(), 12), closed in any::<bool>()) {
        let faces = tetra_faces(closed);
        let mut obj = String::new();
        let mut off = format!("OFF\n4 {} 0\n", faces.len());
        for v in toks.chunks(3) {
            obj.push_str(&format!("v {} {} {}\n", v[0], v[1], v[2]));
            off.push_str(&format!("{} {} {}\n", v[0], v[1], v[2]));
        }
        for f in &faces {
            obj.push_str(&format!("f {} {} {}\n", f[0] + 1, f[1] + 1, f[2] + 1));
            off.push_str(&format!("3 {} {} {}\n", f[0], f[1], f[2]));
        }
        check(obj.as_bytes(), Some(Format::Obj))?;
        check(off.as_bytes(), Some(Format::Off))?;
    }
}

fn check_mesh_formats(mesh: &geom::Mesh) -> Result<(), TestCaseError> {
    for f in [Format::Obj, Format::Off, Format::Ply, Format::Stl, Format::Gltf] {
        check(&io::write(mesh, f), Some(f))?;
    }
    Ok(())
}

/// The cases of issue 51, named: the 1e200 tetrahedron, one point, a flat face.
#[test]
fn issue_51_meshes_are_refused_in_every_format() {
    let mut cases = Vec::new();
    for (k, code) in [(1e200, "mesh_not_finite"), (0.0, "mesh_no_extent")] {
        let p = [[k, 0.0, 0.0], [-k, 0.0, 0.0], [0.0, k, 0.0], [0.0, 0.0, k]];
        cases.push((p, code));
    }
    cases.push(([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], "zero_area_face"));
    for (p, code) in cases {
        let pos: Vec<P3> = p.iter().map(|c| P3::new(c[0], c[1], c[2])).collect();
        let mesh = geom::Mesh::from_triangles(pos, &tetra_faces(true)).unwrap();
        // The formats that keep f64 (STL and glTF store f32: 1e200 does not survive them).
        for f in [Format::Obj, Format::Off, Format::Ply] {
            let r = io::read(&io::write(&mesh, f), &ReadOptions::default()).unwrap();
            let e = geom::topology::checked_summary(&r.mesh, None).unwrap_err();
            assert_eq!(e.code(), code, "{f:?}");
        }
    }
}
