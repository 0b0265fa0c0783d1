//! glTF 2.0 reader (`.glb`, and `.gltf` JSON with embedded `data:` buffers), on the `gltf`
//! crate: the triangle primitives of the default scene with node transforms applied, as one
//! [`SplitMesh`] in the file's own vertex layout (seams stay split; the caller welds).
//!
//! Read: `POSITION`, and when every primitive has them `NORMAL`, `TEXCOORD_n`, `COLOR_0`,
//! `JOINTS_0`, `WEIGHTS_0`; indexed or not; triangle lists, strips and fans; sparse accessors;
//! `KHR_mesh_quantization`. Refused with a typed error: required extensions other than that one
//! (Draco, meshopt, ...), external buffer files, node hierarchies that are not trees.

use super::gltf_accessor::Buffers;
use super::options::{ReadOptions, check_limits};
use crate::error::{InputError, Result, parse_err};
use crate::mesh::{SplitMesh, Warning};
use base64::Engine;
use gltf::mesh::{Mode, Semantic};
use gltf_json::validation::Validate;

/// Extensions this reader implements.
const SUPPORTED: &[&str] = &["KHR_mesh_quantization"];

/// GLB magic, or a JSON object with an `asset` member near its start.
pub(crate) fn sniff(b: &[u8]) -> bool {
    if b.starts_with(b"glTF") {
        return true;
    }
    let head = &b[..b.len().min(4096)];
    let first = head.iter().find(|c| !c.is_ascii_whitespace());
    first == Some(&b'{') && head.windows(7).any(|w| w == b"\"asset\"")
}

fn container_err(e: gltf::Error) -> crate::Error {
    match e {
        gltf::Error::Binary(gltf::binary::Error::Length { length, length_read }) => InputError::LyingCount {
            format: "glTF",
            promised: format!("{length} bytes in the GLB header"),
            available: format!("{length_read}"),
        }
        .into(),
        gltf::Error::Binary(gltf::binary::Error::ChunkLength { ty, length, length_read }) => InputError::LyingCount {
            format: "glTF",
            promised: format!("a {ty:?} chunk of {length} bytes"),
            available: format!("{length_read}"),
        }
        .into(),
        e => parse_err("glTF", "container", e.to_string()),
    }
}

/// Parses and validates the document; refuses unsupported required extensions by name.
fn document(b: &[u8]) -> Result<(gltf::Document, Option<Vec<u8>>)> {
    let g = gltf::Gltf::from_slice_without_validation(b).map_err(container_err)?;
    let mut root = g.document.into_json();
    if let Some(ext) = root.extensions_required.iter().find(|e| !SUPPORTED.contains(&e.as_str())) {
        return Err(InputError::UnsupportedExtension(ext.clone()).into());
    }
    root.extensions_required.clear();
    let mut first: Option<String> = None;
    root.validate(&root, gltf_json::Path::new, &mut |path, e| {
        if first.is_none() {
            first = Some(format!("{}: {e}", path()));
        }
    });
    if let Some(m) = first {
        return Err(parse_err("glTF", "document", m));
    }
    Ok((gltf::Document::from_json_without_validation(root), g.blob))
}

fn load_buffers<'a>(doc: &gltf::Document, blob: Option<&'a [u8]>, decoded: &'a mut Vec<Vec<u8>>) -> Result<()> {
    for buf in doc.buffers() {
        let bytes = match buf.source() {
            gltf::buffer::Source::Bin => blob.map(<[u8]>::to_vec).ok_or_else(|| {
                parse_err("glTF", format!("buffers[{}]", buf.index()), "refers to a GLB binary chunk the file lacks")
            })?,
            gltf::buffer::Source::Uri(uri) if uri.starts_with("data:") => {
                let data = uri
                    .split_once(";base64,")
                    .map(|(_, d)| d)
                    .ok_or_else(|| parse_err("glTF", format!("buffers[{}]", buf.index()), "data URI is not base64"))?;
                base64::engine::general_purpose::STANDARD
                    .decode(data)
                    .map_err(|e| parse_err("glTF", format!("buffers[{}]", buf.index()), e.to_string()))?
            }
            gltf::buffer::Source::Uri(uri) => {
                return Err(InputError::Invalid(format!(
                    "glTF buffers[{}] refers to the external file {uri:?}: send a .glb, or a .gltf with data: URIs",
                    buf.index()
                ))
                .into());
            }
        };
        if bytes.len() < buf.length() {
            return Err(InputError::LyingCount {
                format: "glTF",
                promised: format!("buffers[{}].byteLength = {}", buf.index(), buf.length()),
                available: format!("{} bytes", bytes.len()),
            }
            .into());
        }
        decoded.push(bytes);
    }
    Ok(())
}

/// Column-major 4x4 products in f64.
fn mul(a: &[[f64; 4]; 4], b: &[[f64; 4]; 4]) -> [[f64; 4]; 4] {
    let mut c = [[0.0; 4]; 4];
    for (j, col) in c.iter_mut().enumerate() {
        for (i, x) in col.iter_mut().enumerate() {
            *x = (0..4).map(|k| a[k][i] * b[j][k]).sum();
        }
    }
    c
}

/// Every (mesh node, world matrix) of the default scene (or of the first scene; or every
/// mesh at the identity when the file has no scene).
fn instances(doc: &gltf::Document) -> Result<Vec<(gltf::Mesh<'_>, [[f64; 4]; 4])>> {
    let id = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 1.0]];
    let Some(scene) = doc.default_scene().or_else(|| doc.scenes().next()) else {
        return Ok(doc.meshes().map(|m| (m, id)).collect());
    };
    let mut seen = vec![false; doc.nodes().len()];
    let mut stack: Vec<(gltf::Node, [[f64; 4]; 4])> = scene.nodes().map(|n| (n, id)).collect();
    let mut out = Vec::new();
    while let Some((node, parent)) = stack.pop() {
        if std::mem::replace(&mut seen[node.index()], true) {
            return Err(parse_err("glTF", format!("nodes[{}]", node.index()), "the node hierarchy is not a tree"));
        }
        let local = node.transform().matrix().map(|c| c.map(f64::from));
        let world = mul(&parent, &local);
        if let Some(m) = node.mesh() {
            out.push((m, world));
        }
        stack.extend(node.children().map(|c| (c, world)));
    }
    Ok(out)
}

/// Triangles of a primitive's index list by its mode; `None` for points and lines.
fn triangles(mode: Mode, idx: &[u32]) -> Option<Vec<[u32; 3]>> {
    Some(match mode {
        Mode::Triangles => idx.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect(),
        Mode::TriangleStrip => (2..idx.len())
            .map(|i| if i % 2 == 0 { [idx[i - 2], idx[i - 1], idx[i]] } else { [idx[i - 1], idx[i - 2], idx[i]] })
            .collect(),
        Mode::TriangleFan => (2..idx.len()).map(|i| [idx[0], idx[i - 1], idx[i]]).collect(),
        _ => return None,
    })
}

/// Reads a glTF file into the file's own vertex layout.
///
/// # Errors
/// `UnsupportedExtension`, `LyingCount`, `TooLarge`, `Parse` naming the element, `NoFaces`.
pub(crate) fn read(b: &[u8], opts: &ReadOptions) -> Result<SplitMesh> {
    let (doc, blob) = document(b)?;
    let mut decoded = Vec::new();
    load_buffers(&doc, blob.as_deref(), &mut decoded)?;
    let bufs = Buffers(decoded.iter().map(Vec::as_slice).collect());
    let max_v = usize::try_from(opts.limits.max_vertices).unwrap_or(usize::MAX);
    let max_i = usize::try_from(opts.limits.max_faces.saturating_mul(3)).unwrap_or(usize::MAX);
    let mut acc = super::gltf_prims::Accumulator::default();
    for (mesh, world) in instances(&doc)? {
        for prim in mesh.primitives() {
            let Some(pos) = prim.get(&Semantic::Positions) else {
                acc.warn(Warning::new(
                    "no_positions",
                    format!("meshes[{}]: a primitive without POSITION", mesh.index()),
                ));
                continue;
            };
            check_limits(opts, (acc.n_vertices() + pos.count()) as u64, 0)?;
            let n = pos.count();
            let idx: Vec<u32> = match prim.indices() {
                Some(a) => bufs.read(&a, max_i)?.0.iter().map(|&x| x as u32).collect(),
                None => (0..n as u32).collect(),
            };
            let Some(tris) = triangles(prim.mode(), &idx) else {
                acc.warn(Warning::new(
                    "not_triangles",
                    format!("meshes[{}]: a {:?} primitive skipped", mesh.index(), prim.mode()),
                ));
                continue;
            };
            check_limits(opts, 0, (acc.n_triangles() + tris.len()) as u64)?;
            if let Some(&bad) = tris.iter().flatten().find(|&&i| i as usize >= n) {
                return Err(InputError::IndexOutOfRange {
                    face: acc.n_triangles(),
                    index: i64::from(bad),
                    vertex_count: n,
                }
                .into());
            }
            let read = |s: Semantic| -> Result<Option<(Vec<f64>, usize)>> {
                prim.get(&s)
                    .map(|a| {
                        if a.count() != n {
                            return Err(parse_err(
                                "glTF",
                                format!("accessors[{}]", a.index()),
                                format!("{} elements, POSITION has {n}", a.count()),
                            ));
                        }
                        bufs.read(&a, max_v)
                    })
                    .transpose()
            };
            let mut texcoords = Vec::new();
            for k in 0.. {
                match read(Semantic::TexCoords(k))? {
                    Some(t) => texcoords.push(t),
                    None => break,
                }
            }
            acc.push(super::gltf_prims::Primitive {
                world,
                positions: read(Semantic::Positions)?.map(|p| p.0).unwrap_or_default(),
                triangles: tris,
                normals: read(Semantic::Normals)?,
                texcoords,
                color: read(Semantic::Colors(0))?,
                joints: read(Semantic::Joints(0))?,
                weights: read(Semantic::Weights(0))?,
            })?;
        }
    }
    let out = acc.finish();
    if out.triangles.is_empty() {
        return Err(InputError::NoFaces.into());
    }
    Ok(out)
}
