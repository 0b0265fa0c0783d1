//! The meta-mesh (Carner et al. section 4, after Lee et al. 1999): both tessellations overlaid
//! in the shared planar domain (the 4g-gon, or the circle of a feature job, see
//! [`super::feature_overlay`]). Every source triangle is clipped against the target triangles it
//! overlaps (Sutherland–Hodgman, convex against convex); each non-empty piece is a convex
//! polygon whose corners are source vertices, target vertices or crossings of a source edge with
//! a target edge, named symbolically so that neighbouring pieces share them. Pieces are fanned
//! into triangles; copies of a vertex on the two sides of a cut loop are glued through the
//! vertex they copy. The result has one face list and two vertex positions per meta-vertex:
//! on the source (barycentric in the source triangle it lies in) and on the target.

use super::sides::SideDomain;
use crate::error::{Error, Result};
use crate::mesh::{Mesh, P3, VertexId};
use crate::param::Uv;
use crate::planar::locate::barycentric;
use std::collections::HashMap;

/// The merged tessellation.
#[derive(Debug, Clone)]
pub struct MetaMeshResult {
    pub faces: Vec<[u32; 3]>,
    /// Per meta-vertex: position on the source surface.
    pub on_source: Vec<P3>,
    /// Per meta-vertex: position on the target surface.
    pub on_target: Vec<P3>,
    /// Meta-vertices that are crossings of a source edge with a target edge.
    pub crossings: usize,
    /// Per meta-vertex: whether it is such a crossing.
    pub crossing: Vec<bool>,
}

impl MetaMeshResult {
    /// The two meshes (same faces).
    ///
    /// # Errors
    /// `Numerical` when the overlay is not a valid manifold mesh.
    pub fn meshes(&self) -> Result<(Mesh, Mesh)> {
        let s = Mesh::from_triangles(self.on_source.clone(), &self.faces)
            .map_err(|e| Error::Numerical(format!("meta-mesh on the source: {e}")))?;
        let t = Mesh::from_triangles(self.on_target.clone(), &self.faces)
            .map_err(|e| Error::Numerical(format!("meta-mesh on the target: {e}")))?;
        Ok((s, t))
    }
}

/// A surface vertex a disk vertex stands for: of the source or of the target (copies across a
/// cut are one vertex).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub(crate) enum VKey {
    S(u32),
    T(u32),
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum Key {
    V(VKey),
    /// Source edge (its ends' keys) crossing target edge.
    X([VKey; 2], [VKey; 2]),
}

/// One side of an overlay: a planar triangulated disk (positions on this side's surface), the
/// planar position and the key of each of its vertices.
pub(crate) struct OverlayDisk<'a> {
    pub mesh: &'a Mesh,
    pub uv: &'a [Uv],
    pub key: Vec<VKey>,
}

/// The surfaces the keys index, and keys that are one meta-vertex: `(target key, source key)`
/// pairs of points the two domains share (the homology base vertex, feature junctions).
pub(crate) struct OverlayInput<'a> {
    pub source: OverlayDisk<'a>,
    pub target: OverlayDisk<'a>,
    pub source_surface: &'a Mesh,
    pub target_surface: &'a Mesh,
    pub same: Vec<(VKey, VKey)>,
}

#[derive(Debug, Clone, Copy)]
enum Support {
    /// Source disk edge (disk vertex ids).
    Src(u32, u32),
    /// Target disk edge.
    Tgt(u32, u32),
}

#[derive(Debug, Clone, Copy)]
struct PV {
    p: Uv,
    key: Key,
    /// Support of the edge that starts here.
    next: Support,
}

/// `[x min, x max, y min, y max]` of a triangle.
fn bbox(t: [Uv; 3]) -> [f64; 4] {
    let (xs, ys) = (t.map(|p| p[0]), t.map(|p| p[1]));
    [
        xs.into_iter().fold(f64::MAX, f64::min),
        xs.into_iter().fold(f64::MIN, f64::max),
        ys.into_iter().fold(f64::MAX, f64::min),
        ys.into_iter().fold(f64::MIN, f64::max),
    ]
}

use crate::planar::area2 as cross;

/// Overlays the source's domain (turned by `angle`) and the target's.
///
/// # Errors
/// `Numerical` when a piece cannot be placed.
pub fn meta_mesh(s: &SideDomain, t: &SideDomain, angle: f64) -> Result<MetaMeshResult> {
    let (ca, sa) = (angle.cos(), angle.sin());
    let us: Vec<Uv> = s.domain.uv.iter().map(|p| [p[0] * ca - p[1] * sa, p[0] * sa + p[1] * ca]).collect();
    let (ds, dt) = (&s.basis.disk, &t.basis.disk);
    overlay(&OverlayInput {
        source: OverlayDisk { mesh: &ds.mesh, uv: &us, key: ds.orig.iter().map(|v| VKey::S(v.0)).collect() },
        target: OverlayDisk { mesh: &dt.mesh, uv: &t.domain.uv, key: dt.orig.iter().map(|v| VKey::T(v.0)).collect() },
        source_surface: &s.basis.refined.mesh,
        target_surface: &t.basis.refined.mesh,
        // The base vertex is a corner of both polygons: one meta-vertex.
        same: vec![(VKey::T(t.basis.base.0), VKey::S(s.basis.base.0))],
    })
}

/// Overlays two planar disks that tile the same region.
///
/// # Errors
/// `Numerical` when a piece cannot be placed.
pub(crate) fn overlay(input: &OverlayInput) -> Result<MetaMeshResult> {
    let (ds, dt) = (&input.source, &input.target);
    let us = ds.uv;
    let ut = dt.uv;
    let tt = dt.mesh.face_indices();
    let st = ds.mesh.face_indices();
    let alias: HashMap<VKey, VKey> = input.same.iter().copied().collect();
    let grid = BucketGrid::new(&tt, ut);
    let mut ids: HashMap<Key, u32> = HashMap::new();
    let mut on_source: Vec<P3> = Vec::new();
    let mut on_target: Vec<P3> = Vec::new();
    let mut faces: Vec<[u32; 3]> = Vec::new();
    let mut crossings = 0;
    let mut crossing: Vec<bool> = Vec::new();
    let mut stamp = vec![u32::MAX; tt.len()];
    let bary = |tri: [Uv; 3], p: Uv| barycentric(tri, p).map(|x| x.clamp(0.0, 1.0));
    let point = |m: &Mesh, tri: [u32; 3], b: [f64; 3]| {
        let s: f64 = b.iter().sum::<f64>().max(f64::MIN_POSITIVE);
        let mut acc = P3::origin().coords;
        for k in 0..3 {
            acc += m.position(VertexId(tri[k])).coords * (b[k] / s);
        }
        P3::from(acc)
    };
    for (sf, stri) in st.iter().enumerate() {
        let sp = stri.map(|v| us[v as usize]);
        for &tf in grid.cells(bbox(sp)).flatten() {
            if stamp[tf as usize] == sf as u32 {
                continue;
            }
            stamp[tf as usize] = sf as u32;
            let ttri = tt[tf as usize];
            let tp = ttri.map(|v| ut[v as usize]);
            let Some(poly) = clip(input, (*stri, sp), (ttri, tp)) else { continue };
            let mut vid = Vec::with_capacity(poly.len());
            for pv in &poly {
                let next_id = on_source.len() as u32;
                let key = match pv.key {
                    Key::V(k) => Key::V(alias.get(&k).copied().unwrap_or(k)),
                    x => x,
                };
                let id = *ids.entry(key).or_insert(next_id);
                if id == next_id {
                    let ps = point(ds.mesh, *stri, bary(sp, pv.p));
                    let pt = point(dt.mesh, ttri, bary(tp, pv.p));
                    on_source.push(ps);
                    on_target.push(pt);
                    crossing.push(matches!(key, Key::X(..)));
                    if matches!(key, Key::X(..)) {
                        crossings += 1;
                    }
                }
                vid.push(id);
            }
            for k in 1..vid.len() - 1 {
                if vid[0] != vid[k] && vid[k] != vid[k + 1] && vid[0] != vid[k + 1] {
                    faces.push([vid[0], vid[k], vid[k + 1]]);
                }
            }
        }
    }
    // Exact positions where the meta-vertex is an input vertex (on both surfaces where it is a
    // shared point).
    let (ms, mt) = (input.source_surface, input.target_surface);
    for (key, &id) in &ids {
        match key {
            Key::V(VKey::S(v)) => on_source[id as usize] = ms.position(VertexId(*v)),
            Key::V(VKey::T(v)) => on_target[id as usize] = mt.position(VertexId(*v)),
            Key::X(..) => {}
        }
    }
    for &(tk, sk) in &input.same {
        if let (Some(&id), VKey::T(v)) = (ids.get(&Key::V(sk)), tk) {
            on_target[id as usize] = mt.position(VertexId(v));
        }
    }
    Ok(MetaMeshResult { faces, on_source, on_target, crossings, crossing })
}

/// The piece of source triangle `stri` (disk positions `sp`) inside target triangle `ttri`
/// (`tp`), as a convex polygon whose corners carry their meta-vertex keys (a disk vertex of
/// either side, or the crossing of a source edge with a target edge), by clipping against the
/// target triangle's sides in turn; `None` when the piece is empty or without area.
fn clip(input: &OverlayInput, (stri, sp): ([u32; 3], [Uv; 3]), (ttri, tp): ([u32; 3], [Uv; 3])) -> Option<Vec<PV>> {
    let eps = 1e-12;
    let (ds, dt) = (&input.source, &input.target);
    let so = |v: u32| ds.key[v as usize];
    let to = |v: u32| dt.key[v as usize];
    let pair = |a: VKey, b: VKey| if a < b { [a, b] } else { [b, a] };
    let mut poly: Vec<PV> = (0..3)
        .map(|k| PV { p: sp[k], key: Key::V(so(stri[k])), next: Support::Src(stri[k], stri[(k + 1) % 3]) })
        .collect();
    for j in 0..3 {
        let (qa, qb) = (tp[j], tp[(j + 1) % 3]);
        let len = ((qb[0] - qa[0]).powi(2) + (qb[1] - qa[1]).powi(2)).sqrt();
        if len == 0.0 {
            poly.clear();
            break;
        }
        let dist = |p: Uv| cross(qa, qb, p) / len;
        let te = (ttri[j], ttri[(j + 1) % 3]);
        let mut out = Vec::with_capacity(poly.len() + 2);
        for i in 0..poly.len() {
            let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
            let (da, db) = (dist(a.p), dist(b.p));
            let (ain, bin) = (da >= -eps, db >= -eps);
            if ain {
                if !bin && da.abs() <= eps {
                    out.push(PV { next: Support::Tgt(te.0, te.1), ..a });
                    continue;
                }
                out.push(a);
            }
            if ain != bin && da.abs() > eps && db.abs() > eps {
                let u = da / (da - db);
                let ip = [a.p[0] + (b.p[0] - a.p[0]) * u, a.p[1] + (b.p[1] - a.p[1]) * u];
                let key = match a.next {
                    Support::Tgt(x, y) => {
                        // Two target edges meet at their shared vertex.
                        let shared = [x, y].into_iter().find(|&v| v == te.0 || v == te.1);
                        shared.map_or(Key::V(to(te.0)), |v| Key::V(to(v)))
                    }
                    Support::Src(x, y) => {
                        // Along the target edge: snap to its ends.
                        let tl = ((ip[0] - qa[0]) * (qb[0] - qa[0]) + (ip[1] - qa[1]) * (qb[1] - qa[1])) / (len * len);
                        if tl <= eps {
                            Key::V(to(te.0))
                        } else if tl >= 1.0 - eps {
                            Key::V(to(te.1))
                        } else if u <= eps {
                            a.key
                        } else if u >= 1.0 - eps {
                            b.key
                        } else {
                            Key::X(pair(so(x), so(y)), pair(to(te.0), to(te.1)))
                        }
                    }
                };
                let next = if ain { Support::Tgt(te.0, te.1) } else { a.next };
                out.push(PV { p: ip, key, next });
            }
        }
        poly = out;
        if poly.len() < 3 {
            break;
        }
    }
    // Drop repeated keys (snapped corners) and empty pieces.
    poly.dedup_by(|b, a| a.key == b.key);
    while poly.len() > 1 && poly[0].key == poly[poly.len() - 1].key {
        poly.pop();
    }
    if poly.len() < 3 {
        return None;
    }
    let area: f64 = (1..poly.len() - 1).map(|k| cross(poly[0].p, poly[k].p, poly[k + 1].p)).sum();
    (area > 1e-24).then_some(poly)
}

/// A bucket grid over the target disk's triangles (the disks lie in [-1, 1]²), about one
/// triangle per cell.
struct BucketGrid {
    cells: usize,
    buckets: Vec<Vec<u32>>,
}

impl BucketGrid {
    const LO: [f64; 2] = [-1.0, -1.0];
    const HI: [f64; 2] = [1.0, 1.0];

    fn new(tris: &[[u32; 3]], uv: &[Uv]) -> BucketGrid {
        let cells = (tris.len().max(1) as f64).sqrt().ceil() as usize;
        let mut g = BucketGrid { cells, buckets: vec![Vec::new(); cells * cells] };
        for (f, tri) in tris.iter().enumerate() {
            let b = bbox(tri.map(|v| uv[v as usize]));
            for y in g.cell_of(b[2], 1)..=g.cell_of(b[3], 1) {
                for x in g.cell_of(b[0], 0)..=g.cell_of(b[1], 0) {
                    g.buckets[y * cells + x].push(f as u32);
                }
            }
        }
        g
    }

    fn cell_of(&self, x: f64, k: usize) -> usize {
        let cw = (Self::HI[0] - Self::LO[0]) / self.cells as f64;
        (((x - Self::LO[k]) / cw).floor().max(0.0) as usize).min(self.cells - 1)
    }

    /// The buckets a bounding box `[x0, x1, y0, y1]` covers, row by row.
    fn cells(&self, b: [f64; 4]) -> impl Iterator<Item = &Vec<u32>> + '_ {
        let (xs, ys) = (self.cell_of(b[0], 0)..=self.cell_of(b[1], 0), self.cell_of(b[2], 1)..=self.cell_of(b[3], 1));
        ys.flat_map(move |y| xs.clone().map(move |x| &self.buckets[y * self.cells + x]))
    }
}
