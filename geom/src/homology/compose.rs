//! Composing two planar domains into a surface map (Carner et al. eq. 2), shared by the 4g-gon
//! maps and the feature maps: every vertex of one mesh is located in the other's planar disk,
//! and the anchor warp that holds interior anchors on their partners.

use crate::error::Result;
use crate::map::SurfaceMap;
use crate::mesh::cut::CutMesh;
use crate::mesh::refine::Refined;
use crate::mesh::{FaceId, VertexId};
use crate::param::Uv;
use crate::planar::locate::Grid;

/// A cut disk with its planar positions and, when the disk was cut from a refinement, the
/// refinement (to convert points back to the original mesh).
#[derive(Debug, Clone, Copy)]
pub struct Planar<'a> {
    pub disk: &'a CutMesh,
    pub uv: &'a [Uv],
    pub refined: Option<&'a Refined>,
}

/// Every original vertex of the `n` vertices of `from`'s mesh (through the first of its disk
/// copies) located in `to`'s domain after `tau`.
pub fn locate_all(n: usize, from: &Planar, to: &Planar, tau: &dyn Fn(Uv) -> Uv) -> SurfaceMap {
    locate_all_by(n, from, to, tau, &|grid, tris, p| grid.locate(to.uv, tris, p))
}

/// A point location in a disk: `(grid, triangles, point)` to a triangle and barycentric
/// coordinates.
pub type Locator<'a> = dyn Fn(&Grid, &[[u32; 3]], Uv) -> (u32, [f64; 3]) + 'a;

/// [`locate_all`] with the point location given: `find(grid, triangles, point)` returns the
/// triangle of `to`'s disk and the barycentric coordinates there.
pub fn locate_all_by(n: usize, from: &Planar, to: &Planar, tau: &dyn Fn(Uv) -> Uv, find: &Locator) -> SurfaceMap {
    let mut copy = vec![u32::MAX; n];
    for (d, o) in from.disk.orig.iter().enumerate() {
        if o.idx() < n && copy[o.idx()] == u32::MAX {
            copy[o.idx()] = d as u32;
        }
    }
    let tris = to.disk.mesh.face_indices();
    let grid = Grid::new(to.uv, &tris);
    let mut face = Vec::with_capacity(n);
    let mut bary = Vec::with_capacity(n);
    for &c in &copy {
        let (f, b) = find(&grid, &tris, tau(from.uv[c as usize]));
        let (of, ob) = match to.refined {
            Some(r) => r.to_original(FaceId(f), b),
            None => (FaceId(f), b),
        };
        face.push(of);
        bary.push(ob);
    }
    SurfaceMap { face, bary }
}

/// The disk copy of original vertex `v` when it has exactly one and it is interior.
fn interior_copy(d: &CutMesh, v: VertexId) -> Option<VertexId> {
    let mut it = d.orig.iter().enumerate().filter(|(_, o)| **o == v);
    let (first, _) = it.next()?;
    let dv = VertexId::from_idx(first);
    (it.next().is_none() && !d.mesh.is_boundary_vertex(dv)).then_some(dv)
}

/// Re-solves `uv` (the map of `disk`, `boundary` held where it is) with the anchors that are
/// interior on both disks held where their partners lie in `to` (mapped back by `untau`): the
/// constrained mean-value map. Kept only when it stays bijective; returns whether it was kept.
///
/// # Errors
/// When the solve fails.
pub fn warp_interior(
    disk: &CutMesh,
    uv: &mut Vec<Uv>,
    boundary: &[VertexId],
    to: &Planar,
    anchors: &[(VertexId, VertexId)],
    untau: &dyn Fn(Uv) -> Uv,
) -> Result<bool> {
    let pairs: Vec<(VertexId, VertexId)> =
        anchors.iter().filter_map(|&(a, b)| Some((interior_copy(disk, a)?, interior_copy(to.disk, b)?))).collect();
    if pairs.is_empty() {
        return Ok(false);
    }
    let mut fixed_uv = uv.clone();
    let mut fixed: Vec<VertexId> = boundary.to_vec();
    for &(a, b) in &pairs {
        fixed_uv[a.idx()] = untau(to.uv[b.idx()]);
        fixed.push(a);
    }
    let mut sys = crate::linalg::FixedBoundarySystem::new(&disk.mesh, &fixed)?;
    sys.prepare_lu()?;
    let w = crate::linalg::directed_weights(&disk.mesh, crate::linalg::Weights::MeanValue);
    let (out, _) = sys.factor_weights(&w, false)?.solve_with_residual::<2>(&|v| fixed_uv[v.idx()])?;
    if !super::domain::exact_orientation(&disk.mesh, &out).is_injective() {
        return Ok(false);
    }
    *uv = out;
    Ok(true)
}
