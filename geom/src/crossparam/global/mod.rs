//! A global map of a closed mesh onto the common base domain, with only the anchors fixed
//! (globally smooth parameterization, Khodakovsky, Litke & Schröder 2003; the coarse-to-fine
//! cross-parameterization of Schreiner et al. 2004 relaxes patch boundaries the same way).
//!
//! The per-patch maps of [`super::patch_param`] hold every vertex of a layout path on its
//! patch side, so the two meshes' maps meet only where the two meshes' paths happen to lie;
//! where a target path runs off the true image of its source path (a tail, a finger: up to
//! 12% of √area on cat poses) the composition squeezes one side and stretches the other.
//! Here the paths only seed the solve: each vertex is the mean of its neighbours (mean-value
//! weights, symmetrized, Floater 2003) across patch sides through the *links* between
//! neighbours' charts ([`charts`], [`links`]); after the solve, vertices that left their patch
//! are moved to the patch they entered ([`charts::Charts::settle`]). Both meshes then depend on
//! the layout's combinatorics and its anchors alone, not on where its paths were traced.
//! [`compose`] carries one mesh to the other through both maps ([`locate`]).

pub mod charts;
pub mod domain_map;
pub mod links;
pub mod locate;
pub mod solve;

use crate::domain::Patch;
use crate::error::{Error, Result};
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, VertexId};
use crate::param::{Uv, stretch_jacobian};
use charts::Charts;
use serde::{Deserialize, Serialize};
use solve::{Rows, State, face_uv};

/// Options for [`global_param`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GlobalParamOptions {
    /// Use the global map (closed meshes); `false` keeps the per-patch maps.
    pub enabled: bool,
    /// Solves at most. Vertices that leave their patch are moved to the patch they entered
    /// and their links carried along, which leaves the system the same, so one solve is
    /// enough; more re-solve in the new charts (a check: the answer does not change).
    pub max_solves: usize,
    /// The patch triangles' shapes.
    pub metric: DomainMetric,
    /// Use the global maps whatever their energy (tests that check the global maps alone).
    pub force: bool,
    /// The per-patch composition is kept without trying the global maps when at most this
    /// fraction of both meshes' faces are folded in it and its area ratios are off by at most
    /// `min_area_deviation` (both directions summed).
    pub min_folded_fraction: f64,
    pub min_area_deviation: f64,
}

/// How the base domain's patch triangles are shaped ([`charts`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DomainMetric {
    /// Every patch equilateral.
    Equilateral,
    /// Sides as long as the layout paths (mean over both meshes, each scaled by √area).
    PathLengths,
}

impl Default for GlobalParamOptions {
    fn default() -> Self {
        Self {
            enabled: true,
            force: false,
            min_folded_fraction: 5e-4,
            min_area_deviation: 0.03,
            max_solves: 1,
            metric: DomainMetric::PathLengths,
        }
    }
}

/// A mesh mapped onto the base domain.
pub struct GlobalParam {
    pub charts: Charts,
    pub state: State,
    pub locators: Vec<locate::PatchLocator>,
    /// Triangles with non-positive area in their first vertex's chart.
    pub flipped: usize,
    /// L2 stretch of the map.
    pub l2: f64,
    /// Relative residual `‖Ax − b‖ / ‖b‖` of the last solve.
    pub residual: f64,
}

/// Maps `mesh` (closed) onto the base domain of `patches`, anchors (`anchors[k]` is anchor
/// `k`) fixed at their corners, starting from `init` (per vertex: patch and position in
/// [`super::TRIANGLE`], e.g. from the per-patch maps); `lengths` per layout path set the
/// patches' shapes (see [`Charts::new`]); `refined`, the mesh cut along the layout, gives the
/// links (see [`links`]).
///
/// # Errors
/// `Numerical` when the domain has no cone metric (see [`Charts::new`]) or a solve fails.
#[allow(clippy::too_many_arguments)]
pub fn global_param(
    mesh: &Mesh,
    patches: &[Patch],
    anchors: &[VertexId],
    init: &[(u32, Uv)],
    refined: Option<&crate::domain::refine::Refined>,
    lengths: Option<&[f64]>,
    opts: &GlobalParamOptions,
    progress: &mut dyn crate::progress::Progress,
) -> Result<GlobalParam> {
    let seed = seed(mesh, patches, anchors, init, refined, lengths)?;
    let Seed { charts, mut state, fixed, rows } = seed;
    let st = &mut state;
    let mut system = solve::System::new(&fixed);
    let residual = relax(&charts, &mut system, st, &fixed, &rows, opts.max_solves)?;
    progress.check()?;
    let l2 = vertex_stretch(mesh, st, &rows, &fixed);
    let flipped = flipped(mesh, st, &rows, &fixed);
    tracing::debug!("global: harmonic map: folds {flipped} l2 {l2} residual {residual:.2e}");
    let locators = locate::locators(mesh, &charts, st, &rows, &fixed);
    Ok(GlobalParam { charts, state, locators, flipped, l2, residual })
}

/// A mesh placed on the base domain before any solve: the charts, every vertex's patch and
/// chart position (anchors at their corners), the links between neighbours' charts, the
/// anchors as fixed vertices and the mesh's mean-value rows.
pub struct Seed {
    pub charts: Charts,
    pub state: State,
    pub fixed: Vec<bool>,
    pub rows: Rows,
}

/// [`Seed`] of `mesh` from `init` (per vertex: patch and position in [`super::TRIANGLE`]); as
/// [`global_param`] before it solves.
///
/// # Errors
/// As [`global_param`].
pub fn seed(
    mesh: &Mesh,
    patches: &[Patch],
    anchors: &[VertexId],
    init: &[(u32, Uv)],
    refined: Option<&crate::domain::refine::Refined>,
    lengths: Option<&[f64]>,
) -> Result<Seed> {
    let charts = Charts::new(patches, anchors.len(), lengths)?;
    let n = mesh.n_vertices();
    if init.len() != n || init.iter().any(|(p, _)| *p as usize >= patches.len()) {
        return Err(Error::Internal("global map: a vertex without a patch".into()));
    }
    let mut st = State {
        patch: init.iter().map(|x| x.0).collect(),
        uv: init.iter().map(|&(p, x)| charts.from_canonical(p).apply(x)).collect(),
        anchor: vec![u32::MAX; n],
        link: Vec::new(),
    };
    let mut fixed = vec![false; n];
    for (k, a) in anchors.iter().enumerate() {
        let Some((p, c)) = charts.anchor_home[k] else {
            return Err(Error::Numerical(format!("anchor {k} is no patch's corner")));
        };
        fixed[a.idx()] = true;
        st.anchor[a.idx()] = k as u32;
        st.patch[a.idx()] = p;
        st.uv[a.idx()] = charts.corner[p as usize][c];
    }
    let rows = Rows::mean_value(mesh);
    // Links from the refinement; by distance only where it cannot tell.
    if let Some(r) = refined {
        st.link = links::from_refinement(mesh, r, patches, &charts, &st, &rows);
    }
    st.fill_links(&charts, &rows);
    Ok(Seed { charts, state: st, fixed, rows })
}

/// Solves, moves vertices into the patches they entered and carries their links along, until
/// none moves or after `max_solves` solves. Returns the last residual.
fn relax(
    charts: &Charts,
    system: &mut solve::System,
    st: &mut State,
    fixed: &[bool],
    rows: &Rows,
    max_solves: usize,
) -> Result<f64> {
    let mut residual = 0.0;
    let mut moved_by = vec![None; st.uv.len()];
    for _ in 0..max_solves.max(1) {
        let (uv, res) = system.solve(st, fixed, rows)?;
        residual = res;
        let mut moved = 0;
        for v in 0..uv.len() {
            moved_by[v] = None;
            if fixed[v] {
                continue;
            }
            let (p, x, m) = charts.settle(st.patch[v], st.uv[v], uv[v]);
            if p != st.patch[v] {
                moved += 1;
                moved_by[v] = Some(m);
            }
            st.patch[v] = p;
            st.uv[v] = x;
        }
        if moved == 0 {
            break;
        }
        st.carry_links(rows, &moved_by);
    }
    Ok(residual)
}

/// Area-weighted L2 stretch (uv scaled to the surface's area); a face without a chart
/// position or uv area counts as infinitely stretched.
fn vertex_stretch(mesh: &Mesh, st: &State, rows: &Rows, fixed: &[bool]) -> f64 {
    let (mut tn, mut td, mut uv_area) = (0.0, 0.0, 0.0);
    for f in 0..mesh.n_faces() {
        let f = FaceId::from_idx(f);
        let area = mesh.face_area(f);
        let s2 = face_uv(mesh, st, rows, fixed, f).and_then(|q| {
            let (ss, stv, a2) = stretch_jacobian(mesh.face_points(f), q)?;
            uv_area += 0.5 * a2.abs();
            Some(0.5 * (ss.norm_squared() + stv.norm_squared()))
        });
        tn += area * s2.unwrap_or(f64::INFINITY);
        td += area;
    }
    // Scaling uv by k scales the squared stretch by 1 / k²: normalise to equal total areas.
    (tn * uv_area / td.max(f64::MIN_POSITIVE) / td.max(f64::MIN_POSITIVE)).sqrt()
}

pub(crate) fn flipped(mesh: &Mesh, st: &State, rows: &Rows, fixed: &[bool]) -> usize {
    (0..mesh.n_faces())
        .filter(|&f| match face_uv(mesh, st, rows, fixed, FaceId::from_idx(f)) {
            Some(q) => (q[1][0] - q[0][0]) * (q[2][1] - q[0][1]) - (q[2][0] - q[0][0]) * (q[1][1] - q[0][1]) <= 0.0,
            None => true,
        })
        .count()
}

/// The map from A's vertices to B's surface through both global maps: each vertex of A is
/// located at its own chart position in B's locator of the same patch. Anchors go exactly to
/// their partners.
///
/// # Errors
/// `Numerical` when a patch of B holds no triangle.
pub fn compose(
    a: &GlobalParam,
    b: &GlobalParam,
    mesh_b: &Mesh,
    anchors: &[(VertexId, VertexId)],
) -> Result<SurfaceMap> {
    map_through(&a.state, &b.locators, mesh_b, anchors)
}

/// The map from the vertices placed by `st` to B's surface: each located at its chart position
/// in B's `locators` of the same patch; anchors go exactly to their partners.
///
/// # Errors
/// `Numerical` when a patch of B holds no triangle.
pub fn map_through(
    st: &State,
    locators: &[locate::PatchLocator],
    mesh_b: &Mesh,
    anchors: &[(VertexId, VertexId)],
) -> Result<SurfaceMap> {
    let n = st.uv.len();
    let mut face = Vec::with_capacity(n);
    let mut bary = Vec::with_capacity(n);
    for v in 0..n {
        let p = st.patch[v];
        let Some((f, w)) = locators[p as usize].locate(st.uv[v]) else {
            return Err(Error::Numerical(format!("patch {p} holds no triangle of the global map")));
        };
        face.push(f);
        bary.push(w);
    }
    let mut map = SurfaceMap { face, bary };
    super::compose::place_anchors(&mut map, mesh_b, anchors);
    Ok(map)
}
