//! Vertex-level alignment of the curve sides of two feature cuts, by dynamic time warping.
//!
//! [`feature_domain`](super::feature_domain) places each side's vertices on its arc by arc
//! length, on both meshes. Two copies of one boundary that differ by a non-isometric
//! deformation then disagree by a few vertex spacings, and on a zigzag boundary that is enough
//! to send a source triangle whose three corners are boundary vertices onto a chord of the
//! target boundary that turns the other way (a flipped face). Here the target's positions along
//! each curve side are warped so that its vertices land where the source's corresponding
//! vertices do.
//!
//! Technique: dynamic time warping (Sakoe–Chiba 1978) of the two sides' vertex sequences, with
//! a cost per pair that adds the squared difference of their arc-length fractions (scaled by a
//! band, so the warp stays near the arc-length correspondence) and the squared difference of
//! their interior angles on the disk (the boundary's turning within the surface: a zigzag's
//! tips and notches), and a penalty per unmatched step. The pairs matched one to one (diagonal
//! steps) are the warp's knots; target vertices between knots are spread by arc length. Links
//! (the chain's own cuts) are left to arc length: they are drawn separately on each mesh.

use super::feature_cut::{FeatureCutResult, SideKind};

/// How the warp weighs its terms.
#[derive(Debug, Clone, Copy)]
pub struct CurveAlignOptions {
    /// Arc-length fraction of a side over which a shift costs as much as a half-turn of angle
    /// mismatch.
    pub band: f64,
    /// Cost of a step that matches one vertex with two.
    pub gap: f64,
    /// Largest `(n + 1)(m + 1)` aligned; longer sides keep arc length.
    pub max_cells: usize,
    /// Angles compared on each side of a vertex (a window of `2 w + 1`).
    pub window: usize,
}

impl Default for CurveAlignOptions {
    fn default() -> Self {
        Self { band: 0.2, gap: 0.1, max_cells: 16_000_000, window: 2 }
    }
}

/// Per side, the fraction in `[0, 1)` of each of its vertices `walk[start + i]`, `i < edges`.
pub type SideFractions = Vec<Vec<f64>>;

/// Arc-length fractions of every side of `cut`.
pub fn arc_fractions(cut: &FeatureCutResult) -> SideFractions {
    let (disk, walk) = (&cut.disk.mesh, &cut.walk);
    cut.sides
        .iter()
        .map(|s| {
            let mut t = 0.0;
            (0..s.edges)
                .map(|i| {
                    let (v, w) = (walk[(s.start + i) % walk.len()], walk[(s.start + i + 1) % walk.len()]);
                    let f = t / s.length.max(f64::MIN_POSITIVE);
                    t += (disk.position(w) - disk.position(v)).norm();
                    f
                })
                .collect()
        })
        .collect()
}

/// Sum of the corner angles at every vertex of `mesh` (a boundary vertex's interior angle).
pub(crate) fn angle_sums(mesh: &crate::mesh::Mesh) -> Vec<f64> {
    let mut out = vec![0.0; mesh.n_vertices()];
    for f in mesh.faces() {
        let p = f.map(|v| mesh.position(v));
        for k in 0..3 {
            let (a, b) = (p[(k + 1) % 3] - p[k], p[(k + 2) % 3] - p[k]);
            out[f[k].idx()] += a.cross(&b).norm().atan2(a.dot(&b));
        }
    }
    out
}

/// Fractions for the target's sides: curve sides warped onto the source's (see the module
/// doc), links by arc length. `source` and `target` have the same side kinds (as
/// [`super::feature_domain::shared_arcs`] checks).
pub fn align_fractions(source: &FeatureCutResult, target: &FeatureCutResult, o: &CurveAlignOptions) -> SideFractions {
    let (fs, mut ft) = (arc_fractions(source), arc_fractions(target));
    let (angs, angt) = (angle_sums(&source.disk.mesh), angle_sums(&target.disk.mesh));
    for (k, (ss, st)) in source.sides.iter().zip(&target.sides).enumerate() {
        if !matches!(ss.kind, SideKind::Curve(_)) || ss.kind != st.kind {
            continue;
        }
        let desc = |cut: &FeatureCutResult, ang: &[f64], edges: usize, start: usize| -> Vec<f64> {
            (0..=edges).map(|i| ang[cut.walk[(start + i) % cut.walk.len()].idx()]).collect()
        };
        let (ds, dt) = (desc(source, &angs, ss.edges, ss.start), desc(target, &angt, st.edges, st.start));
        let mut a = fs[k].clone();
        a.push(1.0);
        let mut b = ft[k].clone();
        b.push(1.0);
        if let Some(w) = warp(&a, &ds, &b, &dt, o) {
            ft[k] = w;
        }
    }
    agree_on_both_sides(target, &mut ft);
    ft
}

/// An open curve is cut into two sides that run along the same vertices, once each way, and
/// each side is warped on its own. Where the two warps put a vertex at different places, the
/// faces on one side of the curve see it where those on the other do not: at the curve's tip,
/// where both sides meet, a face can then span more than a half-turn of the tip's fan and fold.
/// Each vertex takes the mean of its two fractions (one mirrored), which keeps both sides
/// strictly increasing and makes them agree.
fn agree_on_both_sides(cut: &FeatureCutResult, ft: &mut SideFractions) {
    let orig =
        |side: &super::feature_cut::Side, i: usize| cut.disk.orig[cut.walk[(side.start + i) % cut.walk.len()].idx()];
    for k in 0..cut.sides.len() {
        let a = cut.sides[k];
        if !matches!(a.kind, SideKind::Curve(_)) {
            continue;
        }
        // The return side of the same curve (a boundary loop has none).
        let Some(r) = (k + 1..cut.sides.len()).find(|&r| cut.sides[r].kind == a.kind) else { continue };
        let b = cut.sides[r];
        let e = a.edges;
        if b.edges != e || ft[k].len() != e || ft[r].len() != e || !(0..=e).all(|i| orig(&a, i) == orig(&b, e - i)) {
            continue;
        }
        for i in 1..e {
            let t = 0.5 * (ft[k][i] + 1.0 - ft[r][e - i]);
            ft[k][i] = t;
            ft[r][e - i] = 1.0 - t;
        }
    }
}

/// Target fractions (without the closing 1) warped onto the source's, or `None` when the
/// sides are too long to align or too short to need it.
pub(crate) fn warp(a: &[f64], da: &[f64], b: &[f64], db: &[f64], o: &CurveAlignOptions) -> Option<Vec<f64>> {
    let (n, m) = (a.len(), b.len());
    if n < 3 || m < 3 || n.checked_mul(m)? > o.max_cells {
        return None;
    }
    let pi2 = std::f64::consts::PI * std::f64::consts::PI;
    let w = o.window as isize;
    let cost = |i: usize, j: usize| {
        let s = (a[i] - b[j]) / o.band;
        let mut d = 0.0;
        for k in -w..=w {
            let (x, y) = ((i as isize + k).clamp(0, n as isize - 1), (j as isize + k).clamp(0, m as isize - 1));
            let e = da[x as usize] - db[y as usize];
            d += e * e;
        }
        s * s + d / (pi2 * (2 * w + 1) as f64)
    };
    // Rolling cost rows; one byte per cell for the way back (0 diagonal, 1 from i - 1, 2 from
    // j - 1). The ends are junctions: they match each other and nothing else.
    let mut back = vec![0u8; n * m];
    let mut prev = vec![f64::INFINITY; m];
    let mut cur = vec![f64::INFINITY; m];
    prev[0] = 0.0;
    for j in 1..m {
        prev[j] = prev[j - 1] + o.gap + cost(0, j);
        back[j] = 2;
    }
    for i in 1..n {
        cur[0] = prev[0] + o.gap + cost(i, 0);
        back[i * m] = 1;
        for j in 1..m {
            let (d, u, l) = (prev[j - 1], prev[j] + o.gap, cur[j - 1] + o.gap);
            let (best, dir) = if d <= u && d <= l {
                (d, 0)
            } else if u <= l {
                (u, 1)
            } else {
                (l, 2)
            };
            cur[j] = best + cost(i, j);
            back[i * m + j] = dir;
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    // Knots: the ends and every pair entered by a diagonal step (strictly increasing in both).
    let end = (n - 1, m - 1);
    let mut knots = vec![end];
    let (mut i, mut j) = end;
    while i > 0 || j > 0 {
        let dir = back[i * m + j];
        if dir == 0 && (i, j) != end {
            knots.push((i, j));
        }
        match dir {
            0 => {
                i -= 1;
                j -= 1;
            }
            1 => i -= 1,
            _ => j -= 1,
        }
    }
    // A knot level with the end (the path ran along the last row or column) would repeat the
    // end's fraction.
    if knots.len() > 1 && (knots[1].0 == end.0 || knots[1].1 == end.1) {
        knots.remove(1);
    }
    knots.push((0, 0));
    knots.reverse();
    // Each target vertex between two knots: the source fraction interpolated by its arc length.
    let mut out = vec![0.0; m - 1];
    for win in knots.windows(2) {
        let ((i0, j0), (i1, j1)) = (win[0], win[1]);
        for (j, slot) in out.iter_mut().enumerate().take(j1.min(m - 1)).skip(j0) {
            let t = if j1 > j0 { (b[j] - b[j0]) / (b[j1] - b[j0]).max(f64::MIN_POSITIVE) } else { 0.0 };
            *slot = a[i0] + (a[i1] - a[i0]) * t;
        }
    }
    Some(out)
}

/// Loops longer than this are not searched for a rotation (the search is quadratic).
const MAX_ROTATION_LOOP: usize = 4096;

/// Where the target's copy of an unlisted boundary loop should start so that it lines up with
/// the source's: both loops have the same vertex count and the cyclic shift `r` of the target's
/// corner angles matches the source's far better than no shift and than shifts in general (a
/// deformed copy of one boundary). `None` when no shift stands out (different shapes: the
/// chain's own arrival point stays).
pub fn loop_rotation(
    source: &crate::mesh::Mesh,
    source_ring: &[crate::mesh::VertexId],
    target: &crate::mesh::Mesh,
    target_ring: &[crate::mesh::VertexId],
) -> Option<usize> {
    let n = source_ring.len();
    if n != target_ring.len() || !(8..=MAX_ROTATION_LOOP).contains(&n) {
        return None;
    }
    let (sa, sb) = (angle_sums(source), angle_sums(target));
    let a: Vec<f64> = source_ring.iter().map(|v| sa[v.idx()]).collect();
    let b: Vec<f64> = target_ring.iter().map(|v| sb[v.idx()]).collect();
    let cost: Vec<f64> = (0..n).map(|r| (0..n).map(|i| (a[i] - b[(i + r) % n]).powi(2)).sum()).collect();
    let best = (0..n).min_by(|&x, &y| cost[x].total_cmp(&cost[y]))?;
    let mut sorted = cost.clone();
    sorted.sort_by(f64::total_cmp);
    let median = sorted[n / 2];
    (best != 0 && cost[best] <= 0.25 * cost[0] && cost[best] <= 0.25 * median).then_some(best)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn zigzag(n: usize, shift: f64) -> (Vec<f64>, Vec<f64>) {
        // Fractions with a smooth non-uniform drift, angles alternating tip / notch.
        let f: Vec<f64> = (0..=n)
            .map(|i| {
                let t = i as f64 / n as f64;
                t + shift * (std::f64::consts::PI * t).sin()
            })
            .collect();
        let d = (0..=n).map(|i| if i % 2 == 0 { 1.0 } else { 4.5 }).collect();
        (f, d)
    }

    #[test]
    fn a_drifted_zigzag_is_matched_vertex_for_vertex() {
        let (a, da) = zigzag(60, 0.0);
        let (b, db) = zigzag(60, 0.03);
        // Arc length alone is off by ~2 vertex spacings in the middle.
        assert!((a[30] - b[30]).abs() > 1.5 / 60.0);
        let w = warp(&a, &da, &b, &db, &CurveAlignOptions::default()).unwrap();
        for (j, x) in w.iter().enumerate() {
            assert!((x - a[j]).abs() < 1e-12, "vertex {j}: {x} vs {}", a[j]);
        }
    }

    /// A grid whose boundary wobbles (distinct corner angles), and a gently bent copy.
    fn wobbly_pair() -> (crate::mesh::Mesh, crate::mesh::Mesh) {
        let g = crate::mesh::shapes::grid(12);
        let pos: Vec<crate::mesh::P3> = g
            .positions()
            .iter()
            .map(|p| {
                let w = (17.0 * p.x + 29.0 * p.y).sin() * 0.02;
                crate::mesh::P3::new(p.x + w, p.y - w, 0.0)
            })
            .collect();
        let s = g.with_positions(pos).unwrap();
        let bent = s.positions().iter().map(|p| crate::mesh::P3::new(p.x, p.y, 0.15 * (p.x * p.x))).collect();
        let t = s.with_positions(bent).unwrap();
        (s, t)
    }

    #[test]
    fn a_turned_copy_of_a_loop_is_found_and_an_aligned_one_is_left() {
        let (s, t) = wobbly_pair();
        let ring: Vec<crate::mesh::VertexId> =
            crate::topology::boundary_loops(&s)[0].iter().map(|&h| s.tail(h)).collect();
        let mut turned = ring.clone();
        turned.rotate_left(7);
        let r = loop_rotation(&s, &ring, &t, &turned).expect("a rotation");
        assert_eq!(turned[r], ring[0]);
        assert_eq!(loop_rotation(&s, &ring, &t, &ring), None);
    }

    #[test]
    fn warped_fractions_increase_strictly() {
        let (a, da) = zigzag(40, 0.0);
        let (b, db) = zigzag(97, -0.04);
        let w = warp(&a, &da, &b, &db, &CurveAlignOptions::default()).unwrap();
        assert_eq!(w.len(), 97);
        assert_eq!(w[0], 0.0);
        assert!(w.windows(2).all(|p| p[1] > p[0]), "{w:?}");
        assert!(*w.last().unwrap() < 1.0);
    }

    /// A curve across the middle of the wobbly grid, cut on the grid and on a copy whose
    /// vertices crowd towards one end: each side is warped on its own, and afterwards the two
    /// sides of the curve put every vertex at the same place (one side's fractions mirror the
    /// other's).
    #[test]
    fn both_sides_of_an_open_curve_agree() {
        use super::super::feature_cut::feature_cut;
        use super::super::features::{Curve, CurveKind};
        let (s, _) = wobbly_pair();
        // Row 6 of the 13 x 13 grid, away from the boundary.
        let row: Vec<crate::mesh::VertexId> = (2..11).map(|i| crate::mesh::VertexId(6 * 13 + i)).collect();
        for w in row.windows(2) {
            assert!(s.vertex_neighbors(w[0]).any(|x| x == w[1]), "the row is an edge path");
        }
        let crowded = s
            .positions()
            .iter()
            .map(|p| crate::mesh::P3::new(p.x * p.x, p.y + 0.1 * (9.0 * p.x).sin(), 0.3 * p.x * p.y))
            .collect();
        let t = s.with_positions(crowded).unwrap();
        let curves = [Curve { vertices: row.clone(), kind: CurveKind::Open }];
        let (sc, tc) = (
            feature_cut(&s, &curves, &[(0, false)], None, None).unwrap(),
            feature_cut(&t, &curves, &[(0, false)], None, None).unwrap(),
        );
        let ft = align_fractions(&sc, &tc, &CurveAlignOptions::default());
        let sides: Vec<usize> = (0..tc.sides.len()).filter(|&k| tc.sides[k].kind == SideKind::Curve(0)).collect();
        assert_eq!(sides.len(), 2, "an open curve has two sides");
        let (a, b) = (&ft[sides[0]], &ft[sides[1]]);
        let e = a.len();
        assert_eq!(b.len(), e);
        for i in 1..e {
            assert!((a[i] - (1.0 - b[e - i])).abs() < 1e-12, "vertex {i}: {} against {}", a[i], 1.0 - b[e - i]);
        }
        assert!(a.windows(2).all(|p| p[1] > p[0]) && b.windows(2).all(|p| p[1] > p[0]));
    }
}
