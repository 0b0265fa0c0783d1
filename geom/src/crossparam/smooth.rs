//! Stretch-reducing relocation of mapped vertices across patch boundaries, in the spirit of
//! Kraevoy & Sheffer 2004, section 5. The patch-wise map is continuous but kinks where patches
//! meet; here every free vertex's image moves, one at a time (Gauss-Seidel), towards the
//! mean-value combination (weights of its source star) of its neighbours' images, and is
//! projected back onto the target
//! surface (BVH closest point). A move is kept only if it lowers the local symmetric Dirichlet
//! stretch of the incident triangles (Sander's L2 plus its inverse, so triangles cannot
//! collapse) minus a weighted reward for their mapped area (chords that cut across a curved
//! target lose area), and leaves every incident triangle facing the way the target does; so
//! the result stays on the surface and flip-free, and anchors never move.

use crate::error::Result;
use crate::linalg::{Weights, directed_weights};
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, P3, V3, VertexId};
use crate::progress::Progress;
use crate::topology::Locator;
use serde::{Deserialize, Serialize};

/// Options for [`smooth`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SmoothOptions {
    /// Sweeps at most (0 disables smoothing). After the first, a sweep visits only vertices
    /// next to one whose move lowered its star energy by more than `tolerance` (relative).
    pub iterations: usize,
    /// Relative star-energy drop below which a move does not wake its neighbours.
    pub tolerance: f64,
    /// Fraction of the way to the relaxed position tried first (halved on rejection, twice).
    pub step: f64,
}

impl Default for SmoothOptions {
    fn default() -> Self {
        Self { iterations: 10, step: 1.0, tolerance: 1e-4 }
    }
}

/// What smoothing did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize, Deserialize)]
pub struct SmoothReport {
    /// Points moved inside their face so that the evaluator's nearest-face rule finds it.
    pub made_visible: usize,
    /// Moves that removed faces the evaluator counts as flipped (`visible::repair_flips`).
    pub repaired: usize,
    /// Regions around remaining folds re-embedded through a target chart (`untangle`).
    pub reembedded: usize,
    pub untangled: usize,
    pub moves: usize,
    pub rejected: usize,
    pub energy_before: f64,
    pub energy_after: f64,
    /// Newton steps of the final optimization of the chords on the target
    /// ([`super::on_surface`]), when kept.
    pub chord_steps: usize,
}

impl SmoothReport {
    pub fn merge(self, o: SmoothReport) -> SmoothReport {
        SmoothReport {
            made_visible: self.made_visible + o.made_visible,
            repaired: self.repaired + o.repaired,
            reembedded: self.reembedded + o.reembedded,
            untangled: self.untangled + o.untangled,
            moves: self.moves + o.moves,
            rejected: self.rejected + o.rejected,
            energy_before: self.energy_before + o.energy_before,
            energy_after: self.energy_after + o.energy_after,
            chord_steps: self.chord_steps + o.chord_steps,
        }
    }
}

/// `J = [c0 c1]` of a mapped triangle, with `n0 = |c0|²`, `n1 = |c1|²`, `d = c0·c1` and
/// `det = n0 n1 − d²` (positive).
pub(crate) struct Jacobian {
    pub(crate) c0: V3,
    pub(crate) c1: V3,
    pub(crate) n0: f64,
    pub(crate) n1: f64,
    pub(crate) d: f64,
    pub(crate) det: f64,
}

/// A source triangle in its own orthonormal frame: `S^-1 = [[a, b], [0, c]]` (the inverse of
/// the upper-triangular matrix of its edges) and its area.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SourceFrame {
    inv: [f64; 3],
    area: f64,
}

impl SourceFrame {
    pub(crate) fn new(s: [P3; 3]) -> Option<Self> {
        let e1 = s[1] - s[0];
        let e2 = s[2] - s[0];
        let l = e1.norm();
        let n = e1.cross(&e2);
        let nn = n.norm();
        if l == 0.0 || nn == 0.0 {
            return None;
        }
        let x = e1 / l;
        let (e2x, e2y) = (e2.dot(&x), (n / nn).cross(&x).dot(&e2));
        Some(Self { inv: [1.0 / l, -e2x / (l * e2y), 1.0 / e2y], area: 0.5 * nn })
    }

    /// `S⁻¹` as a 2x2 matrix (rows), for maps into the plane.
    pub(crate) fn inverse(&self) -> [[f64; 2]; 2] {
        let [a, b, c] = self.inv;
        [[a, b], [0.0, c]]
    }

    pub(crate) fn area(&self) -> f64 {
        self.area
    }

    /// Symmetric Dirichlet energy of the affine map onto the mapped triangle `m` (scaled by
    /// `scale`), times the source area: `|J|² + |J⁻¹|²` with `J = [m1 - m0, m2 - m0] S⁻¹`
    /// (3x2), so `|J⁻¹|² = |J|² / det(JᵀJ)`. `None` for a degenerate mapped triangle.
    pub(crate) fn energy(&self, m: [P3; 3], scale: f64) -> Option<f64> {
        let j = self.jacobian(m, scale)?;
        let fro = j.n0 + j.n1;
        Some(self.area * (fro + fro / j.det))
    }

    /// The columns `c0`, `c1` of `J` for the mapped triangle `m` (scaled by `scale`), their
    /// squared norms, dot product and `det(JᵀJ)`; `None` when that is not positive.
    pub(crate) fn jacobian(&self, m: [P3; 3], scale: f64) -> Option<Jacobian> {
        let [a, b, c] = self.inv;
        let (e1, e2) = ((m[1] - m[0]) * scale, (m[2] - m[0]) * scale);
        let c0 = e1 * a;
        let c1 = e1 * b + e2 * c;
        let (n0, n1, d) = (c0.norm_squared(), c1.norm_squared(), c0.dot(&c1));
        let det = n0 * n1 - d * d;
        (det > 0.0 && det.is_finite()).then_some(Jacobian { c0, c1, n0, n1, d, det })
    }

    /// Gradient and Hessian of [`SourceFrame::energy`] with respect to corner `corner` of `m`
    /// moving in the plane spanned by the orthonormal `t1`, `t2` (exact derivatives, for the
    /// smoother's Newton step). With `J = [c0 c1]` a corner's move `δ` changes the columns by
    /// `α δ` and `β δ`; the energy is `A (F + F / D)`, `F = |c0|² + |c1|²`,
    /// `D = |c0|²|c1|² − (c0·c1)²`, whose derivatives follow from those of `|c0|²`, `|c1|²` and
    /// `c0·c1` (all quadratic in `δ`). `None` for a degenerate mapped triangle.
    pub(crate) fn energy_derivatives(
        &self,
        m: [P3; 3],
        corner: usize,
        scale: f64,
        t1: V3,
        t2: V3,
    ) -> Option<([f64; 2], [[f64; 2]; 2])> {
        let Jacobian { c0, c1, n0, n1, d, det: dd } = self.jacobian(m, scale)?;
        let [a, b, c] = self.inv;
        let f = n0 + n1;
        let (al, be) = match corner {
            0 => (-scale * a, -scale * (b + c)),
            1 => (scale * a, scale * b),
            _ => (0.0, scale * c),
        };
        // Everything in tangent coordinates.
        let p0 = [c0.dot(&t1), c0.dot(&t2)];
        let p1 = [c1.dot(&t1), c1.dot(&t2)];
        let gn0 = [2.0 * al * p0[0], 2.0 * al * p0[1]];
        let gn1 = [2.0 * be * p1[0], 2.0 * be * p1[1]];
        let gd = [al * p1[0] + be * p0[0], al * p1[1] + be * p0[1]];
        let gf = [gn0[0] + gn1[0], gn0[1] + gn1[1]];
        let gdd = [0, 1].map(|i| n1 * gn0[i] + n0 * gn1[i] - 2.0 * d * gd[i]);
        let hf = 2.0 * (al * al + be * be);
        let hdd_diag = 2.0 * al * al * n1 + 2.0 * be * be * n0 - 4.0 * al * be * d;
        let (inv, inv2) = (1.0 / dd, 1.0 / (dd * dd));
        let grad = [0, 1].map(|i| self.area * (gf[i] * (1.0 + inv) - f * gdd[i] * inv2));
        let mut hess = [[0.0; 2]; 2];
        for i in 0..2 {
            for j in 0..2 {
                let id = if i == j { 1.0 } else { 0.0 };
                let hdd = gn0[i] * gn1[j] + gn1[i] * gn0[j] - 2.0 * gd[i] * gd[j] + hdd_diag * id;
                hess[i][j] = self.area
                    * (hf * id * (1.0 + inv) - (gf[i] * gdd[j] + gdd[i] * gf[j]) * inv2 - f * hdd * inv2
                        + 2.0 * f * gdd[i] * gdd[j] * inv2 * inv);
            }
        }
        Some((grad, hess))
    }
}

/// What [`map_quality`] measures of a map before smoothing.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MapQuality {
    /// Symmetric Dirichlet energy (summed over source faces, source areas as weights, the
    /// target scaled to the source's area), as [`smooth`] measures it before it moves anything;
    /// a face mapped flat counts as `f64::MAX` divided by the face count.
    pub energy: f64,
    /// Faces whose mapped normal opposes the target's at all three corners.
    pub flipped: usize,
    /// Mapped area over the target's area.
    pub area_ratio: f64,
}

/// Measures `map` from `source` onto `target`: the figures by which two candidate maps are
/// compared before one is smoothed.
pub fn map_quality(source: &Mesh, target: &Mesh, map: &SurfaceMap) -> MapQuality {
    let scale = (source.area() / target.area().max(f64::MIN_POSITIVE)).sqrt();
    let pos: Vec<P3> = (0..source.n_vertices()).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    let flat = f64::MAX / source.n_faces().max(1) as f64;
    let mut q = MapQuality { energy: 0.0, flipped: 0, area_ratio: 0.0 };
    for f in 0..source.n_faces() {
        let tri = source.face(FaceId::from_idx(f));
        let m = tri.map(|w| pos[w.idx()]);
        if let Some(fr) = SourceFrame::new(tri.map(|w| source.position(w))) {
            q.energy += fr.energy(m, scale).unwrap_or(flat);
        }
        let n = (m[1] - m[0]).cross(&(m[2] - m[0]));
        q.area_ratio += 0.5 * n.norm();
        q.flipped += usize::from(tri.iter().all(|w| n.dot(&target.face_normal_raw(map.face[w.idx()])) < 0.0));
    }
    q.area_ratio /= target.area().max(f64::MIN_POSITIVE);
    q
}

/// Faces of `v`'s star in `source` that face against `target` at all their corners (the
/// evaluator's flip rule, with the target faces the corners lie on), were `v`'s image at `p`
/// on face `f` and every other vertex `w` at `pos[w]` on face `faces[w]`.
pub(crate) fn flipped_in_star(
    source: &Mesh,
    target: &Mesh,
    v: VertexId,
    p: P3,
    f: FaceId,
    pos: &[P3],
    faces: &[FaceId],
) -> usize {
    source
        .outgoing(v)
        .filter(|h| {
            let tri = source.face(h.face());
            let m = tri.map(|w| if w == v { p } else { pos[w.idx()] });
            let nm = (m[1] - m[0]).cross(&(m[2] - m[0]));
            tri.iter().all(|&w| nm.dot(&target.face_normal_raw(if w == v { f } else { faces[w.idx()] })) < 0.0)
        })
        .count()
}

/// Relaxes `map: source -> target`. `fixed` vertices (the anchors) never move.
///
/// # Errors
/// `Cancelled`; `Error::Internal` if the target's BVH cannot be built.
pub fn smooth(
    source: &Mesh,
    target: &Mesh,
    mut map: SurfaceMap,
    fixed: &[VertexId],
    opts: &SmoothOptions,
    progress: &mut dyn Progress,
) -> Result<(SurfaceMap, SmoothReport)> {
    let mut rep = SmoothReport::default();
    if opts.iterations == 0 {
        return Ok((map, rep));
    }
    let n = source.n_vertices();
    let loc = Locator::new(target)?;
    let scale = (source.area() / target.area().max(f64::MIN_POSITIVE)).sqrt();
    let mut pos: Vec<P3> = (0..n).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    let mut is_fixed = vec![false; n];
    for v in fixed {
        is_fixed[v.idx()] = true;
    }
    // Boundary images stay where the patch maps put them: on the target's boundary.
    for (v, f) in is_fixed.iter_mut().enumerate() {
        *f |= source.is_boundary_vertex(VertexId::from_idx(v));
    }
    // Mean-value weight of each outgoing half-edge's head, from both faces beside the edge.
    let dw = directed_weights(source, Weights::MeanValue);
    let lambda: Vec<f64> = (0..source.n_halfedges())
        .map(|h| {
            let h = crate::HalfedgeId::from_idx(h);
            dw.fwd[h.idx()] + source.twin(h).map_or(0.0, |t| dw.rev[t.idx()])
        })
        .collect();
    // The target's normal at each image, from the face it lies on.
    let tnormal = |f: FaceId| -> V3 { target.face_normal_raw(f) };
    let mut img_face: Vec<FaceId> = map.face.clone();
    let frames: Vec<Option<SourceFrame>> =
        (0..source.n_faces()).map(|f| SourceFrame::new(source.face_points(FaceId::from_idx(f)))).collect();
    let star_energy = |v: VertexId, pos: &[P3], img_face: &[FaceId], p: P3, f: FaceId| -> Option<f64> {
        let mut e = 0.0;
        for h in source.outgoing(v) {
            let tri = source.face(h.face());
            let m = tri.map(|w| if w == v { p } else { pos[w.idx()] });
            // Orientation against the target at all three corners' faces.
            let nm = (m[1] - m[0]).cross(&(m[2] - m[0]));
            let faces = tri.map(|w| if w == v { f } else { img_face[w.idx()] });
            if faces.iter().all(|&g| nm.dot(&tnormal(g)) < 0.0) {
                return None;
            }
            if nm.dot(&tnormal(f)) <= 0.0 {
                return None;
            }
            e += frames[h.face().idx()].as_ref()?.energy(m, scale)?;
        }
        Some(e)
    };
    let total = |pos: &[P3]| -> f64 {
        (0..source.n_faces())
            .filter_map(|f| {
                let tri = source.face(FaceId::from_idx(f));
                frames[f]?.energy(tri.map(|w| pos[w.idx()]), scale)
            })
            .sum::<f64>()
    };
    // Newton step of the star energy (without the orientation test) over the tangent plane
    // `p + a t1 + b t2`, with exact derivatives (`SourceFrame::energy_derivatives`); `None`
    // where the Hessian is not positive definite.
    let newton_goal = |v: VertexId, pos: &[P3], normal: V3| -> Option<P3> {
        let p = pos[v.idx()];
        let nl = normal.norm();
        if nl <= 0.0 {
            return None;
        }
        let [t1, t2] = tangents(normal);
        let (mut reach, mut k) = (0.0, 0.0);
        for w in source.vertex_neighbors(v) {
            reach += (pos[w.idx()] - p).norm();
            k += 1.0;
        }
        let reach = reach / f64::max(k, 1.0);
        if reach <= 0.0 {
            return None;
        }
        let (g, h11, h22, h12) = {
            // Exact derivatives of the symmetric Dirichlet energy.
            let (mut g, mut hs) = ([0.0; 2], [[0.0; 2]; 2]);
            for he in source.outgoing(v) {
                let tri = source.face(he.face());
                let corner = tri.iter().position(|&w| w == v)?;
                let m = tri.map(|w| pos[w.idx()]);
                let (fg, fh) = frames[he.face().idx()].as_ref()?.energy_derivatives(m, corner, scale, t1, t2)?;
                for i in 0..2 {
                    g[i] += fg[i];
                    for j in 0..2 {
                        hs[i][j] += fh[i][j];
                    }
                }
            }
            (g, hs[0][0], hs[1][1], hs[0][1])
        };
        let det = h11 * h22 - h12 * h12;
        if !(h11 > 0.0 && det > 0.0) {
            return None;
        }
        let (da, db) = ((-h22 * g[0] + h12 * g[1]) / det, (h12 * g[0] - h11 * g[1]) / det);
        // No further than half the star's mean reach in one step.
        let len = (da * da + db * db).sqrt();
        let cap = if len > 0.5 * reach { 0.5 * reach / len } else { 1.0 };
        Some(p + t1 * (da * cap) + t2 * (db * cap))
    };
    // Untangle first: a vertex of a face that faces against the target at all its corners
    // moves towards its neighbours' images if that lowers the number of such faces.
    let flipped_at = |v: VertexId, pos: &[P3], img_face: &[FaceId], p: P3, f: FaceId| -> usize {
        flipped_in_star(source, target, v, p, f, pos, img_face)
    };
    for _ in 0..4 * opts.iterations.max(1) {
        let mut changed = false;
        for vi in 0..n {
            if is_fixed[vi] {
                continue;
            }
            let v = VertexId::from_idx(vi);
            let cur = flipped_at(v, &pos, &img_face, pos[vi], img_face[vi]);
            if cur == 0 {
                continue;
            }
            let (mut c, mut k) = (V3::zeros(), 0.0f64);
            for w in source.vertex_neighbors(v) {
                c += pos[w.idx()].coords;
                k += 1.0;
            }
            let goal = P3::from(c / k.max(1.0));
            // Candidates: towards the neighbours' mean, then half-way towards each neighbour.
            let mut cands: Vec<P3> =
                [1.0, 0.5, 0.25, 0.125].iter().map(|&t| P3::from(pos[vi].coords + (goal - pos[vi]) * t)).collect();
            cands.extend(source.vertex_neighbors(v).map(|w| P3::from((pos[vi].coords + pos[w.idx()].coords) * 0.5)));
            let mut best: Option<(usize, crate::topology::Projection)> = None;
            for c in cands {
                let pr = loc.project(&c);
                let fl = flipped_at(v, &pos, &img_face, pr.point, pr.face);
                if fl < cur && best.as_ref().is_none_or(|b| fl < b.0) {
                    best = Some((fl, pr));
                    if fl == 0 {
                        break;
                    }
                }
            }
            if let Some((_, pr)) = best {
                pos[vi] = pr.point;
                img_face[vi] = pr.face;
                map.face[vi] = pr.face;
                map.bary[vi] = pr.bary;
                rep.untangled += 1;
                changed = true;
            }
        }
        if !changed {
            break;
        }
    }
    rep.energy_before = total(&pos);
    // One relaxation move of `vi` against the current images: the new projection and whether
    // its star energy dropped by more than the tolerance. Reads only.
    let try_move = |vi: usize, pos: &[P3], img_face: &[FaceId]| -> Option<(crate::topology::Projection, bool)> {
        let v = VertexId::from_idx(vi);
        // Shape-preserving relaxation target (Floater's mean-value weights of the source star
        // applied to the neighbours' images: an isometry reproduces it), then the surface.
        let (mut c, mut k) = (V3::zeros(), 0.0f64);
        for h in source.outgoing(v) {
            let l = lambda[h.idx()];
            c += pos[source.head(h).idx()].coords * l;
            k += l;
        }
        if k <= 0.0 || !k.is_finite() {
            return None;
        }
        let relaxed = P3::from(c / k);
        // A star that is already degenerate or faces against the target accepts any valid move.
        let cur = star_energy(v, pos, img_face, pos[vi], img_face[vi]).unwrap_or(f64::INFINITY);
        // First a Newton step on the star energy in the target's tangent plane, then the
        // relaxation target; each with step halving.
        let newton = if cur.is_finite() { newton_goal(v, pos, tnormal(img_face[vi])) } else { None };
        for (goal, tries) in newton.map(|g| (g, 2)).into_iter().chain([(relaxed, 3)]) {
            let mut step = opts.step;
            for _ in 0..tries {
                let trial = P3::from(pos[vi].coords + (goal - pos[vi]) * step);
                let pr = loc.project_near(target, &trial, img_face[vi], 1);
                if let Some(e) = star_energy(v, pos, img_face, pr.point, pr.face)
                    && e < cur
                {
                    return Some((pr, cur - e > opts.tolerance * cur));
                }
                step *= 0.5;
            }
        }
        None
    };
    // Gauss-Seidel in index order (meshes store neighbours close together, so this walks
    // memory nearly in sequence); a sweep after the first visits only woken vertices.
    let mut active = vec![true; n];
    let mut next = vec![false; n];
    for it in 0..opts.iterations {
        progress.check()?;
        progress.report(crate::progress::Stage::Smooth, it as f64 / opts.iterations as f64);
        for vi in 0..n {
            if is_fixed[vi] || !active[vi] {
                continue;
            }
            let Some((pr, wake)) = try_move(vi, &pos, &img_face) else {
                rep.rejected += 1;
                continue;
            };
            if wake {
                next[vi] = true;
                for w in source.vertex_neighbors(VertexId::from_idx(vi)) {
                    next[w.idx()] = true;
                }
            }
            pos[vi] = pr.point;
            img_face[vi] = pr.face;
            map.face[vi] = pr.face;
            map.bary[vi] = pr.bary;
            rep.moves += 1;
        }
        std::mem::swap(&mut active, &mut next);
        next.fill(false);
        if !active.iter().any(|&a| a) {
            break;
        }
    }
    rep.energy_after = total(&pos);
    Ok((map, rep))
}

/// An orthonormal pair spanning the plane normal to `n` (not zero).
pub(crate) fn tangents(n: V3) -> [V3; 2] {
    let n = n.normalize();
    let t1 = if n.x.abs() < 0.9 { V3::x().cross(&n) } else { V3::y().cross(&n) }.normalize();
    [t1, n.cross(&t1)]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The exact gradient and Hessian agree with central differences of the energy, for each
    /// corner of a skewed triangle mapped onto a tilted, stretched one.
    #[test]
    fn energy_derivatives_match_central_differences() {
        let fr = SourceFrame::new([P3::new(0.1, 0.0, 0.2), P3::new(1.3, 0.2, 0.0), P3::new(0.4, 0.9, 0.1)]).unwrap();
        let m = [P3::new(0.0, 0.1, 0.0), P3::new(1.7, 0.0, 0.4), P3::new(0.2, 1.1, 0.6)];
        let (t1, t2) = (V3::new(1.0, 0.0, 0.0), V3::new(0.0, 0.6, 0.8));
        let scale = 0.9;
        for corner in 0..3 {
            let e = |x: f64, y: f64| {
                let mut q = m;
                q[corner] += t1 * x + t2 * y;
                fr.energy(q, scale).unwrap()
            };
            let h = 1e-4;
            let g = [(e(h, 0.0) - e(-h, 0.0)) / (2.0 * h), (e(0.0, h) - e(0.0, -h)) / (2.0 * h)];
            let hxx = (e(h, 0.0) - 2.0 * e(0.0, 0.0) + e(-h, 0.0)) / (h * h);
            let hyy = (e(0.0, h) - 2.0 * e(0.0, 0.0) + e(0.0, -h)) / (h * h);
            let hxy = (e(h, h) - e(h, -h) - e(-h, h) + e(-h, -h)) / (4.0 * h * h);
            let (ga, ha) = fr.energy_derivatives(m, corner, scale, t1, t2).unwrap();
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-5 * (1.0 + b.abs());
            assert!(close(ga[0], g[0]) && close(ga[1], g[1]), "corner {corner}: gradient {ga:?} vs {g:?}");
            assert!(close(ha[0][0], hxx) && close(ha[1][1], hyy), "corner {corner}: {ha:?} vs {hxx} {hyy}");
            assert!(close(ha[0][1], hxy) && close(ha[1][0], hxy), "corner {corner}: {ha:?} vs {hxy}");
        }
    }
}
