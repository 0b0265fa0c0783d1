//! The common base domain as a flat cone surface: every patch is a triangle in a chart of its
//! own, and the patch across a side is unfolded into that chart by a rigid motion (the
//! transition function of Khodakovsky, Litke & Schröder 2003). Anchors are the cone points.
//!
//! The triangles' side lengths are the layout paths' lengths (averaged over both meshes, each
//! scaled by √area), so the cone angle at an anchor follows the surface around it. With
//! equilateral triangles an anchor of valence 2 is a 120° cone and one of valence 8 a 480°
//! cone, whatever the surface does there, and a harmonic map folds around them (cow, 24
//! anchors: 144 folded triangles within six rings of anchors).
//!
//! A point of one chart is expressed in another through chains of transitions; near a cone
//! point several chains reach the same patch, one per sheet.

use super::super::TRIANGLE;
use crate::domain::Patch;
use crate::error::{Error, Result};
use crate::param::Uv;
use crate::planar::locate::barycentric;

/// An affine map of the plane, `x -> m x + t`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Affine {
    pub m: [[f64; 2]; 2],
    pub t: [f64; 2],
}

impl Affine {
    pub const IDENTITY: Affine = Affine { m: [[1.0, 0.0], [0.0, 1.0]], t: [0.0, 0.0] };

    pub fn apply(&self, x: Uv) -> Uv {
        [self.m[0][0] * x[0] + self.m[0][1] * x[1] + self.t[0], self.m[1][0] * x[0] + self.m[1][1] * x[1] + self.t[1]]
    }

    /// `self ∘ other`: first `other`, then `self`.
    pub fn after(&self, other: &Affine) -> Affine {
        let (a, b) = (&self.m, &other.m);
        let m = [
            [a[0][0] * b[0][0] + a[0][1] * b[1][0], a[0][0] * b[0][1] + a[0][1] * b[1][1]],
            [a[1][0] * b[0][0] + a[1][1] * b[1][0], a[1][0] * b[0][1] + a[1][1] * b[1][1]],
        ];
        Affine { m, t: self.apply(other.t) }
    }

    /// The inverse map (the maps used here are rigid, never singular).
    pub fn inverse(&self) -> Affine {
        let m = &self.m;
        let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
        let inv = [[m[1][1] / det, -m[0][1] / det], [-m[1][0] / det, m[0][0] / det]];
        let a = Affine { m: inv, t: [0.0, 0.0] };
        let t = a.apply(self.t);
        Affine { m: inv, t: [-t[0], -t[1]] }
    }

    /// The rotation and translation taking `a` to `a2` and the direction of `b - a` to that
    /// of `b2 - a2` (the segments have equal lengths when they are one side seen from two
    /// charts); `None` for a degenerate segment.
    pub fn rigid(a: Uv, b: Uv, a2: Uv, b2: Uv) -> Option<Affine> {
        let (d, e) = ([b[0] - a[0], b[1] - a[1]], [b2[0] - a2[0], b2[1] - a2[1]]);
        let (ld, le) = (d[0].hypot(d[1]), e[0].hypot(e[1]));
        if !(ld > 1e-300 && le > 1e-300) {
            return None;
        }
        let (c, s) = ((d[0] * e[0] + d[1] * e[1]) / (ld * le), (d[0] * e[1] - d[1] * e[0]) / (ld * le));
        let m = [[c, -s], [s, c]];
        let ma = Affine { m, t: [0.0, 0.0] }.apply(a);
        Some(Affine { m, t: [a2[0] - ma[0], a2[1] - ma[1]] })
    }

    /// The affine map taking `from[k]` to `to[k]`; `None` for a degenerate `from`.
    pub fn from_points(from: [Uv; 3], to: [Uv; 3]) -> Option<Affine> {
        let d =
            [[from[1][0] - from[0][0], from[2][0] - from[0][0]], [from[1][1] - from[0][1], from[2][1] - from[0][1]]];
        let e = [[to[1][0] - to[0][0], to[2][0] - to[0][0]], [to[1][1] - to[0][1], to[2][1] - to[0][1]]];
        let det = d[0][0] * d[1][1] - d[0][1] * d[1][0];
        if det.abs() < 1e-12 {
            return None;
        }
        let inv = [[d[1][1] / det, -d[0][1] / det], [-d[1][0] / det, d[0][0] / det]];
        let m = [
            [e[0][0] * inv[0][0] + e[0][1] * inv[1][0], e[0][0] * inv[0][1] + e[0][1] * inv[1][1]],
            [e[1][0] * inv[0][0] + e[1][1] * inv[1][0], e[1][0] * inv[0][1] + e[1][1] * inv[1][1]],
        ];
        let mf = Affine { m, t: [0.0, 0.0] }.apply(from[0]);
        Some(Affine { m, t: [to[0][0] - mf[0], to[0][1] - mf[1]] })
    }
}

/// Chains of transitions are followed this many patches deep.
const DEPTH: usize = 3;

/// Charts of every patch and the transitions between them.
pub struct Charts {
    /// Per patch: chart position of corner `k` (`patch.corners[k]`).
    pub corner: Vec<[Uv; 3]>,
    /// Per patch: its triangle counter-clockwise, corners 0, 2, 1 (the roles of
    /// [`TRIANGLE`]'s corners in the per-patch maps).
    pub tri: Vec<[Uv; 3]>,
    /// Per patch and side: the patch across it, the map from that patch's chart into this one,
    /// and its inverse.
    pub across: Vec<[(u32, Affine, Affine); 3]>,
    /// Per patch: every patch reachable within [`DEPTH`] steps, with the map of its chart into
    /// this patch's chart (one entry per distinct sheet).
    reach: Vec<Vec<(u32, Affine)>>,
    /// Per anchor: one patch that has it as a corner, and the corner's index there.
    pub anchor_home: Vec<Option<(u32, usize)>>,
    /// Per patch: its corner anchors.
    corners: Vec<[u32; 3]>,
}

impl Charts {
    /// Builds the charts of `patches` over `n_anchors` anchors; `lengths` (per path, i.e. per
    /// half `h` at `h / 2`) sets the side lengths, `None` makes every patch equilateral. Lengths
    /// that break a triangle inequality are shortened until every patch has angles of at least
    /// [`MIN_ANGLE_DEG`]; when that fails the patches are equilateral.
    ///
    /// # Errors
    /// `Error::Numerical` when a patch has a side with no partner or a repeated corner (the
    /// domain is not a closed triangulated surface, so it has no cone metric).
    pub fn new(patches: &[Patch], n_anchors: usize, lengths: Option<&[f64]>) -> Result<Charts> {
        let n_paths = patches.iter().flat_map(|p| p.sides).map(|h| h as usize / 2 + 1).max().unwrap_or(0);
        let len =
            lengths.and_then(|l| (l.len() >= n_paths).then(|| feasible_lengths(patches, &l[..n_paths]))).flatten();
        // Corner k sits where the patch parameterization puts it: the walk order runs
        // clockwise in the chart, so corners 0, 1, 2 take TRIANGLE[0], [2], [1]'s roles: corner
        // 0 at the origin, corner 2 on the positive x axis, corner 1 above it.
        let corner: Vec<[Uv; 3]> = patches
            .iter()
            .map(|p| match &len {
                Some(l) => {
                    let [l0, l1, l2] = p.sides.map(|h| l[h as usize / 2]);
                    // |c1 - c0| = l0, |c1 - c2| = l1, |c2 - c0| = l2.
                    let x = (l0 * l0 - l1 * l1 + l2 * l2) / (2.0 * l2);
                    let y = (l0 * l0 - x * x).max(0.0).sqrt();
                    [[0.0, 0.0], [x, y], [l2, 0.0]]
                }
                None => [TRIANGLE[0], TRIANGLE[2], TRIANGLE[1]],
            })
            .collect();
        let mut side_of = std::collections::HashMap::with_capacity(patches.len() * 3);
        let mut anchor_home = vec![None; n_anchors];
        for (p, patch) in patches.iter().enumerate() {
            let c = patch.corners;
            if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
                return Err(Error::Numerical(format!("patch {p} repeats a corner")));
            }
            for (k, &corner) in c.iter().enumerate() {
                side_of.insert(patch.sides[k], (p as u32, k));
                if let Some(h) = anchor_home.get_mut(corner as usize)
                    && h.is_none()
                {
                    *h = Some((p as u32, k));
                }
            }
        }
        let mut across = Vec::with_capacity(patches.len());
        for (p, patch) in patches.iter().enumerate() {
            let mut sides = [(0u32, Affine::IDENTITY, Affine::IDENTITY); 3];
            for (k, side) in sides.iter_mut().enumerate() {
                let Some(&(q, m)) = side_of.get(&(patch.sides[k] ^ 1)) else {
                    return Err(Error::Numerical(format!("side {k} of patch {p} has no patch across it")));
                };
                if q as usize == p {
                    return Err(Error::Numerical(format!("patch {p} borders itself")));
                }
                // Side k runs corners[k] -> corners[k+1]; across it, side m runs back.
                // The rigid motion taking q's copy of the side onto p's, ends matched; q's
                // triangle then lies across the side (both charts are counter-clockwise and the
                // side runs the other way in q).
                let (a, b) = (corner[p][(k + 1) % 3], corner[p][k]);
                let qc = &corner[q as usize];
                let Some(fwd) = Affine::rigid(qc[m], qc[(m + 1) % 3], a, b) else {
                    return Err(Error::Numerical(format!("degenerate transition at patch {p}")));
                };
                let back = fwd.inverse();
                *side = (q, fwd, back);
            }
            across.push(sides);
        }
        let reach = (0..patches.len()).map(|p| reach_from(p as u32, &across)).collect();
        let corners = patches.iter().map(|p| p.corners).collect();
        let tri = corner.iter().map(|c| [c[0], c[2], c[1]]).collect();
        Ok(Charts { corner, tri, across, reach, anchor_home, corners })
    }

    /// A map from anchor `a`'s home chart into patch `p`'s that takes the anchor to its place
    /// there (its corner when `p` has it; else the sheet closest to `near`).
    pub fn anchor_link(&self, a: u32, p: u32, near: Uv) -> Option<Affine> {
        let (h, k) = self.anchor_home.get(a as usize).copied().flatten()?;
        let x = self.corner[h as usize][k];
        match self.corners[p as usize].iter().position(|&c| c == a) {
            Some(c) => {
                let y = self.corner[p as usize][c];
                let exact = self.reach[p as usize].iter().find(|(r, m)| *r == h && dist2(m.apply(x), y) < 1e-18);
                Some(match exact {
                    Some((_, m)) => *m,
                    None => Affine { m: Affine::IDENTITY.m, t: [y[0] - x[0], y[1] - x[1]] },
                })
            }
            None => self.transition(h, p, x, near),
        }
    }

    /// Point `x` of patch `q`'s chart in patch `p`'s chart, on the sheet closest to `near`;
    /// `None` when `q` is more than [`DEPTH`] patches away.
    pub fn express(&self, x: Uv, q: u32, p: u32, near: Uv) -> Option<Uv> {
        self.transition(q, p, x, near).map(|a| a.apply(x))
    }

    /// The map of patch `q`'s chart into patch `p`'s on the sheet that puts `x` (a point of
    /// `q`'s chart) closest to `near`.
    pub fn transition(&self, q: u32, p: u32, x: Uv, near: Uv) -> Option<Affine> {
        if q == p {
            return Some(Affine::IDENTITY);
        }
        self.reach[p as usize]
            .iter()
            .filter(|(r, _)| *r == q)
            .min_by(|(_, a), (_, b)| dist2(a.apply(x), near).total_cmp(&dist2(b.apply(x), near)))
            .map(|(_, a)| *a)
    }

    /// The map of patch `q`'s chart into patch `p`'s on the sheet that puts `x` closest to
    /// `p`'s own triangle.
    pub fn transition_near_patch(&self, q: u32, p: u32, x: Uv) -> Option<Affine> {
        if q == p {
            return Some(Affine::IDENTITY);
        }
        self.reach[p as usize]
            .iter()
            .filter(|(r, _)| *r == q)
            .min_by(|(_, a), (_, b)| self.outside(p, a.apply(x)).total_cmp(&self.outside(p, b.apply(x))))
            .map(|(_, a)| *a)
    }

    /// Walks a vertex from `from` (inside patch `p`'s triangle) to `to` (same chart) across the
    /// sides the segment crosses, in order, so a point beyond a cone point's wedge lands on the
    /// sheet the segment reaches (not the one some other route would). Returns the patch where
    /// the walk ends, the position there, and the map from the old chart into the new one.
    pub fn settle(&self, mut p: u32, mut from: Uv, mut to: Uv) -> (u32, Uv, Affine) {
        let mut moved = Affine::IDENTITY;
        for _ in 0..8 {
            let bt = barycentric(self.tri[p as usize], to);
            if bt.iter().all(|&b| b >= -1e-12) {
                break;
            }
            let bf = barycentric(self.tri[p as usize], from);
            // The side whose line the segment reaches first, among those `to` lies beyond.
            let mut exit: Option<(f64, usize)> = None;
            for j in 0..3 {
                if bt[j] < -1e-12 {
                    let t = (bf[j].max(0.0) / (bf[j].max(0.0) - bt[j])).clamp(0.0, 1.0);
                    if exit.is_none_or(|(s, _)| t < s) {
                        exit = Some((t, j));
                    }
                }
            }
            let Some((t, j)) = exit else { break };
            // The side opposite tri[j]: tri holds corners 0, 2, 1, so tri[0] faces side 1,
            // tri[1] side 0, tri[2] side 2.
            let side = [1, 0, 2][j];
            let (q, _, back) = self.across[p as usize][side];
            let at = [from[0] + t * (to[0] - from[0]), from[1] + t * (to[1] - from[1])];
            from = back.apply(at);
            to = back.apply(to);
            moved = back.after(&moved);
            p = q;
        }
        (p, to, moved)
    }
}

fn reach_from(p: u32, across: &[[(u32, Affine, Affine); 3]]) -> Vec<(u32, Affine)> {
    let mut out: Vec<(u32, Affine)> = vec![(p, Affine::IDENTITY)];
    let mut frontier = vec![(p, Affine::IDENTITY)];
    for _ in 0..DEPTH {
        let mut next = Vec::new();
        for (s, to_p) in frontier {
            for &(n, n_to_s, _) in &across[s as usize] {
                let a = to_p.after(&n_to_s);
                // One entry per sheet: the same patch reached by the same motion is one sheet.
                if out.iter().any(|(r, b)| *r == n && same(b, &a)) {
                    continue;
                }
                out.push((n, a));
                next.push((n, a));
            }
        }
        frontier = next;
    }
    out
}

fn same(a: &Affine, b: &Affine) -> bool {
    let d = (0..2).flat_map(|i| (0..2).map(move |j| (i, j))).map(|(i, j)| (a.m[i][j] - b.m[i][j]).abs()).sum::<f64>();
    d + (a.t[0] - b.t[0]).abs() + (a.t[1] - b.t[1]).abs() < 1e-9
}

pub(super) fn dist2(a: Uv, b: Uv) -> f64 {
    (a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2)
}

impl Charts {
    /// How far chart point `x` lies outside patch `p`'s triangle (0 inside): minus its most
    /// negative barycentric coordinate.
    pub fn outside(&self, p: u32, x: Uv) -> f64 {
        let b = barycentric(self.tri[p as usize], x);
        (-b[0].min(b[1]).min(b[2])).max(0.0)
    }

    /// The affine map from [`TRIANGLE`] (the per-patch maps' domain) onto patch `p`'s
    /// triangle, corner roles kept.
    pub fn from_canonical(&self, p: u32) -> Affine {
        Affine::from_points(TRIANGLE, self.tri[p as usize]).unwrap_or(Affine::IDENTITY)
    }
}

/// Smallest angle a patch triangle may have after [`feasible_lengths`].
pub const MIN_ANGLE_DEG: f64 = 5.0;

/// Path lengths that make every patch a triangle with angles of at least [`MIN_ANGLE_DEG`]: the
/// longest side of a patch that breaks this is shortened to what the other two allow, for a
/// few rounds (a side is shared by two patches, so shortening it can break the other); `None`
/// when that does not settle.
fn feasible_lengths(patches: &[Patch], lengths: &[f64]) -> Option<Vec<f64>> {
    let mut l = lengths.to_vec();
    if l.iter().any(|x| !(x.is_finite() && *x > 0.0)) {
        return None;
    }
    let cmin = MIN_ANGLE_DEG.to_radians().cos();
    for _ in 0..50 {
        let mut changed = false;
        for p in patches {
            let idx = p.sides.map(|h| h as usize / 2);
            for k in 0..3 {
                let (a, b, c) = (l[idx[k]], l[idx[(k + 1) % 3]], l[idx[(k + 2) % 3]]);
                // The angle opposite side a: a² = b² + c² - 2bc cos α, α >= MIN_ANGLE... and
                // the angles opposite b and c large enough too: cap a at the length that gives
                // the angle between b and c its largest value 180° - 2 MIN_ANGLE.
                let amax = (b * b + c * c + 2.0 * b * c * (2.0 * MIN_ANGLE_DEG.to_radians()).cos()).sqrt();
                let amin = (b * b + c * c - 2.0 * b * c * cmin).max(0.0).sqrt();
                if a > amax * (1.0 + 1e-12) {
                    l[idx[k]] = amax;
                    changed = true;
                } else if a < amin * (1.0 - 1e-12) {
                    l[idx[k]] = amin;
                    changed = true;
                }
            }
        }
        if !changed {
            return Some(l);
        }
    }
    None
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The octahedron's eight faces as patches over six anchors (every anchor of valence 4, a
    /// cone of 240°), with halves numbered `2 * edge + direction`.
    pub(crate) fn octahedron() -> Vec<Patch> {
        let faces: [[u32; 3]; 8] =
            [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
        let mut edges: Vec<(u32, u32)> = Vec::new();
        let mut half = |a: u32, b: u32| -> u32 {
            if let Some(e) = edges.iter().position(|&(x, y)| (x, y) == (a, b)) {
                return 2 * e as u32;
            }
            if let Some(e) = edges.iter().position(|&(x, y)| (x, y) == (b, a)) {
                return 2 * e as u32 + 1;
            }
            edges.push((a, b));
            2 * (edges.len() as u32 - 1)
        };
        // Walk order is clockwise; sides[k] runs corners[k] -> corners[k + 1].
        faces
            .iter()
            .map(|f| {
                let c = [f[0], f[2], f[1]];
                Patch { corners: c, sides: [half(c[0], c[1]), half(c[1], c[2]), half(c[2], c[0])] }
            })
            .collect()
    }

    #[test]
    fn transitions_glue_shared_sides_and_invert() {
        let patches = octahedron();
        let ch = Charts::new(&patches, 6, None).unwrap();
        for (p, patch) in patches.iter().enumerate() {
            for k in 0..3 {
                let (q, fwd, back) = ch.across[p][k];
                let qp = &patches[q as usize];
                // Both shared anchors land on their own positions in p's chart.
                for a in [patch.corners[k], patch.corners[(k + 1) % 3]] {
                    let iq = qp.corners.iter().position(|&c| c == a).unwrap();
                    let ip = patch.corners.iter().position(|&c| c == a).unwrap();
                    assert!(dist2(fwd.apply(ch.corner[q as usize][iq]), ch.corner[p][ip]) < 1e-24);
                }
                // q's third corner is unfolded outside p's triangle, and back undoes fwd.
                let third = (0..3).find(|&i| !patch.corners.contains(&qp.corners[i])).unwrap();
                assert!(ch.outside(p as u32, fwd.apply(ch.corner[q as usize][third])) > 0.5);
                let x = [0.3, 0.2];
                assert!(dist2(back.apply(fwd.apply(x)), x) < 1e-24);
                // Rigid: the linear part is a rotation.
                let det = fwd.m[0][0] * fwd.m[1][1] - fwd.m[0][1] * fwd.m[1][0];
                assert!((det - 1.0).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn points_settle_in_the_patch_across_and_keep_their_place() {
        let patches = octahedron();
        let ch = Charts::new(&patches, 6, None).unwrap();
        // Just past side 0 of patch 0: it belongs to the patch across side 0.
        let (q, _, back) = ch.across[0][0];
        let a = ch.corner[0][0];
        let b = ch.corner[0][1];
        let mid = [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0];
        let out = [mid[0] - 0.05, mid[1] + 0.03];
        assert!(ch.outside(0, out) > 0.0);
        let (p, x, m) = ch.settle(0, [0.5, 0.3], out);
        assert_eq!(p, q);
        assert!(dist2(m.apply(out), x) < 1e-24);
        assert!(dist2(m.inverse().apply(x), out) < 1e-24);
        assert!(dist2(x, back.apply(out)) < 1e-24);
        assert!(ch.outside(p, x) == 0.0);
        // Expressed back into patch 0 near where it came from, it is the same point.
        let y = ch.express(x, p, 0, out).unwrap();
        assert!(dist2(y, out) < 1e-24);
    }

    #[test]
    fn around_a_cone_point_each_sheet_is_reached_once() {
        let patches = octahedron();
        let ch = Charts::new(&patches, 6, None).unwrap();
        // Anchor 4 has valence 4: going round it, the patch opposite patch 0 at anchor 4 is
        // reached two ways, on two sheets that differ by the cone's 240° turn.
        let sheets: Vec<_> = ch.reach[0].iter().filter(|(q, _)| *q == 2).collect();
        assert!(sheets.len() >= 2, "{}", sheets.len());
    }
}
