//! glTF 2.0 binary (`.glb`) writer for morph animations: one mesh whose base positions are the
//! first model and whose morph targets are the other models' displacements from it. The JSON
//! chunk is small and written with serde_json; the binary chunk holds little-endian f32
//! positions and u32 indices, each view 4-byte aligned as the container requires.

use crate::mesh::P3;
use serde_json::json;

fn push_positions(bin: &mut Vec<u8>, pts: impl Iterator<Item = [f32; 3]>) -> ([f32; 3], [f32; 3], usize) {
    let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
    let mut n = 0;
    for p in pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
            bin.extend_from_slice(&p[k].to_le_bytes());
        }
        n += 1;
    }
    (lo, hi, n)
}

/// A `.glb` with `base` and `faces`, and one morph target per `(name, positions)` (same vertex
/// count as the base), all weights 0.
pub fn write_glb(base: &[P3], faces: &[[u32; 3]], targets: &[(String, Vec<P3>)]) -> Vec<u8> {
    let f32p = |p: &P3| [p.x as f32, p.y as f32, p.z as f32];
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let (lo, hi, n) = push_positions(&mut bin, base.iter().map(f32p));
    views.push(json!({"buffer": 0, "byteOffset": 0, "byteLength": bin.len(), "target": 34962}));
    accessors.push(json!({"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi}));
    let off = bin.len();
    for t in faces {
        for v in t {
            bin.extend_from_slice(&v.to_le_bytes());
        }
    }
    views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": bin.len() - off, "target": 34963}));
    accessors.push(json!({"bufferView": 1, "componentType": 5125, "count": faces.len() * 3, "type": "SCALAR"}));
    let mut prim_targets = Vec::new();
    for (name, pos) in targets {
        let off = bin.len();
        let d = base.iter().zip(pos).map(|(b, p)| f32p(&P3::from(p - b)));
        let (lo, hi, n) = push_positions(&mut bin, d);
        views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": bin.len() - off, "target": 34962}));
        accessors.push(json!({"bufferView": views.len() - 1, "componentType": 5126, "count": n, "type": "VEC3", "min": lo, "max": hi}));
        prim_targets.push(json!({"POSITION": accessors.len() - 1}));
        let _ = name;
    }
    let names: Vec<&str> = targets.iter().map(|(n, _)| n.as_str()).collect();
    let mut mesh = json!({
        "name": "surfmap morph",
        "primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}],
    });
    if !targets.is_empty() {
        mesh["primitives"][0]["targets"] = json!(prim_targets);
        mesh["weights"] = json!(vec![0.0; targets.len()]);
        mesh["extras"] = json!({"targetNames": names});
    }
    let doc = json!({
        "asset": {"version": "2.0", "generator": "surfmap"},
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [mesh],
        "buffers": [{"byteLength": bin.len()}],
        "bufferViews": views,
        "accessors": accessors,
    });
    let mut js = serde_json::to_vec(&doc).unwrap_or_default();
    while !js.len().is_multiple_of(4) {
        js.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + js.len() + 8 + bin.len();
    let mut out = Vec::with_capacity(total);
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(js.len() as u32).to_le_bytes());
    out.extend_from_slice(b"JSON");
    out.extend_from_slice(&js);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(b"BIN\0");
    out.extend_from_slice(&bin);
    out
}
