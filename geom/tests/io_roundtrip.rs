//! Readers and writers: round trips in every format, attributes, index forms, encodings.

mod common;
use geom::io::{self, Format, ReadOptions};
use geom::mesh::{Mesh, RawMesh, V3, shapes};

fn read(b: &[u8]) -> io::ReadResult {
    io::read(b, &ReadOptions::default()).expect("read")
}

fn same_geometry(a: &Mesh, b: &Mesh, tol: f64) {
    assert_eq!(a.faces(), b.faces());
    for (p, q) in a.positions().iter().zip(b.positions()) {
        assert!((p - q).norm() <= tol, "{p} vs {q}");
    }
}

#[test]
fn every_format_round_trips_a_real_mesh() {
    let m = common::load("bunny.off");
    for f in [Format::Obj, Format::Off, Format::Ply] {
        let r = read(&io::write(&m, f));
        assert_eq!(r.format, f);
        same_geometry(&m, &r.mesh, 0.0);
    }
    // STL is single precision and welds by position: same counts, positions within f32.
    let r = read(&io::write(&m, Format::Stl));
    assert_eq!(r.format, Format::Stl);
    assert_eq!(r.mesh.n_vertices(), m.n_vertices());
    assert_eq!(r.mesh.n_faces(), m.n_faces());
    assert_eq!(geom::topology::genus(&r.mesh), 0);
}

fn with_attributes() -> Mesh {
    let g = shapes::grid(3);
    let n = g.n_vertices();
    let mut raw = RawMesh::from_triangles(g.positions().iter().map(|p| [p.x, p.y, p.z]).collect(), &g.face_indices());
    raw.attributes.normals = Some((0..n).map(|i| V3::new(0.0, (i as f64 * 0.1).sin(), 1.0).normalize()).collect());
    raw.attributes.colors = Some((0..n).map(|i| [i as u8 * 10, 255 - i as u8, 7, 255]).collect());
    raw.attributes.uvs = Some((0..n).map(|i| [i as f64 * 0.25, 1.0 - i as f64 * 0.125]).collect());
    Mesh::from_raw(raw).unwrap().0
}

#[test]
fn attributes_survive_where_the_format_allows() {
    let m = with_attributes();
    let a = m.attributes();
    for f in [Format::Ply, Format::Off] {
        let r = read(&io::write(&m, f));
        assert_eq!(r.mesh.attributes(), a, "{f:?}");
    }
    // OBJ keeps normals and UVs exactly; colours go through [0,1] floats and come back.
    let r = read(&io::write(&m, Format::Obj));
    let b = r.mesh.attributes();
    assert_eq!(b.normals, a.normals);
    assert_eq!(b.uvs, a.uvs);
    let ca = a.colors.as_ref().unwrap();
    let cb = b.colors.as_ref().unwrap();
    for (x, y) in ca.iter().zip(cb) {
        assert_eq!(x[..3], y[..3]);
    }
}

#[test]
fn obj_index_forms_negative_indices_and_polygons() {
    let src = b"# a square and a triangle\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 2 0\nvn 0 0 1\n\
o thing\ng part\nusemtl none\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf -4//-1 -1//-1 -3//-1\n";
    let r = read(src);
    assert_eq!(r.mesh.n_faces(), 3);
    assert_eq!(r.mesh.n_vertices(), 5);
    assert!(r.warnings.iter().any(|w| w.code == "polygons_triangulated"));
    let src2 = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nf 1/1 2/2 3/3\n";
    let r = read(src2);
    assert_eq!(r.mesh.attributes().uvs.as_ref().unwrap()[1], [1.0, 0.0]);
}

#[test]
fn ply_ascii_and_big_endian_with_any_property_order() {
    let ascii = b"ply\nformat ascii 1.0\ncomment test\nelement vertex 4\nproperty float z\nproperty uchar red\nproperty float x\nproperty uchar green\nproperty float y\nproperty uchar blue\n\
element face 2\nproperty uchar flags\nproperty list uchar uint vertex_indices\nelement extra 1\nproperty int k\nend_header\n\
0 255 0 0 0 1\n0 0 1 0 0 0\n0 0 1 0 1 0\n0 0 0 0 1 0\n7 3 0 1 2\n7 3 0 2 3\n42\n";
    let r = read(ascii);
    assert_eq!(r.format, Format::Ply);
    assert_eq!(r.mesh.n_faces(), 2);
    assert_eq!(r.mesh.position(geom::VertexId(1)), geom::mesh::P3::new(1.0, 0.0, 0.0));
    assert_eq!(r.mesh.attributes().colors.as_ref().unwrap()[0], [255, 0, 1, 255]);
    // Big endian, double coordinates, int16 indices.
    let mut be = b"ply\nformat binary_big_endian 1.0\nelement vertex 3\nproperty double x\nproperty double y\nproperty double z\nelement face 1\nproperty list uchar short vertex_indices\nend_header\n".to_vec();
    for p in [[0.0f64, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.5]] {
        for c in p {
            be.extend_from_slice(&c.to_be_bytes());
        }
    }
    be.push(3);
    for i in [0i16, 1, 2] {
        be.extend_from_slice(&i.to_be_bytes());
    }
    let r = read(&be);
    assert_eq!(r.mesh.position(geom::VertexId(2)), geom::mesh::P3::new(0.0, 1.0, 0.5));
}

#[test]
fn stl_ascii_and_binary_weld_identical_vertices() {
    let ascii =
        b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nendloop\nendfacet\n\
facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 1 0\nvertex 0 1 0\nendloop\nendfacet\nendsolid t\n";
    let r = read(ascii);
    assert_eq!(r.format, Format::Stl);
    assert_eq!(r.mesh.n_vertices(), 4);
    assert_eq!(r.mesh.n_faces(), 2);
    let bin = io::write(&r.mesh, Format::Stl);
    assert_eq!(bin.len(), 84 + 50 * 2);
    let r2 = read(&bin);
    assert_eq!(r2.mesh.n_vertices(), 4);
    // A binary STL whose header starts with "solid" is still binary.
    let mut tricky = bin.clone();
    tricky[..5].copy_from_slice(b"solid");
    assert_eq!(read(&tricky).mesh.n_faces(), 2);
}

#[test]
fn format_is_detected_from_content_not_extension() {
    let m = shapes::icosphere(1);
    let dir = std::env::temp_dir().join(format!("surfmap-detect-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join("actually_ply.obj");
    io::write_bytes(&p, &io::write(&m, Format::Ply)).unwrap();
    let r = io::read_path(&p, &ReadOptions::default()).unwrap();
    assert_eq!(r.format, Format::Ply);
    assert_eq!(r.mesh.n_faces(), m.n_faces());
}
