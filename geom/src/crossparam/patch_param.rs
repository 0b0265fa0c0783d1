//! Each patch of a refined mesh onto the canonical triangle: corners at the patch's anchors,
//! sides by arc length along the layout paths, interior by mean-value coordinates (Floater
//! 2003), which embed a disk bijectively for any convex boundary. The corner order is the
//! walk's, so every mesh places the same anchor at the same corner and the same path on the
//! same side.

use super::TRIANGLE;
use crate::domain::Patch;
use crate::domain::refine::Refined;
use crate::error::{Error, Result};
use crate::linalg::{FixedBoundarySystem, Weights, directed_weights};
use crate::mesh::{FaceId, Mesh, VertexId};
use crate::param::{
    BoundaryShape, StretchOptions, Uv, check_injective, disk_boundary, map_boundary_to_polygon, minimize_stretch,
};
use crate::planar::locate::Grid;
use crate::progress::Progress;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

/// Options for [`parameterize_patches`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PatchParamOptions {
    pub weights: Weights,
    /// Stretch-minimizing reweighting rounds after the first embedding (Yoshizawa et al.;
    /// 0 keeps the plain mean-value map). Lower stretch on both meshes makes corresponding
    /// patches agree where a mean-value map squeezes protrusions.
    pub stretch_iterations: usize,
}

impl Default for PatchParamOptions {
    fn default() -> Self {
        Self { weights: Weights::MeanValue, stretch_iterations: 3 }
    }
}

/// One patch flattened onto the canonical triangle.
pub struct PatchParam {
    /// The patch as a mesh of its own.
    pub local: Mesh,
    /// Local vertex -> refined vertex.
    pub global_v: Vec<VertexId>,
    /// Local face -> refined face.
    pub global_f: Vec<FaceId>,
    /// Local vertex -> triangle coordinates.
    pub uv: Vec<Uv>,
    /// Local boundary vertices (fixed in the solve).
    pub boundary: Vec<VertexId>,
    pub tris: Vec<[u32; 3]>,
    pub grid: Grid,
    pub residual: f64,
}

impl PatchParam {
    /// The refined face and its barycentric coordinates at triangle point `p`.
    pub fn locate(&self, p: Uv) -> (FaceId, [f64; 3]) {
        let (f, b) = self.grid.locate(&self.uv, &self.tris, p);
        (self.global_f[f as usize], b)
    }
}

/// Where given vertices of a refined mesh lie along their layout path, instead of by arc
/// length: per refined vertex, the anchor its fraction counts from and the fraction (0 at that
/// anchor, 1 at the path's other end). Open meshes' loop sides on the target use it
/// ([`crate::pipeline::layout::open_loops`]): aligned with the source's, not by arc length.
pub type SideFractions = Vec<Option<(u32, f64)>>;

/// Flattens every patch of `r` (the faces labelled with it) onto [`TRIANGLE`].
///
/// # Errors
/// `Error::Numerical` when a patch is not a disk with its three corners on the boundary, or
/// its embedding folds.
pub fn parameterize_patches(
    r: &Refined,
    patches: &[Patch],
    anchors: &[VertexId],
    opts: &PatchParamOptions,
    progress: &mut dyn Progress,
) -> Result<Vec<PatchParam>> {
    parameterize_patches_with(r, patches, anchors, opts, None, progress)
}

/// [`parameterize_patches`] with the side vertices in `sides` placed at their given fractions.
///
/// # Errors
/// As [`parameterize_patches`].
pub fn parameterize_patches_with(
    r: &Refined,
    patches: &[Patch],
    anchors: &[VertexId],
    opts: &PatchParamOptions,
    sides: Option<&SideFractions>,
    progress: &mut dyn Progress,
) -> Result<Vec<PatchParam>> {
    let mut faces_of: Vec<Vec<usize>> = vec![Vec::new(); patches.len()];
    for (f, &p) in r.patch.iter().enumerate() {
        faces_of[p as usize].push(f);
    }
    progress.check()?;
    progress.report(crate::progress::Stage::Parameterize, 0.0);
    // Patches are independent: flatten them in parallel, one vertex-renumbering scratch per
    // worker thread.
    let out = patches
        .par_iter()
        .zip(faces_of.par_iter())
        .enumerate()
        .map_init(
            || vec![u32::MAX; r.mesh.n_vertices()],
            |local_of, (pi, (patch, faces))| {
                let ctx = PatchCtx { r, anchors, opts, sides };
                ctx.flatten(pi, patch, faces, local_of)
            },
        )
        .collect::<Result<Vec<_>>>()?;
    progress.report(crate::progress::Stage::Parameterize, 1.0);
    Ok(out)
}

/// What every patch's flattening reads.
struct PatchCtx<'a> {
    r: &'a Refined,
    anchors: &'a [VertexId],
    opts: &'a PatchParamOptions,
    sides: Option<&'a SideFractions>,
}

impl PatchCtx<'_> {
    /// Flattens patch `pi` (its `faces` of `r`) onto [`TRIANGLE`]; `local_of` is all `u32::MAX`
    /// on entry and on return.
    fn flatten(&self, pi: usize, patch: &Patch, faces: &[usize], local_of: &mut [u32]) -> Result<PatchParam> {
        let PatchCtx { r, anchors, opts, .. } = *self;
        let mut global_v = Vec::new();
        let mut tris = Vec::with_capacity(faces.len());
        for &f in faces {
            let t = r.mesh.face(FaceId::from_idx(f)).map(|v| {
                if local_of[v.idx()] == u32::MAX {
                    local_of[v.idx()] = global_v.len() as u32;
                    global_v.push(v);
                }
                local_of[v.idx()]
            });
            tris.push(t);
        }
        for v in &global_v {
            local_of[v.idx()] = u32::MAX;
        }
        let positions = global_v.iter().map(|&v| r.mesh.position(v)).collect();
        let local = Mesh::from_triangles(positions, &tris)
            .map_err(|e| Error::Numerical(format!("patch {pi} is not a valid mesh: {e}")))?;
        let mut lp = disk_boundary(&local).map_err(|e| Error::Numerical(format!("patch {pi}: {e}")))?;
        let corner_local = |a: u32| {
            let v = anchors[a as usize];
            global_v.iter().position(|&g| g == v).map(VertexId::from_idx)
        };
        let c = patch.corners.map(corner_local);
        let [Some(c0), Some(c1), Some(c2)] = c else {
            return Err(Error::Numerical(format!("patch {pi} does not contain its corners")));
        };
        let Some(s) = lp.iter().position(|&v| v == c0) else {
            return Err(Error::Numerical(format!("corner of patch {pi} is not on its boundary")));
        };
        lp.rotate_left(s);
        let p2 = lp.iter().position(|&v| v == c2);
        let p1 = lp.iter().position(|&v| v == c1);
        let (Some(p2), Some(p1)) = (p2, p1) else {
            return Err(Error::Numerical(format!("corner of patch {pi} is not on its boundary")));
        };
        if !(0 < p2 && p2 < p1) {
            return Err(Error::Numerical(format!("patch {pi} has its corners in the wrong order")));
        }
        let shape = BoundaryShape::Polygon { vertices: TRIANGLE.to_vec(), corners: Some(vec![0, p2, p1]) };
        let mut buv = map_boundary_to_polygon(&local, &lp, &shape)?;
        if let Some(sides) = self.sides {
            // Triangle corner j sits at loop position `at[j]` and is anchor `corner[j]`.
            let at = [0, p2, p1, lp.len()];
            let corner = [patch.corners[0], patch.corners[2], patch.corners[1], patch.corners[0]];
            for j in 0..3 {
                let (x, y) = (TRIANGLE[j], TRIANGLE[(j + 1) % 3]);
                for i in at[j] + 1..at[j + 1] {
                    if let Some((from, g)) = sides[global_v[lp[i].idx()].idx()] {
                        let t = if from == corner[j] { g } else { 1.0 - g };
                        buv[i] = [x[0] + t * (y[0] - x[0]), x[1] + t * (y[1] - x[1])];
                    }
                }
            }
        }
        let mut fixed = vec![[f64::NAN; 2]; local.n_vertices()];
        for (v, p) in lp.iter().zip(&buv) {
            fixed[v.idx()] = *p;
        }
        let (uv, residual) = if lp.len() == local.n_vertices() {
            (fixed.clone(), 0.0)
        } else {
            let mut sys = FixedBoundarySystem::new(&local, &lp)?;
            if opts.weights.is_symmetric() {
                sys.prepare_cholesky()?;
            } else {
                sys.prepare_lu()?;
            }
            let w = directed_weights(&local, opts.weights);
            let fac = sys.factor_weights(&w, opts.weights.is_symmetric())?;
            let (uv, residual) = fac.solve_with_residual::<2>(&|v| fixed[v.idx()])?;
            if opts.stretch_iterations > 0 && !opts.weights.is_symmetric() {
                let so = StretchOptions { iterations: opts.stretch_iterations, ..Default::default() };
                let r = minimize_stretch(&local, &sys, &w, uv, &|v| fixed[v.idx()], &so)?;
                let res = if r.rounds > 0 { r.residual } else { residual };
                (r.uv, res)
            } else {
                (uv, residual)
            }
        };
        let inj = check_injective(&local, &uv);
        if inj.flipped > 0 {
            if tracing::enabled!(tracing::Level::DEBUG) {
                let on_b: std::collections::HashSet<VertexId> = lp.iter().copied().collect();
                for t in &tris {
                    let p = t.map(|v| uv[v as usize]);
                    let o = (p[1][0] - p[0][0]) * (p[2][1] - p[0][1]) - (p[1][1] - p[0][1]) * (p[2][0] - p[0][0]);
                    if o < 0.0 {
                        let b = t.map(|v| on_b.contains(&VertexId(v)));
                        tracing::debug!("patch {pi} flipped {t:?} boundary {b:?} uv {p:?} area2 {o:e}");
                    }
                }
            }
            return Err(Error::Numerical(format!(
                "patch {pi} (anchors {:?}) folds: {} flipped triangles",
                patch.corners, inj.flipped
            )));
        }
        let grid = Grid::new(&uv, &tris);
        let global_f = faces.iter().map(|&f| FaceId::from_idx(f)).collect();
        Ok(PatchParam { local, global_v, global_f, uv, boundary: lp, tris, grid, residual })
    }
}
