//! Cutting a mesh along its layout: every face that a path crosses is split along the path's
//! chords (a convex polygon cut by non-crossing chords falls into convex pieces; pieces with
//! more than three corners are fanned from their centroid, so no sliver or zero-area triangle
//! appears where several path nodes lie on one edge). Path nodes become vertices, paths run on
//! edges, and every face of the result is labelled with its patch.

use super::Patch;
use super::tracer::Tracer;
use crate::error::{Error, Result};
use crate::mesh::{FaceId, HalfedgeId, Mesh, P3, VertexId};
use crate::topology::SurfacePoint;
use std::collections::{HashMap, HashSet};

/// A mesh refined so that its layout's paths run on edges.
pub struct Refined {
    pub mesh: Mesh,
    /// Per refined vertex: where it lies on the original mesh. Original vertices keep their ids.
    pub point: Vec<SurfacePoint>,
    /// Per refined face: the original face containing it.
    pub parent: Vec<FaceId>,
    /// Per refined face: its patch.
    pub patch: Vec<u32>,
    /// Per path: its refined vertices, anchor to anchor.
    pub path_vertices: Vec<Vec<VertexId>>,
}

/// Barycentric coordinates of `p` in original face `f` (which must contain it).
pub fn bary_in(mesh: &Mesh, f: FaceId, p: &SurfacePoint) -> [f64; 3] {
    let tri = mesh.face(f);
    let corner = |v: VertexId| tri.iter().position(|&x| x == v);
    let mut b = [0.0; 3];
    match *p {
        SurfacePoint::Vertex { vertex } => {
            if let Some(k) = corner(vertex) {
                b[k] = 1.0;
            }
        }
        SurfacePoint::Edge { halfedge, t } => {
            if let (Some(i), Some(j)) = (corner(mesh.tail(halfedge)), corner(mesh.head(halfedge))) {
                b[i] = 1.0 - t;
                b[j] = t;
            }
        }
        SurfacePoint::Face { face, bary } => {
            if face == f {
                b = bary;
            }
        }
    }
    b
}

/// Splits the faces of `t`'s mesh along its paths and labels the pieces with `patches`
/// (the walks of the layout).
///
/// # Errors
/// `Error::Internal` when a region of the cut mesh matches no patch.
pub fn refine(t: &Tracer, patches: &[Patch]) -> Result<Refined> {
    let mesh = t.mesh();
    let g = t.graph();
    let nv = mesh.n_vertices();
    let mut point: Vec<SurfacePoint> =
        (0..nv).map(|v| SurfacePoint::Vertex { vertex: VertexId::from_idx(v) }).collect();
    let mut vid_of: HashMap<u32, u32> = HashMap::new();
    let mut touched: HashSet<FaceId> = HashSet::new();
    let mut path_vertices = Vec::with_capacity(t.paths().len());
    for p in t.paths() {
        let mut pv = Vec::with_capacity(p.nodes.len());
        for n in &p.nodes {
            let v = match g.as_edge_node(*n) {
                None => n.0,
                Some((e, _)) => *vid_of.entry(n.0).or_insert_with(|| {
                    let (f, h) = mesh.edge_faces(e);
                    touched.insert(f);
                    if let Some(h) = h {
                        touched.insert(h);
                    }
                    point.push(g.surface_point(*n));
                    (point.len() - 1) as u32
                }),
            };
            pv.push(VertexId(v));
        }
        path_vertices.push(pv);
    }
    for f in 0..mesh.n_faces() {
        if !t.chords(FaceId::from_idx(f)).is_empty() {
            touched.insert(FaceId::from_idx(f));
        }
    }
    let mut tris: Vec<[u32; 3]> = Vec::with_capacity(mesh.n_faces() + 4 * touched.len());
    let mut parent: Vec<FaceId> = Vec::with_capacity(tris.capacity());
    for f in 0..mesh.n_faces() {
        let fid = FaceId::from_idx(f);
        let tri = mesh.face(fid);
        if !touched.contains(&fid) {
            tris.push(tri.map(|v| v.0));
            parent.push(fid);
            continue;
        }
        // Boundary positions of the face: corners and used edge nodes, in cyclic order.
        let mut ring: Vec<(u32, u32)> = Vec::new();
        for (k, corner) in tri.iter().enumerate() {
            let h = HalfedgeId::of(fid, k);
            ring.push(((k as u32) << 16, corner.0));
            let e = mesh.edge(h);
            let mut side: Vec<(u32, u32)> = (0..g.edge_node_count(e))
                .filter_map(|i| {
                    let n = g.edge_node(e, i);
                    let v = *vid_of.get(&n.0)?;
                    Some((g.face_position(fid, n)?, v))
                })
                .collect();
            side.sort_unstable();
            ring.extend(side);
        }
        let mut polys: Vec<Vec<usize>> = vec![(0..ring.len()).collect()];
        for &(a, b) in t.chords(fid) {
            let ia = ring.iter().position(|r| r.0 == a);
            let ib = ring.iter().position(|r| r.0 == b);
            let (Some(ia), Some(ib)) = (ia, ib) else {
                return Err(Error::Internal(format!("chord end missing on face {f}")));
            };
            let Some(k) = polys.iter().position(|p| p.contains(&ia) && p.contains(&ib)) else {
                return Err(Error::Internal(format!("crossing chords on face {f}")));
            };
            let poly = polys.swap_remove(k);
            let pa = poly.iter().position(|&x| x == ia).unwrap_or(0);
            let pb = poly.iter().position(|&x| x == ib).unwrap_or(0);
            let (s, e) = (pa.min(pb), pa.max(pb));
            polys.push(poly[s..=e].to_vec());
            let mut rest: Vec<usize> = poly[e..].to_vec();
            rest.extend_from_slice(&poly[..=s]);
            polys.push(rest);
        }
        for poly in polys {
            if poly.len() == 3 {
                tris.push([ring[poly[0]].1, ring[poly[1]].1, ring[poly[2]].1]);
                parent.push(fid);
                continue;
            }
            let mut b = [0.0; 3];
            for &i in &poly {
                let q = bary_in(mesh, fid, &point[ring[i].1 as usize]);
                for k in 0..3 {
                    b[k] += q[k] / poly.len() as f64;
                }
            }
            point.push(SurfacePoint::Face { face: fid, bary: b });
            let c = (point.len() - 1) as u32;
            for w in 0..poly.len() {
                tris.push([c, ring[poly[w]].1, ring[poly[(w + 1) % poly.len()]].1]);
                parent.push(fid);
            }
        }
    }
    let positions: Vec<P3> = point.iter().map(|p| p.position(mesh)).collect();
    let refined =
        Mesh::from_triangles(positions, &tris).map_err(|e| Error::Internal(format!("refined mesh is invalid: {e}")))?;
    let patch = label_patches(&refined, &path_vertices, patches)?;
    Ok(Refined { mesh: refined, point, parent, patch, path_vertices })
}

/// Flood-fills the faces between path edges and names each region by the walk on its side.
fn label_patches(m: &Mesh, path_vertices: &[Vec<VertexId>], patches: &[Patch]) -> Result<Vec<u32>> {
    // Directed path edges -> half (2p forward, 2p + 1 backward).
    let mut dir: HashMap<(u32, u32), u32> = HashMap::new();
    for (p, pv) in path_vertices.iter().enumerate() {
        for w in pv.windows(2) {
            dir.insert((w[0].0, w[1].0), 2 * p as u32);
            dir.insert((w[1].0, w[0].0), 2 * p as u32 + 1);
        }
    }
    let mut patch_of_half: HashMap<u32, u32> = HashMap::new();
    for (i, p) in patches.iter().enumerate() {
        for &h in &p.sides {
            patch_of_half.insert(h, i as u32);
        }
    }
    let nf = m.n_faces();
    let mut label = vec![u32::MAX; nf];
    let mut stack = Vec::new();
    for start in 0..nf {
        if label[start] != u32::MAX {
            continue;
        }
        let mut region = vec![start];
        let mut name = None;
        label[start] = u32::MAX - 1;
        stack.push(start);
        while let Some(f) = stack.pop() {
            for k in 0..3 {
                let h = HalfedgeId::of(FaceId::from_idx(f), k);
                let (u, w) = (m.tail(h).0, m.head(h).0);
                if let Some(&half) = dir.get(&(u, w)) {
                    // The face lies left of u -> w, i.e. right of the opposite half.
                    name = name.or(patch_of_half.get(&(half ^ 1)).copied());
                    continue;
                }
                if let Some(tw) = m.twin(h) {
                    let g = tw.face().idx();
                    if label[g] == u32::MAX {
                        label[g] = u32::MAX - 1;
                        region.push(g);
                        stack.push(g);
                    }
                }
            }
        }
        let Some(name) = name else {
            return Err(Error::Internal("a region of the cut mesh touches no path".into()));
        };
        for f in region {
            label[f] = name;
        }
    }
    Ok(label)
}
