//! Quad patches on any genus the `voronoi` layout supports (Yu & Chuang's extension beyond
//! genus 0): the common base domain of all models is built from the anchor rows (the source
//! layout on model 0, the same connectivity rebuilt on every other model), each layout triangle
//! is flattened onto the canonical triangle (mean value, sides by arc length), its embedding is
//! stretch-optimized with the boundary fixed (Sander et al., as for genus-0 patches), and every
//! triangle is split into three quads through its centroid and its side midpoints: quad `k`
//! is the kite `(X_k, M_k, O, M_{k-1})`, reached from the unit square by the bilinear map of its
//! corners. Midpoints are at half the arc length of their layout path on every model, so quads
//! of neighbouring triangles share sides exactly, and every anchor is a quad corner on every
//! model (features are aligned by construction).

use super::layout::{QuadLayout, QuadPatchLayout, QuadSide};
use super::stretch::{ParamState, PatchSoup, StretchOptOptions, mesh_stretch};
use super::surface::{QuadSurface, interpolate, vertex_normals};
use crate::crossparam::{PatchParam, PatchParamOptions, TRIANGLE, parameterize_patches};
use crate::domain::refine::{Refined, refine};
use crate::domain::tracer::Tracer;
use crate::domain::{LayoutOptions, Patch, patches_of, straighten::straighten, voronoi};
use crate::error::{Error, InputError, Result};
use crate::mesh::{Mesh, P3, V3, VertexId};
use crate::param::Uv;
use crate::planar::locate::{Grid, barycentric};
use crate::progress::Progress;

/// One model: its refined mesh and its triangle parameterizations.
pub struct TriModel {
    pub refined: Refined,
    pub params: Vec<PatchParam>,
    normals: Vec<V3>,
    /// Per triangle: normalized (L2, L∞) stretch of the mean-value map and of the optimized one.
    pub stretch: Vec<((f64, f64), (f64, f64))>,
    /// Whole model: mean-value start and final.
    pub total: ((f64, f64), (f64, f64)),
}

/// All models' quads over one voronoi layout.
pub struct TriQuads {
    pub layout: QuadLayout,
    pub patches: Vec<Patch>,
    pub models: Vec<TriModel>,
}

fn bilinear(c: [Uv; 4], st: Uv) -> Uv {
    let [s, t] = st;
    let w = [(1.0 - s) * (1.0 - t), s * (1.0 - t), s * t, (1.0 - s) * t];
    [0, 1].map(|k| w[0] * c[0][k] + w[1] * c[1][k] + w[2] * c[2][k] + w[3] * c[3][k])
}

/// Corners of quad `k` of the canonical triangle: `X_k, M_k, O, M_{k-1}`.
pub fn kite(k: usize) -> [Uv; 4] {
    let t = TRIANGLE;
    let mid = |a: usize| [(t[a][0] + t[(a + 1) % 3][0]) / 2.0, (t[a][1] + t[(a + 1) % 3][1]) / 2.0];
    let o = [(t[0][0] + t[1][0] + t[2][0]) / 3.0, (t[0][1] + t[1][1] + t[2][1]) / 3.0];
    [t[k], mid(k), o, mid((k + 2) % 3)]
}

/// Inverse of [`bilinear`] on a convex quad (Newton from the centre), clamped to the square.
fn inverse_bilinear(c: [Uv; 4], p: Uv) -> Uv {
    let mut st = [0.5, 0.5];
    for _ in 0..20 {
        let q = bilinear(c, st);
        let r = [q[0] - p[0], q[1] - p[1]];
        let [s, t] = st;
        let ds = [0, 1].map(|k| (1.0 - t) * (c[1][k] - c[0][k]) + t * (c[2][k] - c[3][k]));
        let dt = [0, 1].map(|k| (1.0 - s) * (c[3][k] - c[0][k]) + s * (c[2][k] - c[1][k]));
        let det = ds[0] * dt[1] - ds[1] * dt[0];
        if det.abs() < 1e-300 {
            break;
        }
        let step = [(r[0] * dt[1] - r[1] * dt[0]) / det, (ds[0] * r[1] - ds[1] * r[0]) / det];
        st = [st[0] - step[0], st[1] - step[1]];
        if step[0].abs() + step[1].abs() < 1e-14 {
            break;
        }
    }
    st.map(|x| x.clamp(0.0, 1.0))
}

/// The quad layout of triangle patches: anchors, then one midpoint per path, then one centre
/// per triangle; curves: each path's two halves, then three spokes per triangle.
fn quad_layout(t: &Tracer, patches: &[Patch]) -> Result<QuadLayout> {
    let na = t.anchors().len() as u32;
    let np = t.paths().len() as u32;
    let mut curves: Vec<[u32; 2]> = Vec::with_capacity(2 * np as usize + 3 * patches.len());
    for (p, path) in t.paths().iter().enumerate() {
        curves.push([path.a, na + p as u32]);
        curves.push([na + p as u32, path.b]);
    }
    let mut quads = Vec::with_capacity(3 * patches.len());
    for (pi, patch) in patches.iter().enumerate() {
        // CCW corners in the canonical triangle: c0, c2, c1; side k runs X_k -> X_{k+1} as the
        // reverse of half sides[2 - k].
        let x = [patch.corners[0], patch.corners[2], patch.corners[1]];
        let g: [u32; 3] = [0, 1, 2].map(|k| patch.sides[2 - k] ^ 1);
        let centre = na + np + pi as u32;
        let spoke0 = curves.len() as u32;
        for &gk in &g {
            curves.push([na + gk / 2, centre]);
        }
        let first = |k: usize| {
            let p = g[k] / 2;
            if g[k].is_multiple_of(2) {
                QuadSide { curve: 2 * p, reversed: false }
            } else {
                QuadSide { curve: 2 * p + 1, reversed: true }
            }
        };
        let second = |k: usize| {
            let p = g[k] / 2;
            if g[k].is_multiple_of(2) {
                QuadSide { curve: 2 * p + 1, reversed: false }
            } else {
                QuadSide { curve: 2 * p, reversed: true }
            }
        };
        for k in 0..3 {
            let km = (k + 2) % 3;
            quads.push(QuadPatchLayout {
                corners: [x[k], na + g[k] / 2, centre, na + g[km] / 2],
                sides: [
                    first(k),
                    QuadSide { curve: spoke0 + k as u32, reversed: false },
                    QuadSide { curve: spoke0 + km as u32, reversed: true },
                    second(km),
                ],
            });
        }
    }
    let layout = QuadLayout { n_corners: (na + np) as usize + patches.len(), curves, patches: quads };
    if !layout.is_consistent() {
        return Err(Error::Internal("the quad split of the layout is inconsistent".into()));
    }
    Ok(layout)
}

/// Builds the common layout of `meshes` from anchor rows and splits it into quads.
///
/// # Errors
/// Layout errors of the `voronoi` method (`LayoutConflict`, too few anchors), numerical
/// failures, `Cancelled`.
pub fn tri_quads(meshes: &[&Mesh], rows: &[Vec<VertexId>], progress: &mut dyn Progress) -> Result<TriQuads> {
    let chi = crate::topology::euler_characteristic(meshes[0]);
    let anchors: Vec<Vec<VertexId>> = (0..meshes.len()).map(|m| rows.iter().map(|r| r[m]).collect()).collect();
    let lo = LayoutOptions::default();
    let mut edge_nodes = lo.edge_nodes;
    let mut attempt = 0;
    let mut tracers = loop {
        let mut ts =
            meshes.iter().zip(&anchors).map(|(m, a)| Tracer::new(m, a, &edge_nodes)).collect::<Result<Vec<_>>>()?;
        let built = (|| -> Result<()> {
            let (first, rest) = ts.split_first_mut().ok_or_else(|| Error::Internal("no model".into()))?;
            let (cl, _) = voronoi::source_layout(first, chi, &lo, progress)?;
            for t in rest {
                voronoi::target_layout_with_restarts(first, &cl, t, &lo, 8, progress)?;
            }
            Ok(())
        })();
        match built {
            Ok(()) => break ts,
            Err(Error::Input(InputError::LayoutConflict(_))) if attempt < lo.rebuilds => {
                edge_nodes.min_nodes = edge_nodes.min_nodes * 2 - 1;
                edge_nodes.max_nodes = edge_nodes.max_nodes.max(edge_nodes.min_nodes);
                attempt += 1;
            }
            Err(e) => return Err(e),
        }
    };
    for t in &mut tracers {
        straighten(t, lo.straighten_rounds, progress)?;
    }
    let patches = patches_of(&tracers[0]);
    let layout = quad_layout(&tracers[0], &patches)?;
    let popts = PatchParamOptions { stretch_iterations: 0, ..Default::default() };
    let mut models = Vec::with_capacity(meshes.len());
    for (m, t) in tracers.iter().enumerate() {
        progress.check()?;
        let refined = refine(t, &patches)?;
        let mut params = parameterize_patches(&refined, &patches, &anchors[m], &popts, progress)?;
        let mut stretch = Vec::with_capacity(params.len());
        let mut soup = PatchSoup::default();
        for (pi, pp) in params.iter_mut().enumerate() {
            progress.report(crate::progress::Stage::Parameterize, pi as f64 / patches.len() as f64);
            let n = pp.local.n_vertices();
            let mut fixed = vec![false; n];
            for v in &pp.boundary {
                fixed[v.idx()] = true;
            }
            let before = mesh_stretch(pp.local.positions(), &pp.uv, pp.tris.iter().copied());
            let mut st = ParamState::new(
                pp.local.positions().to_vec(),
                pp.uv.clone(),
                pp.tris.clone(),
                vec![true; pp.tris.len()],
                fixed,
                0x5eed + pi as u64,
            );
            // Flat triangles (three corners on one side of the triangle, which the layout
            // refinement can leave) have only fixed corners, so they are in no free vertex's star
            // and the optimization cannot change them; it must not add any.
            let flat = st.flipped();
            let all: Vec<u32> = (0..n as u32).collect();
            st.optimize(&all, &StretchOptOptions::default());
            if st.flipped() > flat {
                return Err(Error::Internal(format!("stretch optimization of triangle {pi} folded")));
            }
            let after = mesh_stretch(pp.local.positions(), &st.uv, pp.tris.iter().copied());
            soup.add(pp.local.positions(), &pp.tris, &pp.uv, &st.uv);
            pp.uv = st.uv;
            pp.grid = Grid::new(&pp.uv, &pp.tris);
            stretch.push((before, after));
        }
        let total = soup.stretch();
        let normals = vertex_normals(&refined.mesh);
        models.push(TriModel { refined, params, normals, stretch, total });
    }
    Ok(TriQuads { layout, patches, models })
}

impl QuadSurface for &TriModel {
    fn n_quads(&self) -> usize {
        3 * self.params.len()
    }

    fn sample(&self, q: usize, st: Uv) -> (P3, V3) {
        let (pi, k) = (q / 3, q % 3);
        let (f, b) = self.params[pi].locate(bilinear(kite(k), st));
        let t = self.refined.mesh.face(f).map(|v| v.0);
        interpolate(self.refined.mesh.positions(), &self.normals, t, b)
    }

    fn vertices(&self) -> Vec<Vec<(Uv, P3)>> {
        let mut out = vec![Vec::new(); self.n_quads()];
        for (pi, pp) in self.params.iter().enumerate() {
            for (v, u) in pp.uv.iter().enumerate() {
                // The quad of the largest barycentric coordinate.
                let l = barycentric(TRIANGLE, *u);
                let k = (0..3).max_by(|&a, &b| l[a].total_cmp(&l[b])).unwrap_or(0);
                out[3 * pi + k].push((inverse_bilinear(kite(k), *u), pp.local.positions()[v]));
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kites_tile_the_triangle_and_invert() {
        let mut area = 0.0;
        for k in 0..3 {
            let c = kite(k);
            for i in 0..4 {
                let (a, b) = (c[i], c[(i + 1) % 4]);
                area += 0.5 * (a[0] * b[1] - b[0] * a[1]);
            }
            for st in [[0.2, 0.7], [0.9, 0.1], [0.5, 0.5]] {
                let back = inverse_bilinear(c, bilinear(c, st));
                assert!((back[0] - st[0]).abs() < 1e-12 && (back[1] - st[1]).abs() < 1e-12);
            }
        }
        assert!((area - 0.25 * 3f64.sqrt()).abs() < 1e-12, "the three kites cover the triangle once");
    }
}
