//! Validated construction of a [`Mesh`] from raw reader output: range and finiteness checks,
//! polygon triangulation, unreferenced-vertex removal, degenerate/duplicate face detection,
//! orientation repair, twin linking in linear time and the manifold checks.

use super::{EdgeId, HalfedgeId, Mesh, P3, VertexAttributes, VertexId, triangulate_polygon};
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
                            return Err(
                                InputError::IndexOutOfRange { face: f, index: i as i64, vertex_count: nv }.into()
                            );
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
                            return Err(
                                InputError::IndexOutOfRange { face: f, index: i as i64, vertex_count: nv }.into()
                            );
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
        let mut st = star(nv, &tris);
        let mut n_flipped = 0;
        let twin = match twins(&st, &tris)? {
            Some(t) => t,
            None => {
                // Some edge is used twice in one direction: repair the orientation, then link.
                n_flipped = orient(&st, &mut tris)?;
                st = star(nv, &tris);
                twins(&st, &tris)?.ok_or_else(|| crate::Error::Internal("orientation repair left a conflict".into()))?
            }
        };
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
        let mesh = link(positions, tris, &st, twin, attributes)?;
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
    /// Head vertex of `he[k]`, cached so scans stay in contiguous memory.
    head: Vec<u32>,
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
    let mut hd = vec![0u32; tris.len() * 3];
    for (f, t) in tris.iter().enumerate() {
        for k in 0..3 {
            let v = t[k] as usize;
            he[fill[v] as usize] = (3 * f + k) as u32;
            hd[fill[v] as usize] = t[(k + 1) % 3];
            fill[v] += 1;
        }
    }
    Star { off, he, head: hd }
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
    let (sa, ea) = (star.off[a as usize] as usize, star.off[a as usize + 1] as usize);
    for k in sa..ea {
        if star.head[k] == b && star.he[k] != h {
            out.push(star.he[k]);
        }
    }
    let (sb, eb) = (star.off[b as usize] as usize, star.off[b as usize + 1] as usize);
    for k in sb..eb {
        if star.head[k] == a {
            out.push(star.he[k]);
        }
    }
}

/// Checks edge manifoldness and duplicates, then makes the orientation consistent by a
/// breadth-first walk over faces. Returns the number of faces flipped.
fn orient(st: &Star, tris: &mut [[u32; 3]]) -> Result<usize> {
    let mut mates = Vec::new();
    let mut need_fix = false;
    for h in 0..(tris.len() * 3) as u32 {
        edge_mates(st, tris, h, &mut mates);
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
                edge_mates(st, tris, h, &mut mates);
                if let Some(&g) = mates.first() {
                    let o = (g / 3) as usize;
                    let same_dir = head(tris, g) == head(tris, h);
                    let want = flip[f] ^ u8::from(same_dir);
                    if flip[o] == u8::MAX {
                        flip[o] = want;
                        queue.push_back(o);
                    } else if flip[o] != want {
                        return Err(
                            InputError::NonOrientable { a: tail(tris, h) as usize, b: head(tris, h) as usize }.into()
                        );
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

/// Pairs every half-edge with its opposite in one pass. `Ok(None)` when an edge is used twice
/// in the same direction (orientation to repair); errors for non-manifold edges and faces that
/// duplicate a neighbour with the opposite orientation.
fn twins(st: &Star, tris: &[[u32; 3]]) -> Result<Option<Vec<HalfedgeId>>> {
    let nh = tris.len() * 3;
    let mut twin = vec![HalfedgeId::INVALID; nh];
    for h in 0..nh as u32 {
        let (a, b) = (tail(tris, h), head(tris, h));
        let (sa, ea) = (st.off[a as usize] as usize, st.off[a as usize + 1] as usize);
        for k in sa..ea {
            if st.head[k] == b && st.he[k] != h {
                return Ok(None);
            }
        }
        if twin[h as usize].is_valid() {
            continue;
        }
        let (sb, eb) = (st.off[b as usize] as usize, st.off[b as usize + 1] as usize);
        let mut found = None;
        let mut count = 1;
        for k in sb..eb {
            if st.head[k] == a {
                count += 1;
                found = Some(st.he[k]);
            }
        }
        if count > 2 {
            return Err(InputError::NonManifoldEdge { a: a as usize, b: b as usize, count }.into());
        }
        if let Some(g) = found {
            // Same third vertex on both sides: the two faces are one face twice.
            let third_h = tail(tris, HalfedgeId(h).prev().0);
            let third_g = tail(tris, HalfedgeId(g).prev().0);
            if third_h == third_g {
                let (f, o) = ((h / 3) as usize, (g / 3) as usize);
                return Err(InputError::DuplicateFace { face: f.max(o), other: f.min(o) }.into());
            }
            twin[h as usize] = HalfedgeId(g);
            twin[g as usize] = HalfedgeId(h);
        }
    }
    Ok(Some(twin))
}

/// Numbers edges, picks outgoing half-edges and checks vertex manifoldness.
fn link(
    positions: Vec<P3>,
    tris: Vec<[u32; 3]>,
    st: &Star,
    twin: Vec<HalfedgeId>,
    attributes: VertexAttributes,
) -> Result<Mesh> {
    let nv = positions.len();
    let (edge_of, edge_he) = edges_from_twins(&twin);
    let mut vertex_he = vec![HalfedgeId::INVALID; nv];
    for (v, slot) in vertex_he.iter_mut().enumerate() {
        let hs = &st.he[st.off[v] as usize..st.off[v + 1] as usize];
        let start = hs.iter().copied().find(|&h| !twin[h as usize].is_valid()).unwrap_or(hs[0]);
        *slot = HalfedgeId(start);
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
    Ok(mesh)
}

/// Undirected edges from the twin table: per half-edge its edge, per edge its first half-edge
/// (the only one on the boundary).
pub(super) fn edges_from_twins(twin: &[HalfedgeId]) -> (Vec<EdgeId>, Vec<HalfedgeId>) {
    let nh = twin.len();
    let mut edge_of = vec![EdgeId::INVALID; nh];
    let mut edge_he = Vec::with_capacity(nh / 2 + 1);
    for h in 0..nh {
        if edge_of[h].is_valid() {
            continue;
        }
        let e = EdgeId(edge_he.len() as u32);
        edge_of[h] = e;
        edge_he.push(HalfedgeId(h as u32));
        if twin[h].is_valid() {
            edge_of[twin[h].idx()] = e;
        }
    }
    (edge_of, edge_he)
}
