//! Maps between two surfaces of one genus through their fundamental domains (Carner et al.
//! eq. 2): every vertex of one mesh is located, after the rotation τ, in the other's planar
//! 4g-gon, and its barycentric coordinates there become a point of the other's original mesh.
//! The homotopy class is chosen by the basis index on each mesh and by τ; the induced map on
//! H1 is reported as an integer matrix computed from intersection numbers.

use super::basis::CanonicalBasisResult;
use super::compose::{Planar, locate_all, warp_interior};
use super::flat::locate_all_periodic;
use super::sides::{SideDomain, Sides};
use crate::error::{Error, InputError, Result};
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, VertexId};
use crate::param::Uv;
use serde::{Deserialize, Serialize};

/// Options for [`homology_map`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct HomologyMapOptions {
    /// Basis index (0 = shortest) on the source and on the target.
    pub basis: [usize; 2],
    /// τ: rotate the source domain by `rotation · 2π/g` (a quarter turn per step for g = 1).
    pub rotation: usize,
    /// Subdivision rounds allowed while looking for disjoint loops.
    pub max_subdivisions: Option<usize>,
    /// Stretch-minimizing reweighting rounds of each domain map.
    pub stretch_iterations: usize,
}

/// Maps both ways and what produced them.
#[derive(Debug, Clone)]
pub struct HomologyMapResult {
    pub source_to_target: SurfaceMap,
    pub target_to_source: SurfaceMap,
    /// Induced map on H1: column `j` is the image of source loop `j` in the target basis
    /// (`a1, b1, …`).
    pub h1: Vec<Vec<i32>>,
    /// Polygon sides τ shifts by.
    pub side_shift: usize,
    /// Whether the source domain was warped to put the anchors on their partners.
    pub warped: bool,
    /// Genus 1: whether the maps went through the flat tori (else the squares).
    pub flat: bool,
    pub source: SideDomain,
    pub target: SideDomain,
}

/// Number of distinct rotations τ: `g`, or 4 quarter turns for the torus.
pub fn rotation_count(genus: usize) -> usize {
    if genus == 1 { 4 } else { genus }
}

/// Maps `source` and `target` through canonical bases at `bases = (source vertex, target vertex)`.
///
/// # Errors
/// `InvalidInput` on genus mismatch; as [`side_domain`].
pub fn homology_map(
    source: &Mesh,
    target: &Mesh,
    bases: (VertexId, VertexId),
    anchors: &[(VertexId, VertexId)],
    opts: &HomologyMapOptions,
) -> Result<HomologyMapResult> {
    let s = Sides::new(source, bases.0, opts.max_subdivisions, opts.stretch_iterations);
    let t = Sides::new(target, bases.1, opts.max_subdivisions, opts.stretch_iterations);
    class_map(&s, &t, opts.basis, opts.rotation, anchors)
}

/// [`homology_map`] of basis pair `basis` and rotation `rotation` from sides kept per job.
///
/// # Errors
/// As [`homology_map`].
pub fn class_map(
    s: &Sides<'_>,
    t: &Sides<'_>,
    basis: [usize; 2],
    rotation: usize,
    anchors: &[(VertexId, VertexId)],
) -> Result<HomologyMapResult> {
    let (a, b) = std::thread::scope(|sc| {
        let h = sc.spawn(|| t.get(basis[1], 0));
        (s.get(basis[0], 0), h.join())
    });
    let (a, b) = (a?, b.map_err(|_| crate::Error::Internal("target basis thread panicked".into()))??);
    let (a, b) = aligned((a, b), &mut |min| s.get(basis[0], min), &mut |min| t.get(basis[1], min))?;
    map_between(s.mesh(), t.mesh(), a, b, rotation, anchors, false)
}

/// Both meshes refined alike: the side found at an earlier attempt is searched again up to the
/// other's attempt (`again_s(min_attempt)`, `again_t`), so that one shape is cut by the same
/// loops on both meshes. Alignment is a preference: when the later search finds no basis (a
/// refinement can pen a corner in that a coarser mesh leaves open), the sides found stand.
///
/// # Errors
/// What the searches report, except `InvalidInput` (no basis at that attempt).
pub fn aligned(
    (mut s, mut t): (SideDomain, SideDomain),
    again_s: &mut dyn FnMut(usize) -> Result<SideDomain>,
    again_t: &mut dyn FnMut(usize) -> Result<SideDomain>,
) -> Result<(SideDomain, SideDomain)> {
    for _ in 0..3 {
        let (a, b) = (s.basis.attempt, t.basis.attempt);
        if a == b {
            break;
        }
        let again = if a < b { again_s(b) } else { again_t(a) };
        match again {
            Ok(x) if a < b => s = x,
            Ok(x) => t = x,
            Err(Error::Input(_)) => break,
            Err(e) => return Err(e),
        }
    }
    Ok((s, t))
}

/// Composes two sides' domains under rotation `rotation`; genus 1 through the flat tori unless
/// `square` (or one flat torus is missing).
///
/// # Errors
/// `InvalidInput` when the genera differ.
pub fn map_between(
    source: &Mesh,
    target: &Mesh,
    mut s: SideDomain,
    t: SideDomain,
    rotation: usize,
    anchors: &[(VertexId, VertexId)],
    square: bool,
) -> Result<HomologyMapResult> {
    let g = s.basis.genus();
    if g != t.basis.genus() {
        return Err(InputError::TopologyMismatch(format!("source genus {g}, target genus {}", t.basis.genus())).into());
    }
    let m = 4 * g;
    let shift = if g == 1 { rotation % 4 } else { 4 * (rotation % g) };
    let angle = std::f64::consts::TAU * shift as f64 / m as f64;
    let c = Composer { source, target, angle, anchors };
    let flat = if square { None } else { c.through_flat(&mut s, &t)? };
    let (composed, flat) = match flat {
        Some(f) => (f, true),
        None => (c.through_square(&mut s, &t)?, false),
    };
    let Composed { source_to_target, target_to_source, warped } = composed;
    let h1 = induced_h1(&s.basis, &t.basis, shift);
    Ok(HomologyMapResult {
        source_to_target,
        target_to_source,
        h1,
        side_shift: shift,
        warped,
        flat,
        source: s,
        target: t,
    })
}

/// Both directions of one composition, and whether the anchor warp was kept.
struct Composed {
    source_to_target: SurfaceMap,
    target_to_source: SurfaceMap,
    warped: bool,
}

fn rotated(p: Uv, a: f64) -> Uv {
    [p[0] * a.cos() - p[1] * a.sin(), p[0] * a.sin() + p[1] * a.cos()]
}

/// What both compositions share: the meshes, the source domain's turn and the anchors.
struct Composer<'a> {
    source: &'a Mesh,
    target: &'a Mesh,
    angle: f64,
    anchors: &'a [(VertexId, VertexId)],
}

impl Composer<'_> {
    /// Through the two 4g-gons, the source's turned by `angle` (its interior warped onto the
    /// anchors when that stays bijective).
    fn through_square(&self, s: &mut SideDomain, t: &SideDomain) -> Result<Composed> {
        let angle = self.angle;
        let warped = warp_interior(&s.basis.disk, &mut s.domain.uv, &s.basis.walk, &t.planar(), self.anchors, &|p| {
            rotated(p, -angle)
        })?;
        if warped {
            s.domain.injectivity = super::domain::exact_orientation(&s.basis.disk.mesh, &s.domain.uv);
        }
        let locate = |n: usize, from: &Planar, to: &Planar, a: f64| locate_all(n, from, to, &|p| rotated(p, a));
        Ok(self.both_ways((&s.planar(), &t.planar()), warped, &locate))
    }

    /// Through the two flat tori (genus 1, both bijective), the source's turned by `angle`.
    fn through_flat(&self, s: &mut SideDomain, t: &SideDomain) -> Result<Option<Composed>> {
        let (Some(sf), Some(tp)) = (s.flat.as_mut(), t.flat_planar()) else {
            return Ok(None);
        };
        let angle = self.angle;
        let warped =
            warp_interior(&s.basis.disk, &mut sf.uv, &s.basis.walk, &tp, self.anchors, &|p| rotated(p, -angle))?;
        let period = sf.period;
        let sp = Planar { disk: &s.basis.disk, uv: &sf.uv, refined: Some(&s.basis.refined) };
        let locate =
            |n: usize, from: &Planar, to: &Planar, a: f64| locate_all_periodic(n, from, to, period, &|p| rotated(p, a));
        Ok(Some(self.both_ways((&sp, &tp), warped, &locate)))
    }

    /// Both directions located by `locate(vertices, from, to, angle)`.
    fn both_ways(
        &self,
        (sp, tp): (&Planar, &Planar),
        warped: bool,
        locate: &dyn Fn(usize, &Planar, &Planar, f64) -> SurfaceMap,
    ) -> Composed {
        Composed {
            source_to_target: locate(self.source.n_vertices(), sp, tp, self.angle),
            target_to_source: locate(self.target.n_vertices(), tp, sp, -self.angle),
            warped,
        }
    }
}

/// The evaluator's L2 stretch of `map`'s chords (infinite for a map that cannot be embedded).
///
/// # Errors
/// When `map` does not fit the meshes.
pub fn chord_l2(from: &Mesh, to: &Mesh, map: &SurfaceMap) -> Result<f64> {
    let s = crate::metrics::distortion(from, &map.embed(from, to)?).l2_stretch;
    Ok(if s.is_finite() { s } else { f64::INFINITY })
}

/// The induced map on H1 when the source domain is turned by `rotation` steps.
pub fn induced_h1_for(s: &CanonicalBasisResult, t: &CanonicalBasisResult, rotation: usize) -> Vec<Vec<i32>> {
    let g = s.genus();
    let shift = if g == 1 { rotation % 4 } else { 4 * (rotation % g) };
    induced_h1(s, t, shift)
}

/// The induced map on H1 in the two canonical bases: source side `k` lands on target side
/// `k + shift`; the image's coordinates come from its intersection numbers with the target
/// basis (`x_j = γ·b_j`, `y_j = −γ·a_j`, since `a_j·b_j = 1`).
fn induced_h1(s: &CanonicalBasisResult, t: &CanonicalBasisResult, shift: usize) -> Vec<Vec<i32>> {
    let n = s.loops.len();
    let m = t.word.len();
    let mut h = vec![vec![0; n]; n];
    for (j, col) in (0..n).map(|j| (j, 4 * (j / 2) + j % 2)) {
        let letter = t.word[(col + shift) % m];
        let sign = i32::from(letter.dir);
        let row = &t.intersection[letter.loop_id];
        for i in 0..n / 2 {
            h[2 * i][j] = sign * row[2 * i + 1];
            h[2 * i + 1][j] = -sign * row[2 * i];
        }
    }
    h
}
