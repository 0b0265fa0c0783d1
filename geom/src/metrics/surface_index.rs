//! Nearest-surface queries as `meshmetrics.py` makes them: the candidate faces of a query are
//! those whose centroids are among its `k = 24` nearest (k-d tree, `kiddo`), and the closest
//! point on each candidate comes from Ericson's region test, evaluated in the evaluator's order
//! (interior, then edge regions AB, AC, BC, then vertex regions A, B, C), keeping the first
//! strictly closer candidate. A distance is exact, or slightly too large when the true closest
//! face is not among the candidates: exactly the evaluator's definition.
//!
//! Batches of queries are answered in Morton order from radius searches shared by runs of
//! nearby points: small balls a few faces wide that prove each answer without the k nearest
//! ([`small_ball`]), or, where faces vary too much in size, balls that hold every point's k
//! nearest (`search_in_order`).

use crate::error::{Error, Result};
use crate::mesh::{FaceId, Mesh, P3, V3};
use kiddo::{ImmutableKdTree, SquaredEuclidean};
use rayon::prelude::*;
use std::num::NonZeroUsize;

/// Consecutive (Morton-ordered) queries handled by one task.
const SEARCH_RUN: usize = 8192;

/// Candidates per query, as in the evaluator.
pub const CANDIDATES: usize = 24;

/// Most points answered from one radius search (see `search_in_order`).
const BLOCK: usize = 64;

/// A k-nearest-centroid surface index.
pub struct SurfaceIndex<'m> {
    mesh: &'m Mesh,
    tree: ImmutableKdTree<f64, 3>,
    k: NonZeroUsize,
    /// Per face, an upper bound on the distance from its centroid to its points.
    radius: Vec<f64>,
    /// Face centroids, as in the tree.
    centroids: Vec<[f64; 3]>,
    /// The face-size tiers of distance-only searches ([`small_ball`]), unless too many faces
    /// are large for them to pay.
    tiers: Option<Tiers>,
}

mod small_ball;
mod tiers;

use tiers::Tiers;

/// One query's answer.
#[derive(Debug, Clone, Copy)]
pub struct Nearest {
    pub distance: f64,
    pub face: FaceId,
    pub point: P3,
}

#[inline]
fn guard(x: f64) -> f64 {
    if x.abs() < 1e-300 { 1e-300 } else { x }
}

/// Ericson's closest point on triangle (a, b, c), in the evaluator's evaluation order.
pub(crate) fn closest_point_on_triangle(p: P3, a: P3, b: P3, c: P3) -> P3 {
    let ab: V3 = b - a;
    let ac: V3 = c - a;
    let ap = p - a;
    let d1 = ab.dot(&ap);
    let d2 = ac.dot(&ap);
    let bp = p - b;
    let d3 = ab.dot(&bp);
    let d4 = ac.dot(&bp);
    let cp = p - c;
    let d5 = ab.dot(&cp);
    let d6 = ac.dot(&cp);
    let va = d3 * d6 - d5 * d4;
    let vb = d5 * d2 - d1 * d6;
    let vc = d1 * d4 - d3 * d2;
    let denom = guard(va + vb + vc);
    let v = vb / denom;
    let w = vc / denom;
    let mut res = a + ab * v + ac * w;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let t = d1 / guard(d1 - d3);
        res = a + ab * t;
    }
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / guard(d2 - d6);
        res = a + ac * t;
    }
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let t = (d4 - d3) / guard((d4 - d3) + (d5 - d6));
        res = b + (c - b) * t;
    }
    if d1 <= 0.0 && d2 <= 0.0 {
        res = a;
    }
    if d3 >= 0.0 && d4 <= d3 {
        res = b;
    }
    if d6 >= 0.0 && d5 <= d6 {
        res = c;
    }
    res
}

/// Face centroid as numpy computes `V[F].mean(axis=1)`.
pub(crate) fn centroid(p: [P3; 3]) -> P3 {
    P3::new((p[0].x + p[1].x + p[2].x) / 3.0, (p[0].y + p[1].y + p[2].y) / 3.0, (p[0].z + p[1].z + p[2].z) / 3.0)
}

/// The block of queries starting at `pts[start]`: it and the points right after it within
/// `within` of it, at most [`BLOCK`]. Returns the end (exclusive) and the largest distance.
fn block(pts: &[P3], start: usize, within: f64) -> (usize, f64) {
    let p0 = pts[start];
    let mut end = start + 1;
    let mut reach: f64 = 0.0;
    while end < pts.len() && end - start < BLOCK {
        let d = (pts[end] - p0).norm();
        if d > within {
            break;
        }
        reach = reach.max(d);
        end += 1;
    }
    (end, reach)
}

/// Index of the smallest of `d2` (the first on a tie); `d2` must not be empty.
fn argmin(d2: &[f64]) -> usize {
    let mut near = 0;
    for (c, d) in d2.iter().enumerate() {
        if *d < d2[near] {
            near = c;
        }
    }
    near
}

/// The faces that may be closer to a point than `best`, the distance to the face of its
/// nearest centroid `near`: those whose centroid distance minus radius does not exceed it,
/// tested on squares with more slack (a face that cannot be strictly closer may pass, none that
/// can is lost). `d2` are the squared centroid distances, `radius(c)` and `id(c)` the radius and
/// face of centroid `c`. Fills `maybe` with `(d2, face)` and returns the largest such `d2`.
fn contenders_of(
    d2: &[f64],
    near: usize,
    best: f64,
    radius: impl Fn(usize) -> f64,
    id: impl Fn(usize) -> u32,
    maybe: &mut Vec<(f64, u32)>,
) -> f64 {
    maybe.clear();
    let mut far: f64 = 0.0;
    for (c, &d) in d2.iter().enumerate() {
        let reach = best + radius(c);
        if c != near && d * (1.0 - 4e-9) <= reach * reach {
            maybe.push((d, id(c)));
            far = far.max(d);
        }
    }
    far
}

/// The `k`-th smallest of `d2` (its largest when it holds no more than `k`), selected in
/// `buf`.
fn kth_of(d2: &[f64], k: usize, buf: &mut Vec<f64>) -> f64 {
    if d2.len() > k {
        buf.clear();
        buf.extend_from_slice(d2);
        *buf.select_nth_unstable_by(k - 1, f64::total_cmp).1
    } else {
        d2.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }
}

impl<'m> SurfaceIndex<'m> {
    /// Builds the k-d tree of face centroids.
    ///
    /// # Errors
    /// `Error::Internal` if the tree cannot be built (no faces).
    pub fn new(mesh: &'m Mesh) -> Result<Self> {
        let mut radius = Vec::with_capacity(mesh.n_faces());
        let cents: Vec<[f64; 3]> = (0..mesh.n_faces())
            .map(|f| {
                let p = mesh.face_points(FaceId::from_idx(f));
                let c = centroid(p);
                let r = p.iter().map(|q| (q - c).norm()).fold(0.0, f64::max);
                // Inflated against rounding, so the pruning bound stays a true lower bound.
                radius.push(r * (1.0 + 1e-9) + 1e-300);
                [c.x, c.y, c.z]
            })
            .collect();
        let tree = ImmutableKdTree::new_from_slice(&cents).map_err(|e| Error::Internal(format!("k-d tree: {e:?}")))?;
        let k = NonZeroUsize::new(CANDIDATES.min(mesh.n_faces()))
            .ok_or_else(|| Error::Internal("mesh has no faces".into()))?;
        let tiers = Tiers::new(&cents, &radius)?;
        Ok(Self { mesh, tree, k, radius, centroids: cents, tiers })
    }

    /// The distances of [`SurfaceIndex::query`] for `pts`, visited in `order` (nearby points in
    /// turn, e.g. Morton order). Only the distance is returned, which is the minimum over the
    /// candidate set whatever its order, so the searches skip sorting.
    pub fn distances_in_order(&self, pts: &[P3], order: &[usize]) -> Vec<f64> {
        let mut out = vec![0.0; pts.len()];
        for (i, n) in self.search_chunks(pts, order, false) {
            out[i] = n.distance;
        }
        out
    }

    /// The distances of [`SurfaceIndex::query`] for every point, searched in Morton order.
    pub fn distances(&self, pts: &[P3]) -> Vec<f64> {
        self.distances_in_order(pts, &morton_order(pts))
    }

    /// `f`, and when `p` (a point of `f`) lies on one of its edges or at a corner (barycentric
    /// weight within 1e-9 of 0), the other faces around that edge or corner: the faces another
    /// tie-break (the evaluator's, in floating point) may take as nearest to `p`.
    pub fn tied_faces(&self, f: FaceId, p: &P3) -> Vec<FaceId> {
        let ([a, b, c], ids) = (self.mesh.face_points(f), self.mesh.face(f));
        let n = (b - a).cross(&(c - a));
        let nn = n.norm_squared();
        if nn == 0.0 || !nn.is_finite() {
            return vec![f];
        }
        let w = [
            (c - b).cross(&(p - b)).dot(&n) / nn,
            (a - c).cross(&(p - c)).dot(&n) / nn,
            (b - a).cross(&(p - a)).dot(&n) / nn,
        ];
        let zero: Vec<usize> = (0..3).filter(|&k| w[k].abs() <= 1e-9).collect();
        match zero.as_slice() {
            [] => vec![f],
            &[k] => {
                let (u, v) = (ids[(k + 1) % 3], ids[(k + 2) % 3]);
                self.mesh.vertex_faces(u).filter(|&g| self.mesh.face(g).contains(&v)).collect()
            }
            _ => {
                let k = (0..3).find(|k| !zero.contains(k)).unwrap_or(0);
                self.mesh.vertex_faces(ids[k]).collect()
            }
        }
    }

    /// [`SurfaceIndex::query`] for every point (face and point included, ties resolved in the
    /// candidates' distance order as the evaluator does), visited in Morton order.
    pub fn query_all(&self, pts: &[P3]) -> Vec<Nearest> {
        let mut out = vec![Nearest { distance: f64::INFINITY, face: FaceId(0), point: P3::origin() }; pts.len()];
        for (i, n) in self.search_chunks(pts, &morton_order(pts), true) {
            out[i] = n;
        }
        out
    }

    /// The searches of `order`, in runs of consecutive points spread over the thread pool
    /// (each run with its own scratch and hint; answers do not depend on the split).
    fn search_chunks(&self, pts: &[P3], order: &[usize], sorted: bool) -> Vec<(usize, Nearest)> {
        order
            .par_chunks(SEARCH_RUN)
            .flat_map_iter(|run| {
                let mut out = Vec::with_capacity(run.len());
                // The run's points copied in visiting order: the searches read them in sequence.
                let local: Vec<P3> = run.iter().map(|&i| pts[i]).collect();
                match &self.tiers {
                    Some(t) => self.search_small_ball(t, &local, sorted, |k, n| out.push((run[k], n))),
                    _ => self.search_in_order(&local, sorted, |k, n| out.push((run[k], n))),
                }
                out
            })
            .collect()
    }

    /// Runs the candidate search for `pts` in their order (nearby points in turn), handing each
    /// answer to `put` with the point's index.
    ///
    /// Queries are taken in blocks of nearby points. The block's first point `p0` has its k-th
    /// nearest centroid within `h`, the previous point's k-th distance plus the step between
    /// the points (triangle inequality). `h` admits into the block the following points within
    /// `h / 2` of `p0` (at most [`BLOCK`]); one radius search then gathers every centroid within
    /// `h + 2ρ` of `p0`, ρ the block's reach. A block point `q` has its k nearest within
    /// `dk(q) ≤ h + |q − p0|` of itself, so within `h + 2ρ` of `p0`: its k nearest of that
    /// gathered set (a few k centroids on a surface) are its k nearest overall. The tree is
    /// searched once per block, and with a k-nearest search only where no previous point gives
    /// `h` (a run's first point, or a step longer than half the previous k-th distance, which
    /// would make `h` loose); the block's last point's k-th distance is the next `h`'s start.
    fn search_in_order(&self, pts: &[P3], sorted: bool, mut put: impl FnMut(usize, Nearest)) {
        let mut scratch = self.tree.create_scratch::<SquaredEuclidean<f64>>();
        let mut hint: Option<(P3, f64)> = None;
        let mut gathered: Vec<([f64; 3], u32)> = Vec::new();
        let mut cand: Vec<(f64, u32)> = Vec::new();
        let mut d2: Vec<f64> = Vec::new();
        let mut kth_buf: Vec<f64> = Vec::new();
        let k = self.k.get();
        let mut start = 0;
        while start < pts.len() {
            let p0 = pts[start];
            let q = [p0.x, p0.y, p0.z];
            // An upper bound on p0's k-th centroid distance: the previous point's plus the step
            // between them, or (no previous point) a k-d tree search that answers p0 itself.
            // A far step (a jump of the visiting order) would make that bound loose and the
            // radius search large: such a point takes the k-d tree search.
            let near_hint = hint.map(|(prev, dk)| (dk, (p0 - prev).norm())).filter(|&(dk, step)| step <= 0.5 * dk);
            let Some(bound) = near_hint.map(|(dk, step)| (dk + step) * (1.0 + 1e-9)) else {
                let query = self.tree.query(&q).nearest_n::<SquaredEuclidean<f64>>(self.k);
                let first = if sorted {
                    query.with_scratch(&mut scratch).execute()
                } else {
                    query.unsorted().with_scratch(&mut scratch).execute()
                };
                put(start, self.best_of(&p0, first.iter().map(|n| (n.item, n.distance))));
                let dk = first.iter().map(|n| n.distance).fold(f64::NEG_INFINITY, f64::max).sqrt();
                hint = dk.is_finite().then_some((p0, dk));
                start += 1;
                continue;
            };
            // The block: p0 and the following points within bound / 2 of it.
            let (end, reach) = block(pts, start, 0.5 * bound);
            let r = (bound + 2.0 * reach) * (1.0 + 1e-9);
            let ball = self.tree.query(&q).within::<SquaredEuclidean<f64>>(r * r).unsorted().execute();
            if ball.len() < k {
                // Never by the triangle inequality; degenerate input takes a k-d tree search.
                hint = None;
                continue;
            }
            gathered.clear();
            gathered.extend(ball.iter().map(|n| (self.centroids[n.item as usize], n.item)));
            for (j, &p) in pts.iter().enumerate().take(end).skip(start) {
                d2.clear();
                d2.extend(gathered.iter().map(|(c, _)| {
                    let (dx, dy, dz) = (c[0] - p.x, c[1] - p.y, c[2] - p.z);
                    dx * dx + dy * dy + dz * dz
                }));
                let best = if sorted {
                    // The k-th smallest squared distance: the candidates are those not beyond it
                    // (every centroid tied at exactly that distance is admitted).
                    let kth = kth_of(&d2, k, &mut kth_buf);
                    cand.clear();
                    cand.extend(d2.iter().zip(&gathered).filter(|(d, _)| **d <= kth).map(|(d, g)| (*d, g.1)));
                    cand.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
                    cand.truncate(k);
                    self.best_of(&p, cand.iter().map(|&(d, item)| (item, d)))
                } else {
                    self.nearest_distance_among(&p, &gathered, &d2, k, &mut cand, &mut kth_buf)
                };
                put(j, best);
                if j + 1 == end && d2.len() >= k {
                    hint = Some((p, kth_of(&d2, k, &mut kth_buf).sqrt()));
                }
            }
            start = end;
        }
    }

    /// The distance of [`SurfaceIndex::query`] for `p` (its face and point may be another
    /// candidate's on a tie), given `gathered`, a superset of its `k` nearest centroids, with
    /// their squared distances `d2`.
    ///
    /// The nearest centroid's face is tested first. Only the gathered faces whose lower bound
    /// (centroid distance minus radius) does not exceed that distance can be closer; when no
    /// more than `k - 1` centroids are strictly nearer than the farthest of them, all of them
    /// are among the `k` nearest, and the k-th distance (a selection over the gathered set) is
    /// not needed. Otherwise they are filtered by it. Either way the minimum is taken over the
    /// same candidates as the evaluator's.
    fn nearest_distance_among(
        &self,
        p: &P3,
        gathered: &[([f64; 3], u32)],
        d2: &[f64],
        k: usize,
        maybe: &mut Vec<(f64, u32)>,
        kth_buf: &mut Vec<f64>,
    ) -> Nearest {
        let near = argmin(d2);
        let best = self.best_of(p, std::iter::once((gathered[near].1, d2[near])));
        let radius = |c: usize| self.radius[gathered[c].1 as usize];
        let far = contenders_of(d2, near, best.distance, radius, |c| gathered[c].1, maybe);
        if maybe.is_empty() {
            return best;
        }
        let nearer = d2.iter().filter(|&&d| d < far).count();
        if nearer >= k {
            let kth = kth_of(d2, k, kth_buf);
            maybe.retain(|&(d, _)| d <= kth);
        }
        let rest = self.best_of(p, maybe.iter().map(|&(d, item)| (item, d)));
        if rest.distance < best.distance { rest } else { best }
    }

    /// Nearest point among the candidate faces.
    ///
    /// A candidate whose centroid distance minus its radius exceeds the best distance so far
    /// cannot be strictly closer, so its closest-point test is skipped: the answer (distance,
    /// face and point, ties included) is the same as testing every candidate.
    pub fn query(&self, p: &P3) -> Nearest {
        let cand = self.tree.query(&[p.x, p.y, p.z]).nearest_n::<SquaredEuclidean<f64>>(self.k).execute();
        self.best_of(p, cand.iter().map(|n| (n.item, n.distance)))
    }

    /// The closest of the candidates `(face, squared centroid distance)`, and of equally close
    /// ones the one with the nearest centroid: in ascending centroid order (the evaluator's),
    /// the first strictly closest; in any order, the same face unless centroids tie too.
    fn best_of(&self, p: &P3, cand: impl Iterator<Item = (u32, f64)>) -> Nearest {
        let mut best = Nearest { distance: f64::INFINITY, face: FaceId(0), point: *p };
        let mut best_d2 = f64::INFINITY;
        for (item, d2) in cand {
            let lower = d2.sqrt() * (1.0 - 1e-9) - self.radius[item as usize];
            if lower > best.distance {
                continue;
            }
            let f = FaceId(item);
            let [a, b, c] = self.mesh.face_points(f);
            let q = closest_point_on_triangle(*p, a, b, c);
            let d = (q - p).norm();
            if d < best.distance || (d == best.distance && d2 < best_d2) {
                best = Nearest { distance: d, face: f, point: q };
                best_d2 = d2;
            }
        }
        best
    }
}

/// Indices of `pts` sorted along a Z-order (Morton) curve of their bounding box.
pub(crate) fn morton_order(pts: &[P3]) -> Vec<usize> {
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in pts {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let spread = |x: u64| {
        // Interleave the low 21 bits with two zero bits each.
        let mut x = x & 0x1f_ffff;
        x = (x | (x << 32)) & 0x1f00000000ffff;
        x = (x | (x << 16)) & 0x1f0000ff0000ff;
        x = (x | (x << 8)) & 0x100f00f00f00f00f;
        x = (x | (x << 4)) & 0x10c30c30c30c30c3;
        (x | (x << 2)) & 0x1249249249249249
    };
    let q = |p: &P3, k: usize| {
        let w = hi[k] - lo[k];
        if w > 0.0 { (((p[k] - lo[k]) / w) * 2_097_151.0) as u64 } else { 0 }
    };
    let mut keyed: Vec<(u64, usize)> = pts
        .iter()
        .enumerate()
        .map(|(i, p)| (spread(q(p, 0)) | (spread(q(p, 1)) << 1) | (spread(q(p, 2)) << 2), i))
        .collect();
    keyed.sort_unstable();
    keyed.into_iter().map(|(_, i)| i).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    /// A point inside a face ties with nothing; on an edge with the face across it; at a corner
    /// with every face around that vertex.
    #[test]
    fn tied_faces_are_the_faces_around_an_edge_or_corner() {
        let m = shapes::icosphere(2);
        let index = SurfaceIndex::new(&m).unwrap();
        let f = FaceId(7);
        let [a, b, c] = m.face_points(f);
        let inside = P3::from((a.coords + b.coords + c.coords) / 3.0);
        assert_eq!(index.tied_faces(f, &inside), vec![f]);
        let on_edge = P3::from((a.coords + b.coords) / 2.0);
        let mut t = index.tied_faces(f, &on_edge);
        t.sort();
        let [u, v, _] = m.face(f);
        let mut want: Vec<FaceId> = m.vertex_faces(u).filter(|&g| m.face(g).contains(&v)).collect();
        want.sort();
        assert_eq!((t.len(), t), (2, want));
        let at_corner = index.tied_faces(f, &a);
        assert_eq!(at_corner.len(), m.vertex_faces(u).count());
        assert!(at_corner.contains(&f));
    }

    #[test]
    fn closest_point_regions() {
        let (a, b, c) = (P3::new(0., 0., 0.), P3::new(1., 0., 0.), P3::new(0., 1., 0.));
        assert!((closest_point_on_triangle(P3::new(0.2, 0.2, 1.0), a, b, c) - P3::new(0.2, 0.2, 0.0)).norm() < 1e-15);
        assert_eq!(closest_point_on_triangle(P3::new(-1., -1., 0.), a, b, c), a);
        assert_eq!(closest_point_on_triangle(P3::new(2., -1., 0.), a, b, c), b);
        let q = closest_point_on_triangle(P3::new(1., 1., 0.), a, b, c);
        assert!((q - P3::new(0.5, 0.5, 0.)).norm() < 1e-15);
    }

    #[test]
    fn hinted_distances_equal_plain_queries() {
        let s = shapes::icosphere(3);
        let idx = SurfaceIndex::new(&s).unwrap();
        // A wandering walk of nearby and far queries, inside and outside the sphere.
        let pts: Vec<P3> = (0..2000)
            .map(|i| {
                let t = f64::from(i) * 0.37;
                let r = 0.5 + 0.9 * (t * 0.13).sin().abs();
                P3::new(r * t.cos() * (t * 0.7).sin(), r * t.sin() * (t * 0.7).sin(), r * (t * 0.7).cos())
            })
            .collect();
        let order: Vec<usize> = (0..pts.len()).rev().collect();
        let d = idx.distances_in_order(&pts, &order);
        for (i, p) in pts.iter().enumerate() {
            assert_eq!(d[i], idx.query(p).distance, "query {i}");
        }
    }

    /// The batch searches (distances in the given order, and whole answers) give exactly what
    /// one plain query per point gives.
    fn batches_equal_plain_queries(idx: &SurfaceIndex, pts: &[P3]) {
        let order: Vec<usize> = (0..pts.len()).collect();
        let d = idx.distances_in_order(pts, &order);
        let all = idx.query_all(pts);
        for (i, p) in pts.iter().enumerate() {
            let q = idx.query(p);
            assert_eq!(d[i], q.distance, "distance {i}");
            assert_eq!((all[i].distance, all[i].face, all[i].point), (q.distance, q.face, q.point), "query {i}");
        }
    }

    #[test]
    fn block_answers_equal_plain_queries() {
        // A slow walk inside and outside the sphere: consecutive points are close, so most are
        // answered from a block's radius search, and far from the surface the candidate set
        // decides the answer.
        let s = shapes::icosphere(2);
        let idx = SurfaceIndex::new(&s).unwrap();
        let pts: Vec<P3> = (0..6000)
            .map(|i| {
                // Off the sphere's symmetry planes and axes (no ties between faces).
                let t = 0.1 + f64::from(i) * 0.012;
                let r = 0.4 + 1.2 * (t * 1.3).sin().abs();
                let (u, v) = (3.0 * t, 0.7 * t);
                P3::new(r * u.cos() * v.sin() + 0.0123, r * u.sin() * v.sin() - 0.0071, r * v.cos() + 0.0047)
            })
            .collect();
        batches_equal_plain_queries(&idx, &pts);
    }

    #[test]
    fn answers_among_faces_of_mixed_sizes_equal_plain_queries() {
        // A bumpy 40 x 40 grid whose last column of cells is stretched twelvefold: 80 large
        // faces, so the small-ball search takes its two tiers, and points near the seam see
        // large faces just outside their balls.
        let g = shapes::grid(40);
        let pos: Vec<P3> = g
            .positions()
            .iter()
            .map(|p| {
                let x = if p.x > 0.975 + 1e-12 { 0.975 + (p.x - 0.975) * 12.0 } else { p.x };
                P3::new(x, p.y, 0.03 * (7.0 * x).sin() * (5.0 * p.y).cos())
            })
            .collect();
        let m = g.with_positions(pos).unwrap();
        let idx = SurfaceIndex::new(&m).unwrap();
        let t = idx.tiers.as_ref().expect("tiers");
        assert!(t.has_large());
        let pts: Vec<P3> = (0..8000)
            .map(|i| {
                let t = f64::from(i) * 0.0011;
                let x = 0.5 + 0.8 * (t * 3.1).sin();
                let y = 0.5 + 0.55 * (t * 1.7).cos();
                P3::new(x + 0.0013, y - 0.0007, 0.04 * (t * 11.0).sin() + 0.001)
            })
            .collect();
        batches_equal_plain_queries(&idx, &pts);
        // Mapped vertices on the surface, ties between faces included.
        let on = idx.query_all(m.positions());
        for (i, p) in m.positions().iter().enumerate() {
            let q = idx.query(p);
            assert_eq!((on[i].distance, on[i].face), (q.distance, q.face), "vertex {i}");
        }
    }

    #[test]
    fn vertices_of_a_sphere_are_on_it() {
        let s = shapes::icosphere(2);
        let idx = SurfaceIndex::new(&s).unwrap();
        for p in s.positions() {
            assert!(idx.query(p).distance < 1e-15);
        }
    }
}
