//! Parameterization of one quad patch over the unit square (Yu & Chuang, section 3.3):
//! a progressive mesh by quadric-error half-edge collapses (boundary vertices, corners and
//! feature points never collapse, and no collapse may create a chord, so no base triangle lies
//! flat along a side of the square), a mean-value embedding of the base mesh (Floater 2003) with
//! the boundary fixed by arc length, stretch optimization of the base, then the vertex splits
//! replayed coarse to fine: each new vertex goes to the centroid of its star's kernel (so the
//! map stays an embedding) and is optimized locally with its neighbours; a global sweep follows
//! every doubling of the vertex count, and a last one at full resolution.

use super::kernel::kernel_centroid;
use super::partition::PatchMesh;
use super::stretch::{ParamState, StretchOptOptions, mesh_stretch};
use crate::error::{Error, Result};
use crate::linalg::{FixedBoundarySystem, Weights};
use crate::mesh::VertexId;
use crate::param::Uv;
use crate::progress::Progress;
use crate::simplify::{CollapseHistory, DecimateOptions, decimate};

/// Options of [`base_embedding`] and [`coarse_to_fine`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadParamOptions {
    /// Interior vertices the base mesh keeps (besides feature points).
    pub base_interior: usize,
    pub stretch: StretchOptOptions,
    /// A global optimization sweep runs each time the vertex count grows by this factor.
    pub global_growth: f64,
    pub seed: u64,
}

impl Default for QuadParamOptions {
    fn default() -> Self {
        Self { base_interior: 32, stretch: StretchOptOptions::default(), global_growth: 2.0, seed: 0x5eed }
    }
}

/// The optimized embedding of a patch's base mesh, ready for feature alignment and refinement.
pub struct BaseEmbedding {
    pub state: ParamState,
    history: CollapseHistory,
    from_to: Vec<(u32, u32)>,
    /// Vertices of the base mesh (patch-local ids).
    pub base_vertices: Vec<VertexId>,
    /// Normalized (L2, L∞) stretch of the base after the mean-value embedding and after
    /// optimization.
    pub stretch_mv: (f64, f64),
    pub stretch_opt: (f64, f64),
}

/// Output of [`coarse_to_fine`].
#[derive(Debug, Clone)]
pub struct PatchParamResult {
    /// Unit-square position of every patch vertex.
    pub uv: Vec<Uv>,
    /// The mean-value map of the whole patch (the reference the stretch is compared with).
    pub uv_mv: Vec<Uv>,
    pub base_vertices: usize,
    /// Stretch of the base (mean value, optimized) and of the full patch: the mean-value map of
    /// the full patch (the reference) and the final map.
    pub base_stretch_mv: (f64, f64),
    pub base_stretch_opt: (f64, f64),
    pub stretch_mv: (f64, f64),
    pub stretch_final: (f64, f64),
    /// Triangles with non-positive parameter area (0 by construction).
    pub flipped: usize,
}

/// Mean-value embedding of `mesh`'s faces (a sub-soup of `faces`) with fixed boundary values.
fn mean_value(patch: &PatchMesh, sub: &crate::mesh::Mesh, kept: &[VertexId]) -> Result<Vec<Uv>> {
    let fixed: Vec<VertexId> = (0..sub.n_vertices())
        .map(VertexId::from_idx)
        .filter(|v| patch.boundary_uv[kept[v.idx()].idx()].is_some())
        .collect();
    let value = |v: VertexId| patch.boundary_uv[kept[v.idx()].idx()].unwrap_or([0.5, 0.5]);
    if fixed.len() == sub.n_vertices() {
        return Ok((0..sub.n_vertices()).map(|v| value(VertexId::from_idx(v))).collect());
    }
    let mut sys = FixedBoundarySystem::new(sub, &fixed)?;
    let factor = sys.factor(sub, Weights::MeanValue)?;
    let (uv, residual) = factor.solve_with_residual::<2>(&|v| value(v))?;
    if residual.is_nan() || residual >= 1e-8 {
        return Err(Error::Numerical(format!("mean-value embedding residual {residual:.2e}")));
    }
    Ok(uv)
}

/// Builds the progressive mesh of a patch and the optimized embedding of its base.
///
/// # Errors
/// `Numerical` when the mean-value solve fails; `Internal` when the embedding folds (a bug).
pub fn base_embedding(patch: &PatchMesh, opts: &QuadParamOptions) -> Result<BaseEmbedding> {
    let n = patch.mesh.n_vertices();
    let mut protected: Vec<VertexId> =
        (0..n).map(VertexId::from_idx).filter(|v| patch.boundary_uv[v.idx()].is_some()).collect();
    let n_boundary = protected.len();
    protected.extend(patch.features.iter().map(|&(_, v)| v));
    let target = n_boundary + patch.features.len() + opts.base_interior;
    let dec = decimate(
        &patch.mesh,
        &DecimateOptions { target_vertices: target, protected, no_chords: true, ..Default::default() },
    )?;
    let base_uv = mean_value(patch, &dec.mesh, &dec.kept)?;
    let mut uv = vec![[f64::NAN; 2]; n];
    for (i, v) in dec.kept.iter().enumerate() {
        uv[v.idx()] = base_uv[i];
    }
    let fixed: Vec<bool> = (0..n).map(|v| patch.boundary_uv[v].is_some()).collect();
    let history = dec.history;
    let state = ParamState::new(
        patch.mesh.positions().to_vec(),
        uv,
        history.faces.clone(),
        history.alive.clone(),
        fixed,
        opts.seed,
    );
    if state.flipped() > 0 {
        return Err(Error::Internal("mean-value embedding of the base mesh folds".into()));
    }
    let stretch_mv = mesh_stretch(&state.pos, &state.uv, state.live_faces());
    let mut base = BaseEmbedding {
        state,
        from_to: dec.collapses.iter().map(|c| (c.from.0, c.to.0)).collect(),
        history,
        base_vertices: dec.kept.clone(),
        stretch_mv,
        stretch_opt: stretch_mv,
    };
    let verts: Vec<u32> = dec.kept.iter().map(|v| v.0).collect();
    base.state.optimize(&verts, &opts.stretch);
    base.stretch_opt = mesh_stretch(&base.state.pos, &base.state.uv, base.state.live_faces());
    Ok(base)
}

/// Replays the vertex splits of the progressive mesh, coarse to fine, with kernel-centroid
/// insertion and local stretch optimization; `frozen` vertices (aligned features) never move.
///
/// # Errors
/// `Numerical` if a star has an empty kernel (cannot happen for an embedding) or the result
/// folds; `Cancelled`.
pub fn coarse_to_fine(
    patch: &PatchMesh,
    mut base: BaseEmbedding,
    frozen: &[VertexId],
    opts: &QuadParamOptions,
    progress: &mut dyn Progress,
) -> Result<PatchParamResult> {
    let st = &mut base.state;
    for v in frozen {
        st.fixed[v.idx()] = true;
    }
    let mut n_active = base.base_vertices.len();
    let mut next_global = (n_active as f64 * opts.global_growth).ceil() as usize;
    let mut ring = Vec::new();
    for i in (0..base.from_to.len()).rev() {
        let (u, v) = base.from_to[i];
        if i % 512 == 0 {
            progress.check()?;
            progress.report(crate::progress::Stage::Parameterize, 1.0 - i as f64 / base.from_to.len().max(1) as f64);
        }
        for &f in &base.history.rewritten[i] {
            for w in st.faces[f as usize].iter_mut() {
                if *w == v {
                    *w = u;
                }
            }
            st.vf[v as usize].retain(|&g| g != f);
            st.vf[u as usize].push(f);
        }
        for &f in &base.history.deleted[i] {
            st.alive[f as usize] = true;
            for w in st.faces[f as usize] {
                st.vf[w as usize].push(f);
            }
        }
        st.active[u as usize] = true;
        n_active += 1;
        ring.clear();
        for w in st.link(u).flatten() {
            if !ring.contains(&w) {
                ring.push(w);
            }
        }
        let c = kernel_centroid(&st.link_uv(u))
            .ok_or_else(|| Error::Numerical(format!("vertex split {i}: the star of vertex {u} has an empty kernel")))?;
        st.uv[u as usize] = c;
        st.optimize_vertex(u, opts.stretch.directions);
        for &w in &ring {
            st.optimize_vertex(w, opts.stretch.directions);
        }
        if n_active >= next_global {
            let verts: Vec<u32> = (0..st.pos.len() as u32).filter(|&w| st.active[w as usize]).collect();
            let few = StretchOptOptions { max_sweeps: 2, ..opts.stretch };
            st.optimize(&verts, &few);
            next_global = (n_active as f64 * opts.global_growth).ceil() as usize;
        }
    }
    let all: Vec<u32> = (0..st.pos.len() as u32).collect();
    st.optimize(&all, &opts.stretch);
    let flipped = st.flipped();
    if flipped > 0 {
        return Err(Error::Numerical(format!("patch parameterization folds {flipped} triangles")));
    }
    let stretch_final = mesh_stretch(&st.pos, &st.uv, st.live_faces());
    let kept: Vec<VertexId> = (0..patch.mesh.n_vertices()).map(VertexId::from_idx).collect();
    let mv = mean_value(patch, &patch.mesh, &kept)?;
    let tris = patch.mesh.face_indices();
    let stretch_mv = mesh_stretch(&st.pos, &mv, tris.iter().copied());
    Ok(PatchParamResult {
        uv: std::mem::take(&mut st.uv),
        uv_mv: mv,
        base_vertices: base.base_vertices.len(),
        base_stretch_mv: base.stretch_mv,
        base_stretch_opt: base.stretch_opt,
        stretch_mv,
        stretch_final,
        flipped,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{P3, shapes};
    use crate::progress::NoProgress;

    /// A bumpy square as a patch, its boundary fixed where it lies.
    fn bumpy_patch(n: usize, feature: Option<usize>) -> PatchMesh {
        let g = shapes::grid(n);
        let pos: Vec<P3> = g
            .positions()
            .iter()
            .map(|p| P3::new(p.x, p.y, 0.6 * (-((p.x - 0.3).powi(2) + (p.y - 0.6).powi(2)) * 30.0).exp()))
            .collect();
        let mesh = g.with_positions(pos).unwrap();
        let boundary_uv = (0..mesh.n_vertices())
            .map(|v| {
                let p = g.positions()[v];
                mesh.is_boundary_vertex(VertexId::from_idx(v)).then_some([p.x, p.y])
            })
            .collect();
        let id = |i: usize, j: usize| VertexId::from_idx(j * (n + 1) + i);
        PatchMesh {
            parent: (0..mesh.n_vertices()).map(VertexId::from_idx).collect(),
            mesh,
            boundary_uv,
            corners: [id(0, 0), id(n, 0), id(n, n), id(0, n)],
            features: feature.map(|f| vec![(0, VertexId::from_idx(f))]).unwrap_or_default(),
        }
    }

    #[test]
    fn coarse_to_fine_lowers_stretch_without_folds() {
        let p = bumpy_patch(24, None);
        let opts = QuadParamOptions::default();
        let base = base_embedding(&p, &opts).unwrap();
        assert!(base.base_vertices.len() < p.mesh.n_vertices() / 4, "a coarse base mesh");
        assert!(base.stretch_opt.0 <= base.stretch_mv.0, "{:?} {:?}", base.stretch_opt, base.stretch_mv);
        let r = coarse_to_fine(&p, base, &[], &opts, &mut NoProgress).unwrap();
        assert_eq!(r.flipped, 0);
        assert!(r.stretch_final.0 < r.stretch_mv.0, "{:?} vs {:?}", r.stretch_final, r.stretch_mv);
        for (v, b) in p.boundary_uv.iter().enumerate() {
            if let Some(b) = b {
                assert_eq!(r.uv[v], *b, "boundary stays fixed");
            }
        }
    }

    #[test]
    fn an_aligned_feature_lands_exactly_and_nothing_folds() {
        let f = 13 * 25 + 11;
        let p = bumpy_patch(24, Some(f));
        let opts = QuadParamOptions::default();
        let mut base = base_embedding(&p, &opts).unwrap();
        let target = [0.62, 0.41];
        let w =
            super::super::warp::align_features(&mut base.state, p.corners.map(|c| c.0), &[(f as u32, target)]).unwrap();
        assert!(w.events >= 1);
        assert_eq!(base.state.flipped(), 0);
        let r = coarse_to_fine(&p, base, &[VertexId::from_idx(f)], &opts, &mut NoProgress).unwrap();
        assert_eq!(r.uv[f], target);
        assert_eq!(r.flipped, 0);
    }
}
