//! glTF 2.0 binary (`.glb`) writer: one mesh with its vertex attributes, and morph targets as
//! displacements from the base positions. The JSON chunk is small and written with
//! serde_json; the binary chunk holds little-endian f32 / u16 / u32 data, each view 4-byte
//! aligned as the container requires.

use crate::mesh::{Attributes, InputLayout, P3};
use serde_json::{Value, json};

/// A mesh to write: base positions, triangles, attributes per vertex and named morph targets
/// (absolute positions, same vertex count).
pub struct GlbMesh<'a> {
    pub positions: &'a [P3],
    pub triangles: &'a [[u32; 3]],
    pub attributes: &'a Attributes,
    pub targets: &'a [(String, Vec<P3>)],
}

#[derive(Default)]
struct Builder {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Builder {
    /// Appends one view and its accessor; returns the accessor index.
    fn push(&mut self, bytes: &[u8], target: u32, mut accessor: Value) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        let off = self.bin.len();
        self.bin.extend_from_slice(bytes);
        self.views.push(json!({"buffer": 0, "byteOffset": off, "byteLength": bytes.len(), "target": target}));
        accessor["bufferView"] = json!(self.views.len() - 1);
        self.accessors.push(accessor);
        self.accessors.len() - 1
    }

    fn floats<const N: usize>(&mut self, data: &[[f32; N]], with_bounds: bool) -> usize {
        let ty = ["SCALAR", "VEC2", "VEC3", "VEC4"][N - 1];
        let bytes: Vec<u8> = data.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let mut acc = json!({"componentType": 5126, "count": data.len(), "type": ty});
        if with_bounds {
            let (mut lo, mut hi) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
            for p in data {
                for k in 0..N {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            acc["min"] = json!(lo.to_vec());
            acc["max"] = json!(hi.to_vec());
        }
        self.push(&bytes, 34962, acc)
    }
}

fn f32p(p: &P3) -> [f32; 3] {
    [p.x as f32, p.y as f32, p.z as f32]
}

/// A `.glb` of `m`: attributes as given; morph targets with weight 0, named in
/// `mesh.extras.targetNames`.
pub fn write_glb_mesh(m: &GlbMesh) -> Vec<u8> {
    write_glb_meshes(&[("surfmap", m)])
}

/// A `.glb` with one named node and mesh per entry, in one scene (as [`write_glb_mesh`]).
pub fn write_glb_meshes(meshes: &[(&str, &GlbMesh)]) -> Vec<u8> {
    let mut b = Builder::default();
    let gltf_meshes: Vec<Value> = meshes.iter().map(|(name, m)| mesh_json(&mut b, name, m)).collect();
    let nodes: Vec<Value> = meshes.iter().enumerate().map(|(i, (name, _))| json!({"mesh": i, "name": name})).collect();
    let doc = json!({
        "asset": {"version": "2.0", "generator": "surfmap"},
        "scene": 0,
        "scenes": [{"nodes": (0..meshes.len()).collect::<Vec<_>>()}],
        "nodes": nodes,
        "meshes": gltf_meshes,
        "buffers": [{"byteLength": b.bin.len()}],
        "bufferViews": b.views,
        "accessors": b.accessors,
    });
    container(serde_json::to_vec(&doc).unwrap_or_default(), b.bin)
}

/// One mesh's accessors into `b`, and its glTF `mesh` object.
fn mesh_json(b: &mut Builder, name: &str, m: &GlbMesh) -> Value {
    let base: Vec<[f32; 3]> = m.positions.iter().map(f32p).collect();
    let mut attrs = serde_json::Map::new();
    attrs.insert("POSITION".into(), json!(b.floats(&base, true)));
    let idx: Vec<u8> = m.triangles.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let indices = b.push(&idx, 34963, json!({"componentType": 5125, "count": m.triangles.len() * 3, "type": "SCALAR"}));
    let a = m.attributes;
    if let Some(n) = &a.normals {
        let unit: Vec<[f32; 3]> = n
            .iter()
            .map(|v| {
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                if l > 0.0 { v.map(|x| x / l) } else { [0.0, 0.0, 1.0] }
            })
            .collect();
        attrs.insert("NORMAL".into(), json!(b.floats(&unit, false)));
    }
    for (k, t) in a.texcoords.iter().enumerate() {
        attrs.insert(format!("TEXCOORD_{k}"), json!(b.floats(t, false)));
    }
    if let Some(c) = &a.color {
        attrs.insert("COLOR_0".into(), json!(b.floats(c, false)));
    }
    if let Some(j) = &a.joints {
        let bytes: Vec<u8> = j.iter().flatten().flat_map(|x| x.to_le_bytes()).collect();
        let acc = json!({"componentType": 5123, "count": j.len(), "type": "VEC4"});
        attrs.insert("JOINTS_0".into(), json!(b.push(&bytes, 34962, acc)));
    }
    if let Some(w) = &a.weights {
        attrs.insert("WEIGHTS_0".into(), json!(b.floats(w, false)));
    }
    let mut prim_targets = Vec::new();
    for (_, pos) in m.targets {
        let d: Vec<[f32; 3]> = m.positions.iter().zip(pos).map(|(p, q)| f32p(&P3::from(q - p))).collect();
        prim_targets.push(json!({"POSITION": b.floats(&d, true)}));
    }
    let names: Vec<&str> = m.targets.iter().map(|(n, _)| n.as_str()).collect();
    let mut mesh = json!({
        "name": name,
        "primitives": [{"attributes": attrs, "indices": indices, "mode": 4}],
    });
    if !m.targets.is_empty() {
        mesh["primitives"][0]["targets"] = json!(prim_targets);
        mesh["weights"] = json!(vec![0.0; m.targets.len()]);
        mesh["extras"] = json!({"targetNames": names});
    }
    mesh
}

/// A `.glb` with `base` and `faces`, and one morph target per `(name, positions)` (same vertex
/// count as the base), all weights 0.
pub fn write_glb(base: &[P3], faces: &[[u32; 3]], targets: &[(String, Vec<P3>)]) -> Vec<u8> {
    write_glb_mesh(&GlbMesh { positions: base, triangles: faces, attributes: &Attributes::default(), targets })
}

/// The GLB container around a JSON and a binary chunk.
fn container(mut js: Vec<u8>, mut bin: Vec<u8>) -> Vec<u8> {
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

/// A `.glb` of a mesh in the input's own layout (seam copies, attributes), with morph targets
/// given per welded vertex (each copy of a vertex moves with it). Without a layout, the mesh's
/// own vertices, with its UVs and normals when it has them.
pub fn write_layout_glb(mesh: &crate::Mesh, layout: Option<&InputLayout>, targets: &[(String, Vec<P3>)]) -> Vec<u8> {
    write_layout_glbs(&[LayoutGlb { name: "surfmap", mesh, layout, targets }])
}

/// One mesh of [`write_layout_glbs`].
pub struct LayoutGlb<'a> {
    pub name: &'a str,
    pub mesh: &'a crate::Mesh,
    pub layout: Option<&'a InputLayout>,
    pub targets: &'a [(String, Vec<P3>)],
}

/// A `.glb` with one node per mesh, each as [`write_layout_glb`] writes it.
pub fn write_layout_glbs(meshes: &[LayoutGlb]) -> Vec<u8> {
    struct Owned {
        positions: Vec<P3>,
        triangles: Vec<[u32; 3]>,
        attributes: Attributes,
        targets: Vec<(String, Vec<P3>)>,
    }
    let owned: Vec<Owned> = meshes
        .iter()
        .map(|m| match m.layout {
            Some(l) => Owned {
                positions: l.spread(m.mesh.positions()),
                triangles: l.triangles.clone(),
                attributes: l.attributes.clone(),
                targets: m.targets.iter().map(|(n, t)| (n.clone(), l.spread(t))).collect(),
            },
            None => Owned {
                positions: m.mesh.positions().to_vec(),
                triangles: m.mesh.faces().iter().map(|f| f.map(|v| v.0)).collect(),
                attributes: Attributes::from(m.mesh.attributes()),
                targets: m.targets.to_vec(),
            },
        })
        .collect();
    let glb: Vec<GlbMesh> = owned
        .iter()
        .map(|o| GlbMesh {
            positions: &o.positions,
            triangles: &o.triangles,
            attributes: &o.attributes,
            targets: &o.targets,
        })
        .collect();
    let named: Vec<(&str, &GlbMesh)> = meshes.iter().zip(&glb).map(|(m, g)| (m.name, g)).collect();
    write_glb_meshes(&named)
}
