//! Attribute transfer through a map: the target, in its own layout, gets the source's UVs,
//! colours or skin weights at the image of each of its face corners.
//!
//! Per face corner, not per vertex, so a seam of the source becomes a seam of the target instead
//! of a smeared triangle: each target face takes one *chart*, the source face under the image of
//! its centroid. A corner whose image lies in a face of the same chart (no seam between, judged
//! by the attribute jump) takes the exact piecewise-linear value there; a corner across a seam
//! takes the chart face's affine extension (its barycentric coordinates in that face's plane).
//! Target vertices whose corners then disagree are split. Skin weights are combined per joint
//! from the three source corners, the strongest four kept and renormalized.

use crate::error::Result;
use crate::mesh::insert::barycentric;
use crate::mesh::{Attributes, FaceId, InputLayout, Mesh, P3};
use crate::topology::Locator;
use std::collections::HashMap;

/// Which attributes to carry (glTF names).
#[derive(Debug, Clone, Default)]
pub struct TransferOptions {
    pub texcoords: Vec<usize>,
    pub color: bool,
    pub skin: bool,
}

/// The target in its own layout with the carried attributes (seam copies added).
#[derive(Debug, Clone)]
pub struct TransferResult {
    pub positions: Vec<P3>,
    pub triangles: Vec<[u32; 3]>,
    pub attributes: Attributes,
    /// Target input vertices split because their corners took different values.
    pub split_vertices: usize,
}

/// The source side: the original mesh, its layout, and a locator for points of its surface.
pub struct SourceField<'a> {
    pub mesh: &'a Mesh,
    pub layout: Option<&'a InputLayout>,
    pub locator: Locator,
}

/// Smooth values of one corner: UV sets then RGBA, flattened.
type Smooth = Vec<f32>;

impl SourceField<'_> {
    /// Input vertices of source face `f`'s corners.
    fn corners(&self, f: FaceId) -> [u32; 3] {
        match self.layout {
            Some(l) => l.triangles[f.idx()],
            None => self.mesh.faces()[f.idx()].map(|v| v.0),
        }
    }

    fn smooth_at(&self, a: &Attributes, o: &TransferOptions, f: FaceId, w: [f64; 3]) -> Smooth {
        let c = self.corners(f);
        let mut out = Vec::new();
        for &k in &o.texcoords {
            for d in 0..2 {
                out.push((0..3).map(|i| w[i] * f64::from(a.texcoords[k][c[i] as usize][d])).sum::<f64>() as f32);
            }
        }
        if let (true, Some(col)) = (o.color, &a.color) {
            let rgba = |i: usize| col[c[i] as usize];
            out.extend((0..4).map(|d| (0..3).map(|i| w[i] * f64::from(rgba(i)[d])).sum::<f64>() as f32));
        }
        out
    }

    fn skin_at(&self, a: &Attributes, f: FaceId, w: [f64; 3]) -> ([u16; 4], [f32; 4]) {
        let (Some(j), Some(wt)) = (&a.joints, &a.weights) else { return ([0; 4], [1.0, 0.0, 0.0, 0.0]) };
        let mut acc: HashMap<u16, f64> = HashMap::new();
        for (i, &v) in self.corners(f).iter().enumerate() {
            for k in 0..4 {
                *acc.entry(j[v as usize][k]).or_default() += w[i] * f64::from(wt[v as usize][k]);
            }
        }
        let mut all: Vec<(u16, f64)> = acc.into_iter().filter(|x| x.1 > 0.0).collect();
        all.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
        all.truncate(4);
        let s: f64 = all.iter().map(|x| x.1).sum();
        let (mut jo, mut wo) = ([0u16; 4], [0f32; 4]);
        for (k, (jj, ww)) in all.iter().enumerate() {
            jo[k] = *jj;
            wo[k] = (ww / s.max(1e-300)) as f32;
        }
        (jo, wo)
    }

    /// `(face, bary)` of a point of the surface.
    fn locate(&self, p: &P3) -> (FaceId, [f64; 3]) {
        let pr = self.locator.project(p);
        (pr.face, pr.bary)
    }
}

fn clamp(w: [f64; 3]) -> [f64; 3] {
    let w = w.map(|x| x.max(0.0));
    let s: f64 = w.iter().sum();
    w.map(|x| x / s.max(1e-300))
}

/// Carries the source's attributes onto the target. `images[v]` is the source-surface point of
/// target mesh vertex `v` (the target -> source map).
///
/// # Errors
/// Only `Internal` on an inconsistent layout.
pub fn transfer(
    src: &SourceField,
    target: &Mesh,
    target_layout: Option<&InputLayout>,
    images: &[P3],
    o: &TransferOptions,
) -> Result<TransferResult> {
    let a = src.layout.map_or_else(|| Attributes::from(src.mesh.attributes()), |l| l.attributes.clone());
    let (t_tris, t_welded): (Vec<[u32; 3]>, Vec<u32>) = match target_layout {
        Some(l) => (l.triangles.clone(), l.welded.clone()),
        None => (target.face_indices(), (0..target.n_vertices() as u32).collect()),
    };
    let located: Vec<(FaceId, [f64; 3])> = images.iter().map(|p| src.locate(p)).collect();
    // Per corner: smooth values, skin.
    let mut corner_smooth: Vec<Smooth> = Vec::with_capacity(3 * t_tris.len());
    let mut corner_skin = Vec::with_capacity(3 * t_tris.len());
    for tri in &t_tris {
        let vs = tri.map(|i| t_welded[i as usize] as usize);
        let c = P3::from((images[vs[0]].coords + images[vs[1]].coords + images[vs[2]].coords) / 3.0);
        let (fr, _) = src.locate(&c);
        let [ra, rb, rc] = src.mesh.faces()[fr.idx()].map(|v| src.mesh.position(v));
        // The chart face's own spread of values: a larger jump to a corner's value is a seam.
        let vals: Vec<Smooth> =
            [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]].iter().map(|w| src.smooth_at(&a, o, fr, *w)).collect();
        let extent = (0..vals[0].len())
            .map(|d| (0..3).map(|i| (vals[i][d] - vals[(i + 1) % 3][d]).abs()).fold(0f32, f32::max))
            .fold(0f32, f32::max);
        for &v in &vs {
            let (f, w) = located[v];
            let own = src.smooth_at(&a, o, f, clamp(w));
            let ext = src.smooth_at(&a, o, fr, barycentric(&images[v], &ra, &rb, &rc));
            let jump = own.iter().zip(&ext).map(|(x, y)| (x - y).abs()).fold(0f32, f32::max);
            corner_smooth.push(if f == fr || jump <= 0.5 * extent + 1e-6 { own } else { ext });
            corner_skin.push(if o.skin { Some(src.skin_at(&a, f, clamp(w))) } else { None });
        }
    }
    // Split target input vertices whose corners disagree.
    let n_in = t_welded.len();
    let mut copies: Vec<Vec<(Smooth, u32)>> = vec![Vec::new(); n_in];
    let mut positions: Vec<P3> = t_welded.iter().map(|&w| target.position(crate::mesh::VertexId(w))).collect();
    let mut origin: Vec<u32> = (0..n_in as u32).collect();
    let mut triangles = Vec::with_capacity(t_tris.len());
    for (f, tri) in t_tris.iter().enumerate() {
        let mut out = [0u32; 3];
        for k in 0..3 {
            let (v, val) = (tri[k] as usize, &corner_smooth[3 * f + k]);
            let same = |x: &Smooth| x.iter().zip(val).all(|(a, b)| (a - b).abs() <= 1e-5);
            let id = match copies[v].iter().find(|c| same(&c.0)) {
                Some(c) => c.1,
                None => {
                    let id = if copies[v].is_empty() { v as u32 } else { positions.len() as u32 };
                    if id as usize >= n_in {
                        positions.push(positions[v]);
                        origin.push(v as u32);
                    }
                    copies[v].push((val.clone(), id));
                    id
                }
            };
            out[k] = id;
        }
        triangles.push(out);
    }
    // Values per output vertex.
    let n_out = positions.len();
    let mut smooth_out: Vec<Smooth> = vec![Vec::new(); n_out];
    for c in copies.iter().flatten() {
        smooth_out[c.1 as usize] = c.0.clone();
    }
    let mut attrs =
        target_layout.map_or_else(|| Attributes::from(target.attributes()), |l| l.attributes.clone()).select(&origin);
    let mut d = 0;
    for slot in 0..o.texcoords.len() {
        let uv: Vec<[f32; 2]> = smooth_out
            .iter()
            .map(|s| [s.get(d).copied().unwrap_or(0.0), s.get(d + 1).copied().unwrap_or(0.0)])
            .collect();
        d += 2;
        if attrs.texcoords.len() > slot {
            attrs.texcoords[slot] = uv;
        } else {
            attrs.texcoords.push(uv);
        }
    }
    if o.color && a.color.is_some() {
        attrs.color =
            Some(smooth_out.iter().map(|s| std::array::from_fn(|i| s.get(d + i).copied().unwrap_or(1.0))).collect());
    }
    if o.skin {
        let mut j = vec![[0u16; 4]; n_out];
        let mut w = vec![[1.0f32, 0.0, 0.0, 0.0]; n_out];
        for (f, tri) in triangles.iter().enumerate() {
            for k in 0..3 {
                if let Some((jj, ww)) = corner_skin[3 * f + k] {
                    j[tri[k] as usize] = jj;
                    w[tri[k] as usize] = ww;
                }
            }
        }
        attrs.joints = Some(j);
        attrs.weights = Some(w);
    }
    Ok(TransferResult { positions, triangles, attributes: attrs, split_vertices: n_out - n_in })
}
