//! Validated construction of a [`Mesh`] from raw reader output: range and finiteness checks,
//! polygon triangulation, unreferenced-vertex removal, degenerate/duplicate face detection,
//! orientation repair, twin linking in linear time and the manifold checks.

use super::{EdgeId, FaceId, HalfedgeId, Mesh, P3, VertexAttributes, VertexId, triangulate_polygon};
use crate::error::{InputError, Result};
use serde::Serialize;

/// Limits on what a reader accepts, checked against header counts before allocating.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct MeshLimits {
    /// Maximum number of vertices.
    pub max_vertices: u64,
    /// Maximum number of faces (after triangulation).
    pub max_faces: u64,
}

impl Default for MeshLimits {
    fn default() -> Self {
        Self { max_vertices: 20_000_000, max_faces: 40_000_000 }
    }
}

/// A non-fatal finding, reported next to the mesh.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Warning {
    /// Stable code, e.g. `unreferenced_vertices`.
    pub code: &'static str,
    /// What happened, with counts or element ids.
    pub message: String,
}

impl Warning {
    pub(crate) fn new(code: &'static str, message: impl Into<String>) -> Self {
        Self { code, message: message.into() }
    }
}

/// What a reader produces: positions, polygons (flat indices plus sizes) and attributes.
#[derive(Debug, Clone, Default)]
pub struct RawMesh {
    /// Vertex positions.
    pub positions: Vec<[f64; 3]>,
    /// Concatenated polygon vertex indices.
    pub indices: Vec<u32>,
    /// Size of each polygon; `None` means every polygon is a triangle.
    pub sizes: Option<Vec<u32>>,
    /// Per-vertex attributes (same length as `positions` when present).
    pub attributes: VertexAttributes,
    /// Warnings found while reading.
    pub warnings: Vec<Warning>,
}

impl RawMesh {
    /// A raw mesh of triangles.
    pub fn from_triangles(positions: Vec<[f64; 3]>, triangles: &[[u32; 3]]) -> Self {
        Self { positions, indices: triangles.iter().flatten().copied().collect(), ..Default::default() }
    }
    /// Number of polygons.
    pub fn n_polygons(&self) -> usize {
        match &self.sizes {
            Some(s) => s.len(),
            None => self.indices.len() / 3,
        }
    }
}

pub(crate) fn check_finite(positions: &[P3]) -> Result<()> {
    for (i, p) in positions.iter().enumerate() {
        for &c in p.coords.iter() {
            if !c.is_finite() {
                return Err(InputError::NonFiniteCoordinate { vertex: i, value: c }.into());
            }
        }
    }
    Ok(())
}

impl Mesh {
    /// Builds a mesh from raw polygons, with the warnings of reading and repair.
    ///
    /// # Errors
    /// An [`InputError`] naming the first offending element: out-of-range index, non-finite
    /// coordinate, face with < 3 vertices, repeated vertex in a face, duplicate face,
    /// non-manifold edge or vertex, non-orientable surface, or no faces at all.
    pub fn from_raw(raw: RawMesh) -> Result<(Mesh, Vec<Warning>)> {
        let RawMesh { positions, indices, sizes, attributes, mut warnings } = raw;
        let nv = positions.len();
        for (i, p) in positions.iter().enumerate() {
            for &c in p {
                if !c.is_finite() {
                    return Err(InputError::NonFiniteCoordinate { vertex: i, value: c }.into());
                }
            }
        }
        // Triangulate.
        let mut tris: Vec<[u32; 3]> = Vec::with_capacity(indices.len() / 3);
        match &sizes {
            None => {
                for (f, c) in indices.chunks_exact(3).enumerate() {
                    for &i in c {
                        if i as usize >= nv {
                            return Err(InputError::IndexOutOfRange { face: f, index: i as i64, vertex_count: nv }.into());
                        }
                    }
                    tris.push([c[0], c[1], c[2]]);
                }
            }
            Some(sizes) => {
                let mut off = 0usize;
                let mut n_poly = 0usize;
                let mut n_nonplanar_fan = 0usize;
                for (f, &k) in sizes.iter().enumerate() {
                    let k = k as usize;
                    let poly = &indices[off..off + k];
                    off += k;
                    if k < 3 {
                        return Err(InputError::FaceTooSmall { face: f, count: k }.into());
                    }
                    for &i in poly {
                        if i as usize >= nv {
                            return Err(InputError::IndexOutOfRange { face: f, index: i as i64, vertex_count: nv }.into());
                        }
                    }
                    if k == 3 {
                        tris.push([poly[0], poly[1], poly[2]]);
                    } else {
                        n_poly += 1;
                        if !triangulate_polygon(&positions, poly, &mut tris) {
                            n_nonplanar_fan += 1;
                        }
                    }
                }
                if n_poly > 0 {
                    warnings.push(Warning::new(
                        "polygons_triangulated",
                        format!(
                            "{n_poly} polygons with more than 3 vertices were triangulated by ear clipping \
                             ({n_nonplanar_fan} degenerate ones by a fan)"
                        ),
                    ));
                }
            }
        }
        if tris.is_empty() {
            return Err(InputError::NoFaces.into());
        }
        for (f, t) in tris.iter().enumerate() {
            if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
                let v = if t[0] == t[1] || t[0] == t[2] { t[0] } else { t[1] };
                return Err(InputError::DegenerateFace { face: f, vertex: v as usize }.into());
            }
        }
        // Remove unreferenced vertices.
        let mut used = vec![false; nv];
        for t in &tris {
            for &i in t {
                used[i as usize] = true;
            }
        }
        let n_unused = used.iter().filter(|u| !**u).count();
        let (positions, attributes) = if n_unused > 0 {
            let keep: Vec<u32> = (0..nv as u32).filter(|&i| used[i as usize]).collect();
            let mut remap = vec![u32::MAX; nv];
            for (new, &old) in keep.iter().enumerate() {
                remap[old as usize] = new as u32;
            }
            for t in &mut tris {
                for i in t.iter_mut() {
                    *i = remap[*i as usize];
                }
            }
            let first = used.iter().position(|u| !*u).unwrap_or(0);
            warnings.push(Warning::new(
                "unreferenced_vertices",
                format!("{n_unused} unreferenced vertices removed (first: {first}); later vertices renumbered"),
            ));
            let pos = keep.iter().map(|&i| positions[i as usize]).collect::<Vec<_>>();
            (pos, attributes.select(&keep))
        } else {
            (positions, attributes)
        };
        let positions: Vec<P3> = positions.into_iter().map(|p| P3::new(p[0], p[1], p[2])).collect();
        let nv = positions.len();
        let n_flipped = orient(nv, &mut tris)?;
        if n_flipped > 0 {
            warnings.push(Warning::new(
                "reoriented",
                format!("{n_flipped} faces were flipped to make the orientation consistent"),
            ));
        }
        let n_zero = tris
            .iter()
            .filter(|t| {
                let [a, b, c] = t.map(|i| positions[i as usize]);
                (b - a).cross(&(c - a)).norm_squared() == 0.0
            })
            .count();
        if n_zero > 0 {
            warnings.push(Warning::new("zero_area_faces", format!("{n_zero} faces have zero area")));
        }
        let mesh = link(positions, tris, attributes)?;
        Ok((mesh, warnings))
    }

    /// Builds a mesh from triangles, discarding warnings.
    ///
    /// # Errors
    /// As [`Mesh::from_raw`].
    pub fn from_triangles(positions: Vec<P3>, triangles: &[[u32; 3]]) -> Result<Mesh> {
        let raw = RawMesh::from_triangles(positions.iter().map(|p| [p.x, p.y, p.z]).collect(), triangles);
        Ok(Mesh::from_raw(raw)?.0)
    }
}

/// Compressed vertex -> (incident half-edge) table: the half-edges with tail `v` are
/// `he[off[v]..off[v+1]]`.
struct Star {
    off: Vec<u32>,
    he: Vec<u32>,
}

fn star(nv: usize, tris: &[[u32; 3]]) -> Star {
    let mut off = vec![0u32; nv + 1];
    for t in tris {
        for &i in t {
            off[i as usize + 1] += 1;
        }
    }
    for i in 0..nv {
        off[i + 1] += off[i];
    }
    let mut fill = off.clone();
    let mut he = vec![0u32; tris.len() * 3];
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let v = t[k] as usize;
            he[fill[v] as usize] = (3 * f + k) as u32;
            fill[v] += 1;
        }
    }
    Star { off, he }
}

#[inline]
fn tail(tris: &[[u32; 3]], h: u32) -> u32 {
    tris[(h / 3) as usize][(h % 3) as usize]
}
#[inline]
fn head(tris: &[[u32; 3]], h: u32) -> u32 {
    tris[(h / 3) as usize][((h % 3 + 1) % 3) as usize]
}

/// Undirected neighbours of half-edge `h` (other half-edges on the same undirected edge).
fn edge_mates(star: &Star, tris: &[[u32; 3]], h: u32, out: &mut Vec<u32>) {
    out.clear();
    let (a, b) = (tail(tris, h), head(tris, h));
    for &g in &star.he[star.off[a as usize] as usize..star.off[a as usize + 1] as usize] {
        if g != h && head(tris, g) == b {
            out.push(g);
        }
    }
    for &g in &star.he[star.off[b as usize] as usize..star.off[b as usize + 1] as usize] {
        if head(tris, g) == a {
            out.push(g);
        }
    }
}

/// Checks edge manifoldness and duplicates, then makes the orientation consistent by a
/// breadth-first walk over faces. Returns the number of faces flipped.
fn orient(nv: usize, tris: &mut [[u32; 3]]) -> Result<usize> {
    let st = star(nv, tris);
    let mut mates = Vec::new();
    let mut need_fix = false;
    for h in 0..(tris.len() * 3) as u32 {
        edge_mates(&st, tris, h, &mut mates);
        if !mates.is_empty() {
            // Two faces with the same three vertices are duplicates, not neighbours.
            let f = (h / 3) as usize;
            let mut key = tris[f];
            key.sort_unstable();
            for &g in &mates {
                let o = (g / 3) as usize;
                let mut k2 = tris[o];
                k2.sort_unstable();
                if k2 == key {
                    return Err(InputError::DuplicateFace { face: f.max(o), other: f.min(o) }.into());
                }
            }
        }
        if mates.len() > 1 {
            let (a, b) = (tail(tris, h), head(tris, h));
            return Err(InputError::NonManifoldEdge { a: a as usize, b: b as usize, count: mates.len() + 1 }.into());
        }
        if mates.len() == 1 && head(tris, mates[0]) == head(tris, h) {
            need_fix = true;
        }
    }
    if !need_fix {
        return Ok(0);
    }
    // BFS: each face gets a flip flag so that neighbours agree; conflict = non-orientable.
    let nf = tris.len();
    let mut flip = vec![u8::MAX; nf];
    let mut queue = std::collections::VecDeque::new();
    for seed in 0..nf {
        if flip[seed] != u8::MAX {
            continue;
        }
        flip[seed] = 0;
        queue.push_back(seed);
        while let Some(f) = queue.pop_front() {
            for k in 0..3 {
                let h = (3 * f + k) as u32;
                edge_mates(&st, tris, h, &mut mates);
                if let Some(&g) = mates.first() {
                    let o = (g / 3) as usize;
                    let same_dir = head(tris, g) == head(tris, h);
                    let want = flip[f] ^ u8::from(same_dir);
                    if flip[o] == u8::MAX {
                        flip[o] = want;
                        queue.push_back(o);
                    } else if flip[o] != want {
                        return Err(InputError::NonOrientable { a: tail(tris, h) as usize, b: head(tris, h) as usize }.into());
                    }
                }
            }
        }
    }
    let mut n = 0;
    for (t, &fl) in tris.iter_mut().zip(&flip) {
        if fl == 1 {
            t.swap(1, 2);
            n += 1;
        }
    }
    // Keep the majority orientation of each component as it was given.
    if n * 2 > nf {
        for t in tris.iter_mut() {
            t.swap(1, 2);
        }
        n = nf - n;
    }
    Ok(n)
}

/// Links twins, numbers edges, picks outgoing half-edges and checks vertex manifoldness.
fn link(positions: Vec<P3>, tris: Vec<[u32; 3]>, attributes: VertexAttributes) -> Result<Mesh> {
    let nv = positions.len();
    let nh = tris.len() * 3;
    let st = star(nv, &tris);
    let mut twin = vec![HalfedgeId::INVALID; nh];
    let mut edge_of = vec![EdgeId::INVALID; nh];
    let mut edge_he = Vec::with_capacity(nh / 2 + 1);
    for h in 0..nh as u32 {
        if edge_of[h as usize].is_valid() {
            continue;
        }
        let (a, b) = (tail(&tris, h), head(&tris, h));
        let e = EdgeId(edge_he.len() as u32);
        edge_of[h as usize] = e;
        let mut t = None;
        for &g in &st.he[st.off[b as usize] as usize..st.off[b as usize + 1] as usize] {
            if head(&tris, g) == a {
                t = Some(g);
                break;
            }
        }
        match t {
            Some(g) => {
                twin[h as usize] = HalfedgeId(g);
                twin[g as usize] = HalfedgeId(h);
                edge_of[g as usize] = e;
                edge_he.push(HalfedgeId(h));
            }
            None => edge_he.push(HalfedgeId(h)),
        }
    }
    let mut vertex_he = vec![HalfedgeId::INVALID; nv];
    for v in 0..nv {
        let hs = &st.he[st.off[v] as usize..st.off[v + 1] as usize];
        let start = hs.iter().copied().find(|&h| !twin[h as usize].is_valid()).unwrap_or(hs[0]);
        vertex_he[v] = HalfedgeId(start);
    }
    let mesh = Mesh {
        positions,
        faces: tris.iter().map(|t| t.map(VertexId)).collect(),
        twin,
        edge_of,
        edge_he,
        vertex_he,
        attributes,
    };
    // Vertex manifoldness: the fan reached by circulation must hold every incident face.
    for v in 0..nv {
        let degree = (st.off[v + 1] - st.off[v]) as usize;
        let fan = mesh.outgoing(VertexId::from_idx(v)).take(degree + 1).count();
        if fan != degree {
            let n_boundary = st.he[st.off[v] as usize..st.off[v + 1] as usize]
                .iter()
                .filter(|&&h| !mesh.twin[h as usize].is_valid())
                .count();
            let fans = n_boundary.max(2);
            return Err(InputError::NonManifoldVertex { vertex: v, fans }.into());
        }
    }
    let _ = FaceId::INVALID;
    Ok(mesh)
}
