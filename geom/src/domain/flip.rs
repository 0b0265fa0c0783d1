//! Path flipping, the second post-process of Kraevoy & Sheffer 2004 (section 4.3), applied to
//! both methods as Kwok et al. do for their comparison: a path between two triangular patches
//! is replaced by the other diagonal of the quadrilateral they form when the layout's patches
//! get better shaped, i.e. the geodesic Delaunay test fails: the two angles facing the path,
//! measured between the paths at the opposite anchors and averaged over both meshes, sum to
//! more than π. Low-valence anchors, whose patches have corners near π, are the usual cause.
//!
//! A flip lifts the path on both meshes and traces the new diagonal inside the quadrilateral
//! (leaving each opposite anchor inside its patch corner), so the rotation system changes the
//! same way on both and the layouts stay consistent; when either trace fails both meshes keep
//! the old path. Anchors keep at least three paths, and no second path is made between two
//! anchors already linked.

use super::tracer::{Half, Tracer};
use super::walks::{Walk, walks};
use crate::error::Result;
use crate::mesh::{P3, V3};
use crate::progress::Progress;
use serde::{Deserialize, Serialize};

/// Angles between paths are measured towards the point a quarter of each path away, which
/// reflects the patch's shape rather than the first step's wiggle.
const SHAPE_REACH: f64 = 0.25;

/// Options of [`flip_paths`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct FlipOptions {
    /// Sweeps over all paths (0 disables flipping).
    pub rounds: usize,
    /// Try a flip when the facing angles sum to more than π times this.
    pub threshold: f64,
    /// Only where the quadrilateral's angles at the path's ends stay below π times this
    /// (convex, so the new diagonal runs inside it, away from the old ends).
    pub max_end_angle: f64,
    /// Also require the new diagonal to be shorter than the old path on both meshes.
    pub shorter_only: bool,
}

impl Default for FlipOptions {
    fn default() -> Self {
        Self { rounds: 3, threshold: 0.9, max_end_angle: 0.9, shorter_only: true }
    }
}

/// Output of [`flip_paths`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FlipResult {
    pub flipped: usize,
    /// Flips that passed the test but could not be traced on both meshes.
    pub refused: usize,
}

/// Unit direction in which half `h` leaves its anchor, in the anchor's tangent plane (normal
/// `n`): towards the first path point `reach` times its length away (0: the first step).
pub(crate) fn leaving_direction(t: &Tracer, h: Half, n: V3, reach: f64) -> Option<V3> {
    let p = &t.paths()[(h / 2) as usize];
    let mesh = t.mesh();
    let pts: Vec<P3> = if h.is_multiple_of(2) {
        p.points.iter().map(|s| s.position(mesh)).collect()
    } else {
        p.points.iter().rev().map(|s| s.position(mesh)).collect()
    };
    let origin = *pts.first()?;
    let reach = reach * p.length;
    let mut walked = 0.0;
    let mut target = *pts.last()?;
    for w in pts.windows(2) {
        walked += (w[1] - w[0]).norm();
        if walked >= reach {
            target = w[1];
            break;
        }
    }
    let d = target - origin;
    let d = d - n * n.dot(&d);
    let l = d.norm();
    (l > 0.0).then(|| d / l)
}

/// Area-weighted vertex normal of an anchor.
pub(crate) fn anchor_normal(t: &Tracer, a: u32) -> V3 {
    let mesh = t.mesh();
    let v = t.anchors()[a as usize];
    let n: V3 = mesh.vertex_faces(v).map(|f| mesh.face_normal_raw(f)).sum();
    let l = n.norm();
    if l > 0.0 { n / l } else { V3::z() }
}

/// Angle of walk `w`'s corner `i`: counter-clockwise from its outgoing half to its reversed
/// incoming half, in the tangent plane.
fn corner_angle(t: &Tracer, w: &Walk, i: usize) -> Option<f64> {
    let n_h = w.halves.len();
    let a = t.half_start(w.halves[i]);
    let n = anchor_normal(t, a);
    let out = leaving_direction(t, w.halves[i], n, SHAPE_REACH)?;
    let back = leaving_direction(t, w.halves[(i + n_h - 1) % n_h] ^ 1, n, SHAPE_REACH)?;
    // The region lies to the right of its halves: clockwise from `out` to `back` seen from
    // outside, i.e. counter-clockwise from `back` to `out`.
    let ang = n.dot(&back.cross(&out)).atan2(back.dot(&out));
    Some(if ang < 0.0 { ang + std::f64::consts::TAU } else { ang })
}

/// The walk containing half `h`, rotated so that it starts with `h`.
fn walk_of(all: &[Walk], h: Half) -> Option<Walk> {
    all.iter().find_map(|w| {
        let i = w.halves.iter().position(|&x| x == h)?;
        let mut halves = w.halves.clone();
        halves.rotate_left(i);
        Some(Walk { halves })
    })
}

/// Sum of the two angles facing path `p` on tracer `t`, with the quadrilateral's far corners.
/// `None` when the quadrilateral is not convex enough for the new diagonal to run inside it
/// (its angle at either end of `p` reaches `max_end_angle`).
fn facing_angles(t: &Tracer, p: u32, max_end_angle: f64) -> Option<(f64, u32, u32, Walk, Walk)> {
    let all = walks(t);
    let w1 = walk_of(&all, 2 * p)?;
    let w2 = walk_of(&all, 2 * p + 1)?;
    if w1.halves.len() != 3 || w2.halves.len() != 3 || w1.halves.contains(&(2 * p + 1)) {
        return None;
    }
    // w1 = [a->b, b->c, c->a], w2 = [b->a, a->d, d->b]: corner 0 of w1 is a, of w2 is b.
    let at_a = corner_angle(t, &w1, 0)? + corner_angle(t, &w2, 1)?;
    let at_b = corner_angle(t, &w1, 1)? + corner_angle(t, &w2, 0)?;
    if at_a >= max_end_angle || at_b >= max_end_angle {
        return None;
    }
    let (c, d) = (t.half_start(w1.halves[2]), t.half_start(w2.halves[2]));
    Some((corner_angle(t, &w1, 2)? + corner_angle(t, &w2, 2)?, c, d, w1, w2))
}

/// Flips paths on both layouts (identical path ids and rotation systems) while the test above
/// asks for it. Returns how many paths were flipped.
///
/// # Errors
/// `Cancelled`; `Error::Internal` if a lifted path cannot be restored.
pub fn flip_paths(
    st: &mut Tracer,
    tt: &mut Tracer,
    opts: &FlipOptions,
    progress: &mut dyn Progress,
) -> Result<FlipResult> {
    let mut res = FlipResult::default();
    let max_end = std::f64::consts::PI * opts.max_end_angle;
    for _ in 0..opts.rounds {
        let mut this_round = 0;
        for p in 0..st.paths().len() as u32 {
            progress.check()?;
            let (a, b) = (st.paths()[p as usize].a, st.paths()[p as usize].b);
            if st.is_fixed(p) || st.rotation(a).len() <= 3 || st.rotation(b).len() <= 3 {
                continue;
            }
            let (Some((s_sum, c, d, w1, w2)), Some((t_sum, c2, d2, tw1, tw2))) =
                (facing_angles(st, p, max_end), facing_angles(tt, p, max_end))
            else {
                continue;
            };
            if c != c2 || d != d2 || c == d || [a, b].contains(&c) || [a, b].contains(&d) {
                continue;
            }
            if 0.5 * (s_sum + t_sum) <= std::f64::consts::PI * opts.threshold {
                continue;
            }
            let linked = st.paths().iter().any(|q| (q.a == c && q.b == d) || (q.a == d && q.b == c));
            if linked {
                continue;
            }
            // How long the new path may be, as a multiple of the old one.
            let growth = if opts.shorter_only { 1.0 } else { f64::INFINITY };
            let too_long = |new: f64, old: f64| new >= growth * old;
            // The new path c -> d leaves c inside w1's corner and reaches d inside w2's.
            let corner = |t: &Tracer, w: &Walk| w.sector(t, 2);
            let (sa_s, sb_s) = (corner(st, &w1), corner(st, &w2));
            let (sa_t, sb_t) = (corner(tt, &tw1), corner(tt, &tw2));
            let Some(old_s) = st.replace(p, c, d, sa_s, sb_s)? else {
                res.refused += 1;
                continue;
            };
            if too_long(st.paths()[p as usize].length, old_s.length) {
                st.restore(p, old_s)?;
                continue;
            }
            let Some(old_t) = tt.replace(p, c, d, sa_t, sb_t)? else {
                st.restore(p, old_s)?;
                res.refused += 1;
                continue;
            };
            if too_long(tt.paths()[p as usize].length, old_t.length) {
                st.restore(p, old_s)?;
                tt.restore(p, old_t)?;
                continue;
            }
            this_round += 1;
        }
        res.flipped += this_round;
        if this_round == 0 {
            break;
        }
    }
    Ok(res)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::greedy::greedy_layout;
    use crate::domain::tracer::TraceRequest;
    use crate::domain::walks::is_complete;
    use crate::domain::{LayoutOptions, patches_of};
    use crate::mesh::{Mesh, P3, VertexId, shapes};
    use crate::progress::NoProgress;

    /// Farthest-point anchors on an icosphere stretched along x by `sx`.
    fn stretched(sx: f64, k: usize) -> (Mesh, Vec<VertexId>) {
        let m = shapes::icosphere(3);
        let m = m.with_positions(m.positions().iter().map(|p| P3::new(p.x * sx, p.y, p.z)).collect()).unwrap();
        let mut a = vec![VertexId(0)];
        let mut d: Vec<f64> = m.positions().iter().map(|p| (p - m.positions()[0]).norm()).collect();
        while a.len() < k {
            let i = (0..d.len()).max_by(|&x, &y| d[x].total_cmp(&d[y])).unwrap();
            a.push(VertexId::from_idx(i));
            for (j, p) in m.positions().iter().enumerate() {
                d[j] = d[j].min((p - m.positions()[i]).norm());
            }
        }
        (m, a)
    }

    /// Four anchors on a sphere stretched along y: `x` and `y` linked twice (`A` over the top,
    /// `B` underneath), `c` in front and `z` behind, each linked to `x` and `y`. `c` and `z`
    /// have two paths each, and the only diagonal across `A`, `c–z`, is longer than `A`.
    fn lens(t: &mut Tracer, m: &Mesh) -> u32 {
        let band = |up: bool| -> Vec<bool> {
            (0..m.n_faces())
                .map(|f| {
                    let [p, q, r] = m.face_points(crate::FaceId::from_idx(f));
                    let c = (p.coords + q.coords + r.coords) / 3.0;
                    c.y.abs() < 0.25 && if up { c.z > -0.05 } else { c.z < 0.05 }
                })
                .collect()
        };
        let (top, bottom) = (band(true), band(false));
        let a = t.trace_insert(&TraceRequest { a: 0, b: 1, faces: Some(&top), ..Default::default() }).unwrap();
        t.trace_insert(&TraceRequest { a: 0, b: 1, faces: Some(&bottom), ..Default::default() }).unwrap().unwrap();
        for (p, q) in [(2, 0), (2, 1), (3, 0), (3, 1)] {
            t.trace_insert(&TraceRequest { a: p, b: q, ..Default::default() }).unwrap().unwrap();
        }
        a.unwrap()
    }

    #[test]
    fn a_longer_diagonal_is_refused() {
        let m = shapes::icosphere(3);
        let m = m.with_positions(m.positions().iter().map(|p| P3::new(p.x, 3.0 * p.y, p.z)).collect()).unwrap();
        let nearest = |q: P3| {
            let i = (0..m.n_vertices())
                .min_by(|&i, &j| (m.positions()[i] - q).norm().total_cmp(&(m.positions()[j] - q).norm()))
                .unwrap();
            VertexId::from_idx(i)
        };
        let anchors = [
            nearest(P3::new(1.0, 0.0, 0.0)),
            nearest(P3::new(-1.0, 0.0, 0.0)),
            nearest(P3::new(0.0, 1.5, 0.85)),
            nearest(P3::new(0.0, -1.5, 0.85)),
        ];
        let t_mesh = m.with_positions(m.positions().iter().map(|p| P3::from(p.coords * 1.5)).collect()).unwrap();
        let mut s = Tracer::new(&m, &anchors, &Default::default()).unwrap();
        let mut t = Tracer::new(&t_mesh, &anchors, &Default::default()).unwrap();
        let a = lens(&mut s, &m);
        assert_eq!(lens(&mut t, &t_mesh), a);
        assert!(is_complete(&s, 2) && is_complete(&t, 2), "the lens layout is a triangulation");
        let r = flip_paths(&mut s, &mut t, &FlipOptions::default(), &mut NoProgress).unwrap();
        assert_eq!((r.flipped, s.rotation(2).len(), s.rotation(3).len()), (0, 2, 2));
    }

    #[test]
    fn flips_keep_both_layouts_complete_and_identical() {
        let mut total = 0;
        for (sx, k) in [(1.0, 8), (2.5, 9), (4.0, 10), (3.0, 12)] {
            let (m, a) = stretched(sx, k);
            // The target: the same surface scaled, so lengths and angles agree up to scale.
            let t_mesh = m.with_positions(m.positions().iter().map(|p| P3::from(p.coords * 1.5)).collect()).unwrap();
            let mut s = Tracer::new(&m, &a, &Default::default()).unwrap();
            let mut t = Tracer::new(&t_mesh, &a, &Default::default()).unwrap();
            greedy_layout(&mut s, &mut t, 2, &LayoutOptions::default(), &mut NoProgress).unwrap();
            let before: f64 = s.paths().iter().map(|p| p.length).sum();
            let r = flip_paths(&mut s, &mut t, &FlipOptions::default(), &mut NoProgress).unwrap();
            total += r.flipped;
            assert!(is_complete(&s, 2) && is_complete(&t, 2), "flips keep a triangulation");
            assert_eq!(walks(&s), walks(&t), "the same flips on both meshes");
            assert_eq!(patches_of(&s).len(), 2 * k - 4, "Euler: 2V - 4 triangles on a sphere");
            let after: f64 = s.paths().iter().map(|p| p.length).sum();
            assert!(after <= before + 1e-12, "every flip shortens a path");
        }
        assert!(total > 0, "a greedy layout on stretched spheres has paths to flip");
    }
}
