//! glTF input: seams welded through the input layout, attributes kept, node transforms,
//! quantized and sparse accessors, strips; malformed files get typed errors.

mod common;
use base64::Engine;
use geom::io::{self, Format, ReadOptions};
use geom::mesh::layout::VertexIds;
use serde_json::{Value, json};

fn read(b: &[u8]) -> geom::Result<io::ReadResult> {
    io::read(b, &ReadOptions::default())
}

fn code(b: &[u8]) -> String {
    match read(b) {
        Ok(_) => "ok".into(),
        Err(e) => e.code().to_string(),
    }
}

/// A `.gltf` JSON with one data-URI buffer holding `bin`.
fn gltf_json(mut doc: Value, bin: &[u8]) -> Vec<u8> {
    let uri = format!("data:application/octet-stream;base64,{}", base64::engine::general_purpose::STANDARD.encode(bin));
    doc["asset"] = json!({"version": "2.0"});
    doc["buffers"] = json!([{"byteLength": bin.len(), "uri": uri}]);
    serde_json::to_vec(&doc).unwrap()
}

fn le<T: Copy, const N: usize>(v: &[T], f: impl Fn(T) -> [u8; N]) -> Vec<u8> {
    v.iter().flat_map(|&x| f(x)).collect()
}

/// A unit tetrahedron's 4 positions as f32 and its 4 faces as u16 indices.
fn tetra() -> (Vec<u8>, Vec<u8>) {
    let p: [f32; 12] = [0., 0., 0., 1., 0., 0., 0., 1., 0., 0., 0., 1.];
    let i: [u16; 12] = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3];
    (le(&p, f32::to_le_bytes), le(&i, u16::to_le_bytes))
}

fn tetra_doc(node: Value) -> Value {
    json!({
        "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [node],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
            {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}
        ]
    })
}

#[test]
fn spot_obj_seams_become_a_layout_and_survive_a_glb_round_trip() {
    let obj = std::fs::read(common::shared_mesh("spot.obj")).unwrap();
    let r = read(&obj).unwrap();
    let lay = r.layout.as_ref().expect("spot has UV seams");
    assert_eq!((r.mesh.n_vertices(), lay.n_vertices()), (2930, 3225));
    assert_eq!(lay.ids, VertexIds::Welded);
    assert_eq!(lay.attributes.texcoords.len(), 1);
    let glb = common::glb_of_obj(&obj);
    let g = read(&glb).unwrap();
    assert_eq!(g.format, Format::Gltf);
    let gl = g.layout.as_ref().unwrap();
    assert_eq!((g.mesh.n_vertices(), gl.n_vertices(), gl.n_split()), (2930, 3225, 295));
    assert_eq!(gl.attributes.texcoords, lay.attributes.texcoords);
    assert_eq!(geom::topology::genus(&g.mesh), geom::topology::genus(&r.mesh));
    // Every input vertex sits where its welded vertex is, and faces agree corner by corner.
    for (f, t) in gl.triangles.iter().enumerate() {
        for (k, &v) in t.iter().enumerate() {
            assert_eq!(gl.welded[v as usize], g.mesh.faces()[f][k].0);
        }
    }
    for (a, b) in lay.spread(r.mesh.positions()).iter().zip(gl.spread(g.mesh.positions())) {
        assert!((a - b).norm() < 1e-6, "{a} vs {b}");
    }
}

#[test]
fn node_transforms_quantized_sparse_and_strips_are_read() {
    // i16-normalized positions (KHR_mesh_quantization) under a node scale of 2 and a mirror.
    let q: [i16; 12] = [0, 0, 0, 32767, 0, 0, 0, 32767, 0, 0, 0, 32767];
    let (_, idx) = tetra();
    let mut bin = le(&q, i16::to_le_bytes);
    bin.extend_from_slice(&idx);
    let mut doc = tetra_doc(json!({"mesh": 0, "scale": [2.0, 2.0, -2.0]}));
    doc["extensionsUsed"] = json!(["KHR_mesh_quantization"]);
    doc["extensionsRequired"] = json!(["KHR_mesh_quantization"]);
    doc["bufferViews"] =
        json!([{"buffer": 0, "byteOffset": 0, "byteLength": 24}, {"buffer": 0, "byteOffset": 24, "byteLength": 24}]);
    doc["accessors"][0]["componentType"] = json!(5122);
    doc["accessors"][0]["normalized"] = json!(true);
    doc["accessors"][0]["max"] = json!([32767, 32767, 32767]);
    let r = read(&gltf_json(doc, &bin)).unwrap();
    let p = r.mesh.positions();
    assert!((p[1].x - 2.0).abs() < 1e-9 && (p[3].z + 2.0).abs() < 1e-9, "{p:?}");
    // The mirror reversed the winding: the mesh is still outward (positive volume).
    let vol: f64 = r
        .mesh
        .faces()
        .iter()
        .map(|f| {
            let [a, b, c] = f.map(|v| p[v.idx()].coords);
            a.dot(&b.cross(&c)) / 6.0
        })
        .sum();
    assert!(vol > 0.0, "volume {vol}");

    // A sparse accessor moves vertex 3 to (0, 0, 5); a strip of 4 indices gives 2 triangles.
    let (pos, _) = tetra();
    let mut bin = pos.clone();
    bin.extend_from_slice(&le(&[3u16, 0], u16::to_le_bytes));
    bin.extend_from_slice(&le(&[0f32, 0., 5.], f32::to_le_bytes));
    let doc = json!({
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "mode": 5}]}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 4}, {"buffer": 0, "byteOffset": 52, "byteLength": 12}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 5],
            "sparse": {"count": 1, "indices": {"bufferView": 1, "componentType": 5123}, "values": {"bufferView": 2}}}]
    });
    let r = read(&gltf_json(doc, &bin)).unwrap();
    assert_eq!(r.mesh.n_faces(), 2);
    assert_eq!(r.mesh.positions()[3].z, 5.0);
}

#[test]
fn malformed_gltf_gets_typed_errors() {
    let (pos, idx) = tetra();
    let mut bin = pos.clone();
    bin.extend_from_slice(&idx);
    let good = gltf_json(tetra_doc(json!({"mesh": 0})), &bin);
    assert_eq!(code(&good), "ok");
    // A GLB whose header promises more bytes than the file has.
    let small = geom::mesh::shapes::tetrahedron();
    let mut glb = io::write(&small, Format::Gltf);
    assert_eq!(code(&glb), "ok");
    let n = glb.len() as u32 + 100;
    glb[8..12].copy_from_slice(&n.to_le_bytes());
    assert_eq!(code(&glb), "lying_count");
    // A GLB with a bad version.
    let mut glb = io::write(&small, Format::Gltf);
    glb[4] = 7;
    assert_eq!(code(&glb), "parse_error");
    // A buffer that promises more than its data URI holds.
    let mut doc: Value = serde_json::from_slice(&good).unwrap();
    doc["buffers"][0]["byteLength"] = json!(500);
    assert_eq!(code(&serde_json::to_vec(&doc).unwrap()), "lying_count");
    // An accessor reading past its view.
    let mut doc = tetra_doc(json!({"mesh": 0}));
    doc["accessors"][1]["count"] = json!(60);
    assert_eq!(code(&gltf_json(doc, &bin)), "lying_count");
    // An index past the vertices.
    let mut bad = bin.clone();
    bad[48..50].copy_from_slice(&9u16.to_le_bytes());
    assert_eq!(code(&gltf_json(tetra_doc(json!({"mesh": 0})), &bad)), "index_out_of_range");
    // An accessor naming a view that does not exist.
    let mut doc = tetra_doc(json!({"mesh": 0}));
    doc["accessors"][1]["bufferView"] = json!(7);
    assert_eq!(code(&gltf_json(doc, &bin)), "parse_error");
    // Draco: refused by name.
    let mut doc = tetra_doc(json!({"mesh": 0}));
    doc["extensionsUsed"] = json!(["KHR_draco_mesh_compression"]);
    doc["extensionsRequired"] = json!(["KHR_draco_mesh_compression"]);
    let e = read(&gltf_json(doc, &bin)).unwrap_err();
    assert_eq!(e.code(), "unsupported_extension");
    assert!(e.to_string().contains("KHR_draco_mesh_compression"), "{e}");
    // An external buffer file.
    let mut doc: Value = serde_json::from_slice(&good).unwrap();
    doc["buffers"][0]["uri"] = json!("mesh.bin");
    let e = read(&serde_json::to_vec(&doc).unwrap()).unwrap_err();
    assert_eq!(e.code(), "invalid_argument");
    assert!(e.to_string().contains("mesh.bin"), "{e}");
    // A node that is its own child.
    let mut doc = tetra_doc(json!({"mesh": 0, "children": [0]}));
    doc["nodes"][0]["children"] = json!([0]);
    assert_eq!(code(&gltf_json(doc, &bin)), "parse_error");
    // Too many vertices for the limits: refused before reading.
    let opts = ReadOptions { limits: geom::mesh::MeshLimits { max_vertices: 3, max_faces: 100 }, hint: None };
    assert_eq!(io::read(&good, &opts).unwrap_err().code(), "too_large");
}
