//! Point location in a global map: per patch, the mesh's triangles that reach into the patch's
//! canonical triangle, expressed in its chart (each vertex once, on the sheet nearest the
//! patch), indexed by [`Grid`]. A triangle may straddle patch sides, since the global map lets
//! vertices cross them.

use super::charts::Charts;
use super::solve::{Rows, State, face_uv};
use crate::mesh::{FaceId, Mesh};
use crate::param::Uv;
use crate::planar::locate::{Grid, barycentric};

/// How far outside a patch's triangle another triangle may lie and still be indexed, in
/// barycentric coordinates of the patch's triangle.
const MARGIN: f64 = 1e-3;

/// One patch's triangles in its chart.
pub struct PatchLocator {
    uv: Vec<Uv>,
    tris: Vec<[u32; 3]>,
    face: Vec<FaceId>,
    grid: Grid,
}

impl PatchLocator {
    /// The mesh face and barycentric coordinates (in the face's own corner order) at chart
    /// point `x`; `None` for a patch no triangle reaches.
    pub fn locate(&self, x: Uv) -> Option<(FaceId, [f64; 3])> {
        if self.tris.is_empty() {
            return None;
        }
        let (t, b) = self.grid.locate(&self.uv, &self.tris, x);
        Some((self.face[t as usize], b))
    }

    /// [`PatchLocator::locate`] with the face's corners in this chart.
    pub fn locate_triangle(&self, x: Uv) -> Option<(FaceId, [Uv; 3])> {
        if self.tris.is_empty() {
            return None;
        }
        let (t, _) = self.grid.locate(&self.uv, &self.tris, x);
        Some((self.face[t as usize], self.tris[t as usize].map(|v| self.uv[v as usize])))
    }
}

/// Builds every patch's locator for `mesh` mapped by `st`. Triangles folded in a chart are
/// left out (a query there lands on the nearest unfolded one).
pub fn locators(mesh: &Mesh, charts: &Charts, st: &State, rows: &Rows, fixed: &[bool]) -> Vec<PatchLocator> {
    let np = charts.across.len();
    let mut faces_of: Vec<Vec<u32>> = vec![Vec::new(); np];
    let mut cand = Vec::with_capacity(12);
    for (f, tri) in mesh.faces().iter().enumerate() {
        cand.clear();
        for v in tri {
            let p = st.patch[v.idx()];
            cand.push(p);
            cand.extend(charts.across[p as usize].iter().map(|s| s.0));
        }
        cand.sort_unstable();
        cand.dedup();
        for &p in &cand {
            faces_of[p as usize].push(f as u32);
        }
    }
    faces_of
        .into_iter()
        .enumerate()
        .map(|(p, faces)| patch_locator(mesh, charts, st, rows, fixed, p as u32, &faces))
        .collect()
}

fn patch_locator(
    mesh: &Mesh,
    charts: &Charts,
    st: &State,
    rows: &Rows,
    fixed: &[bool],
    p: u32,
    faces: &[u32],
) -> PatchLocator {
    let mut local: std::collections::HashMap<u32, Vec<u32>> = std::collections::HashMap::with_capacity(faces.len());
    let mut uv: Vec<Uv> = Vec::new();
    let (mut tris, mut face) = (Vec::new(), Vec::new());
    for &f in faces {
        let f = FaceId(f);
        // The face in its reference corner's chart (links keep it whole around cone points),
        // then moved into p's chart on the sheet nearest p's triangle.
        let Some(q) = face_uv(mesh, st, rows, fixed, f) else { continue };
        let t = mesh.face(f);
        let r = (0..3).find(|&k| !fixed[t[k].idx()]).unwrap_or(0);
        let Some(a) = charts.transition_near_patch(st.patch[t[r].idx()], p, q[r]) else { continue };
        let q = q.map(|x| a.apply(x));
        let area2 = crate::planar::area2(q[0], q[1], q[2]);
        if area2 <= 0.0 || !reaches_triangle(charts, p, q) {
            continue;
        }
        // A vertex is shared by the triangles that put it at one place; near a cone point two
        // triangles can develop it on different sheets, and each keeps its own copy.
        let mut tri = [0u32; 3];
        for k in 0..3 {
            let copies: &mut Vec<u32> = local.entry(t[k].0).or_default();
            tri[k] = match copies.iter().find(|&&c| super::charts::dist2(uv[c as usize], q[k]) <= 1e-24) {
                Some(&c) => c,
                None => {
                    uv.push(q[k]);
                    copies.push((uv.len() - 1) as u32);
                    (uv.len() - 1) as u32
                }
            };
        }
        tris.push(tri);
        face.push(f);
    }
    let grid = Grid::new(&uv, &tris);
    PatchLocator { uv, tris, face, grid }
}

/// False when one side's line of patch `p`'s triangle separates it from `q` (with margin).
fn reaches_triangle(charts: &Charts, p: u32, q: [Uv; 3]) -> bool {
    if q.iter().any(|x| charts.outside(p, *x) == 0.0) {
        return true;
    }
    let b = q.map(|x| barycentric(charts.tri[p as usize], x));
    (0..3).all(|k| b.iter().any(|c| c[k] >= -MARGIN))
}
