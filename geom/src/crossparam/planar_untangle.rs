//! Untangling a planar embedding with fixed boundary, for [`super::untangle`]: free vertices
//! of inverted faces move into the kernels of their stars, or to the points that maximize their
//! stars' smallest normalized area (Freitag & Plassmann 2000); and the ring of a held interior
//! vertex can be spread around it as in the source.

use crate::mesh::{FaceId, Mesh, VertexId};
use crate::param::Uv;

pub(crate) use crate::planar::triangle_area2 as signed_area;

/// Sweeps of [`kernel_sweeps`] at most.
const KERNEL_SWEEPS: usize = 30;

/// Moves every free vertex whose star is inverted into the kernel of its 1-ring polygon (the
/// points that see every ring edge on the chart's side), found by cyclic projection onto the
/// ring edges' half-planes with a small margin. Returns true when no star is inverted.
pub(crate) fn kernel_sweeps(m: &Mesh, uv: &mut [Uv], held: &[bool], sign: f64) -> bool {
    let orient = |a: Uv, b: Uv, c: Uv| sign * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
    let mut last = usize::MAX;
    let mut stalled = 0;
    for _ in 0..KERNEL_SWEEPS {
        let mut inverted = 0;
        for v in 0..m.n_vertices() {
            if held[v] {
                continue;
            }
            let ring: Vec<(Uv, Uv)> =
                m.outgoing(VertexId::from_idx(v)).map(|h| (uv[m.head(h).idx()], uv[m.head(h.next()).idx()])).collect();
            if ring.iter().all(|&(a, b)| orient(a, b, uv[v]) > 0.0) {
                continue;
            }
            inverted += 1;
            let k = ring.len() as f64;
            let mut p = ring.iter().fold([0.0; 2], |s, (a, _)| [s[0] + a[0] / k, s[1] + a[1] / k]);
            for _ in 0..16 {
                let mut inside = true;
                for &(a, b) in &ring {
                    let d = [b[0] - a[0], b[1] - a[1]];
                    let len = d[0].hypot(d[1]);
                    if len == 0.0 {
                        continue;
                    }
                    // Unit normal towards the side where orient(a, b, .) > 0.
                    let nrm = [-d[1] * sign / len, d[0] * sign / len];
                    let gap = (p[0] - a[0]) * nrm[0] + (p[1] - a[1]) * nrm[1] - 1e-3 * len;
                    if gap < 0.0 {
                        p = [p[0] - nrm[0] * gap, p[1] - nrm[1] * gap];
                        inside = false;
                    }
                }
                if inside {
                    break;
                }
            }
            uv[v] = p;
        }
        if inverted == 0 {
            return true;
        }
        // Stop when the count of inverted stars has not fallen for five sweeps.
        stalled = if inverted < last { 0 } else { stalled + 1 };
        last = last.min(inverted);
        if stalled >= 5 {
            return false;
        }
    }
    false
}

/// Sweeps of [`untangle_planar`] at most.
const PLANAR_SWEEPS: usize = 40;

/// Optimization-based untangling in the plane (Freitag & Plassmann 2000): each free vertex of
/// an inverted face (and its neighbours) moves to the point that maximizes the smallest
/// normalized signed area of its star, `σ_f(x) / |b - a|²` for the star face `(x, a, b)`: a 2D
/// linear program (maximize `t` with `σ_f(x) ≥ t |b - a|²`), solved exactly by taking the best
/// point where three constraints are tight. Unlike the kernel of the star, this point exists
/// when the kernel is empty, so sweeps make progress while neighbours are still folded.
/// Returns true when no face is inverted.
pub(crate) fn untangle_planar(m: &Mesh, uv: &mut [Uv], held: &[bool], sign: f64) -> bool {
    let orient = |a: Uv, b: Uv, c: Uv| sign * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]));
    let inverted = |uv: &[Uv]| -> Vec<FaceId> {
        (0..m.n_faces())
            .map(FaceId::from_idx)
            .filter(|&f| {
                let t = m.face(f).map(|v| uv[v.idx()]);
                orient(t[0], t[1], t[2]) <= 0.0
            })
            .collect()
    };
    let mut bad = inverted(uv);
    for _ in 0..PLANAR_SWEEPS {
        if bad.is_empty() {
            return true;
        }
        let mut active: Vec<VertexId> = Vec::new();
        for &f in &bad {
            for v in m.face(f) {
                active.push(v);
                active.extend(m.vertex_neighbors(v));
            }
        }
        active.sort_unstable();
        active.dedup();
        for v in active {
            if held[v.idx()] {
                continue;
            }
            // Constraint k: σ_k(x) / |b - a|² = g·x + c, for the ring edge (a, b).
            let cons: Vec<([f64; 2], f64)> = m
                .outgoing(v)
                .filter_map(|h| {
                    let (a, b) = (uv[m.head(h).idx()], uv[m.head(h.next()).idx()]);
                    let l2 = (b[0] - a[0]).powi(2) + (b[1] - a[1]).powi(2);
                    if l2 <= 0.0 {
                        return None;
                    }
                    // orient(a, b, x) = sign((b - a) x (x - a)).
                    let g = [-sign * (b[1] - a[1]) / l2, sign * (b[0] - a[0]) / l2];
                    Some((g, -(g[0] * a[0] + g[1] * a[1])))
                })
                .collect();
            let worst = |x: Uv| cons.iter().map(|(g, c)| g[0] * x[0] + g[1] * x[1] + c).fold(f64::INFINITY, f64::min);
            let mut best = (worst(uv[v.idx()]), uv[v.idx()]);
            let k = cons.len();
            for i in 0..k {
                for j in i + 1..k {
                    for l in j + 1..k {
                        // g_i·x + c_i = g_j·x + c_j = g_l·x + c_l.
                        let (gi, gj, gl) = (cons[i].0, cons[j].0, cons[l].0);
                        let r1 = [gi[0] - gj[0], gi[1] - gj[1], cons[j].1 - cons[i].1];
                        let r2 = [gi[0] - gl[0], gi[1] - gl[1], cons[l].1 - cons[i].1];
                        let det = r1[0] * r2[1] - r1[1] * r2[0];
                        if det.abs() < 1e-300 {
                            continue;
                        }
                        let x = [(r1[2] * r2[1] - r1[1] * r2[2]) / det, (r1[0] * r2[2] - r1[2] * r2[0]) / det];
                        let w = worst(x);
                        if w.is_finite() && w > best.0 {
                            best = (w, x);
                        }
                    }
                }
            }
            uv[v.idx()] = best.1;
        }
        bad = inverted(uv);
    }
    bad.is_empty()
}

/// Places the ring of held interior vertex `h` around it as the source ring's angles (scaled to
/// a full turn) at the ring's smallest current radius, turned to match the current ring best,
/// and holds it there. A star at a sharp tip whose ring bunches on one side folds in 3D although
/// it is valid in the chart.
pub(crate) fn spread_ring(m: &Mesh, h: VertexId, uv: &mut [Uv], held: &mut [bool], sign: f64) {
    let ring: Vec<VertexId> = m.outgoing(h).map(|e| m.head(e)).collect();
    if ring.len() < 3 || ring.iter().any(|w| held[w.idx()]) {
        return;
    }
    let c = m.position(h);
    let ang: Vec<f64> = (0..ring.len())
        .map(|j| {
            let (a, b) = (m.position(ring[j]) - c, m.position(ring[(j + 1) % ring.len()]) - c);
            a.cross(&b).norm().atan2(a.dot(&b))
        })
        .collect();
    let total: f64 = ang.iter().sum();
    let o = uv[h.idx()];
    let cur: Vec<(f64, f64)> = ring
        .iter()
        .map(|w| {
            let d = [uv[w.idx()][0] - o[0], uv[w.idx()][1] - o[1]];
            (d[1].atan2(d[0]), d[0].hypot(d[1]))
        })
        .collect();
    let r = cur.iter().map(|x| x.1).fold(f64::INFINITY, f64::min);
    if !(r.is_finite() && r > 0.0 && total > 0.0) {
        return;
    }
    let mut phi = Vec::with_capacity(ring.len());
    let mut acc = 0.0;
    for a in &ang {
        phi.push(sign * acc * std::f64::consts::TAU / total);
        acc += a;
    }
    // Rotation: circular mean of the current angles minus the new ones.
    let (sx, sy) = cur.iter().zip(&phi).fold((0.0, 0.0), |(x, y), (c, p)| (x + (c.0 - p).cos(), y + (c.0 - p).sin()));
    let off = sy.atan2(sx);
    for (w, p) in ring.iter().zip(&phi) {
        uv[w.idx()] = [o[0] + r * (p + off).cos(), o[1] + r * (p + off).sin()];
        held[w.idx()] = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::P3;

    /// A 5x5 grid of the unit square with its boundary held.
    fn grid() -> (Mesh, Vec<Uv>, Vec<bool>) {
        let n = 5;
        let mut pos = Vec::new();
        let mut tris = Vec::new();
        for j in 0..n {
            for i in 0..n {
                pos.push(P3::new(i as f64, j as f64, 0.0));
            }
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let a = (j * n + i) as u32;
                tris.push([a, a + 1, a + n as u32 + 1]);
                tris.push([a, a + n as u32 + 1, a + n as u32]);
            }
        }
        let m = Mesh::from_triangles(pos.clone(), &tris).unwrap();
        let uv: Vec<Uv> = pos.iter().map(|p| [p.x, p.y]).collect();
        let held = (0..n * n).map(|k| k % n == 0 || k % n == n - 1 || k / n == 0 || k / n == n - 1).collect();
        (m, uv, held)
    }

    fn inverted(m: &Mesh, uv: &[Uv]) -> usize {
        (0..m.n_faces()).filter(|&f| signed_area(m.face(FaceId::from_idx(f)).map(|v| uv[v.idx()])) <= 0.0).count()
    }

    #[test]
    fn a_vertex_pushed_across_its_ring_is_pulled_back() {
        let (m, mut uv, held) = grid();
        // Vertex (1, 1) pushed past (2, 2), and (2, 2) past (3, 3): a fold two vertices deep.
        uv[6] = [2.6, 2.4];
        uv[12] = [3.4, 3.6];
        assert!(inverted(&m, &uv) > 0);
        let mut a = uv.clone();
        assert!(kernel_sweeps(&m, &mut a, &held, 1.0));
        assert_eq!(inverted(&m, &a), 0);
        let mut b = uv.clone();
        assert!(untangle_planar(&m, &mut b, &held, 1.0));
        assert_eq!(inverted(&m, &b), 0);
        // Held vertices never move.
        for (k, h) in held.iter().enumerate() {
            if *h {
                assert_eq!(a[k], uv[k]);
                assert_eq!(b[k], uv[k]);
            }
        }
    }

    #[test]
    fn a_bunched_ring_is_spread_around_its_centre() {
        let (m, mut uv, mut held) = grid();
        // Centre vertex 12 held; its ring squeezed into one quadrant.
        held[12] = true;
        let ring: Vec<VertexId> = m.outgoing(VertexId(12)).map(|h| m.head(h)).collect();
        for (k, w) in ring.iter().enumerate() {
            let t = 0.2 * k as f64;
            uv[w.idx()] = [2.0 + 0.5 * t.cos(), 2.0 + 0.5 * t.sin()];
        }
        spread_ring(&m, VertexId(12), &mut uv, &mut held, 1.0);
        let star_ok = m
            .outgoing(VertexId(12))
            .all(|h| signed_area([uv[12], uv[m.head(h).idx()], uv[m.head(h.next()).idx()]]) > 0.0);
        assert!(star_ok);
        assert!(ring.iter().all(|w| held[w.idx()]));
    }
}
