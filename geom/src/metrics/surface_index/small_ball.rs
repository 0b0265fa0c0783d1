//! Distance-only answers of the evaluator's nearest-surface rule from small radius searches,
//! without finding any point's k nearest centroids.
//!
//! The rule's answer for `p` is the minimum distance over the faces whose centroids are among
//! its `k` nearest. Let `f0` be the face of the nearest centroid and `best` its distance. Only
//! a face whose lower bound (centroid distance minus radius) does not exceed `best` can be
//! closer; call those the contenders. When a ball around the block's first point `p0` is known
//! to hold (a) the nearest centroid, (b) every contender, and (c) every centroid strictly nearer
//! than the farthest contender, and fewer than `k` centroids are strictly nearer than that
//! farthest contender, then every contender is among the `k` nearest and the answer is the
//! minimum over `f0` and the contenders: exactly the rule's (the argument of
//! `nearest_distance_among`, with the k-th distance never needed).
//!
//! Everything outside a ball of radius `r` is farther than `avail = r − |p − p0|` from `p`. For
//! (b), faces are split in two tiers by radius: a small face outside is no nearer than `avail`
//! minus the small tier's largest radius, which must exceed `best`; the few large faces have a
//! k-d tree of their own, and the large faces near the block but outside its ball are tested
//! one by one. A contender lies within about one small-face radius of the surface near `p`, so
//! the ball is a few faces wide instead of twice the k nearest's reach, and its radius follows
//! the previous block's need. A point whose checks fail takes the k-nearest search.

use super::tiers::Tiers;
use super::{Nearest, SurfaceIndex};
use crate::mesh::P3;
use kiddo::SquaredEuclidean;

/// Margin of the next ball over the previous block's largest need.
const GROWTH: f64 = 1.25;

/// Relative slack on every bound (rounding of distances and of their squares).
const SLACK: f64 = 1e-9;

/// The centroids gathered for a block, as columns.
#[derive(Default)]
struct Gathered {
    x: Vec<f64>,
    y: Vec<f64>,
    z: Vec<f64>,
    radius: Vec<f64>,
    id: Vec<u32>,
}

impl Gathered {
    fn clear(&mut self) {
        self.x.clear();
        self.y.clear();
        self.z.clear();
        self.radius.clear();
        self.id.clear();
    }

    fn push(&mut self, c: [f64; 3], r: f64, id: u32) {
        self.x.push(c[0]);
        self.y.push(c[1]);
        self.z.push(c[2]);
        self.radius.push(r);
        self.id.push(id);
    }
}

impl SurfaceIndex<'_> {
    /// The rule's answer for each of `pts` (nearby points in turn), handed to `put` with the
    /// point's index. With `sorted`, `face` and `point` are the rule's on ties too (of the
    /// closest candidates, the one with the nearest centroid, which the evaluator meets
    /// first); without, a closest candidate's.
    pub(super) fn search_small_ball(
        &self,
        tiers: &Tiers,
        pts: &[P3],
        sorted: bool,
        mut put: impl FnMut(usize, Nearest),
    ) {
        let mut ball = Gathered::default();
        let mut outside = Gathered::default();
        let mut scratch = (Vec::new(), Vec::new());
        let mut base = 2.0 * tiers.small_max;
        let mut start = 0;
        while start < pts.len() {
            let p0 = pts[start];
            let q0 = [p0.x, p0.y, p0.z];
            let (end, reach) = super::block(pts, start, 0.5 * base);
            let r = base + reach;
            ball.clear();
            for n in self.tree.query(&q0).within::<SquaredEuclidean<f64>>(r * r).unsorted().execute() {
                ball.push(self.centroids[n.item as usize], self.radius[n.item as usize], n.item);
            }
            // Large faces that a block point might see but the ball does not hold.
            outside.clear();
            if let Some((tree, ids)) = &tiers.large {
                let wide = r + tiers.all_max;
                for n in tree.query(&q0).within::<SquaredEuclidean<f64>>(wide * wide).unsorted().execute() {
                    if n.distance > r * r * (1.0 - 4.0 * SLACK) {
                        let f = ids[n.item as usize];
                        outside.push(self.centroids[f as usize], self.radius[f as usize], f);
                    }
                }
            }
            let mut need_max: f64 = 0.0;
            for (j, &p) in pts.iter().enumerate().take(end).skip(start) {
                let avail = (r - (p - p0).norm()) * (1.0 - SLACK);
                let found = self.contenders(tiers, &p, avail, (&ball, &outside), sorted, &mut scratch);
                let (ans, need) = found.unwrap_or_else(|| self.fallback(tiers, &p, sorted));
                put(j, ans);
                need_max = need_max.max(need);
            }
            // A block whose points needed nothing (an empty ball) keeps its radius.
            if need_max > 0.0 {
                base = GROWTH * need_max;
            }
            start = end;
        }
    }

    /// The answer for `p` from the block's ball and the large faces outside it, and the radius
    /// around `p` it needed, or `None` when they cannot show it (see the module doc).
    fn contenders(
        &self,
        tiers: &Tiers,
        p: &P3,
        avail: f64,
        (g, outside): (&Gathered, &Gathered),
        sorted: bool,
        (d2, maybe): &mut (Vec<f64>, Vec<(f64, u32)>),
    ) -> Option<(Nearest, f64)> {
        if g.x.is_empty() {
            return None;
        }
        d2.clear();
        d2.extend((0..g.x.len()).map(|i| {
            let (dx, dy, dz) = (g.x[i] - p.x, g.y[i] - p.y, g.z[i] - p.z);
            dx * dx + dy * dy + dz * dz
        }));
        let near = super::argmin(d2);
        let d_near = d2[near].sqrt();
        // (a) the nearest centroid is the ball's.
        if d_near >= avail {
            return None;
        }
        let best = self.best_of(p, std::iter::once((g.id[near], d2[near])));
        // (b) no small face outside the ball can be as close, nor any large one.
        if best.distance + tiers.small_max >= avail {
            return None;
        }
        for i in 0..outside.x.len() {
            let (dx, dy, dz) = (outside.x[i] - p.x, outside.y[i] - p.y, outside.z[i] - p.z);
            if (dx * dx + dy * dy + dz * dz).sqrt() * (1.0 - SLACK) - outside.radius[i] <= best.distance {
                return None;
            }
        }
        let far = super::contenders_of(d2, near, best.distance, |c| g.radius[c], |c| g.id[c], maybe);
        let far_r = far.sqrt();
        // (c) every centroid nearer than the farthest contender is the ball's, and fewer than k
        // of them are.
        if far_r >= avail || d2.iter().filter(|&&d| d < far).count() >= self.k.get() {
            return None;
        }
        let need = (best.distance + tiers.small_max).max(far_r).max(d_near);
        if maybe.is_empty() {
            return Some((best, need));
        }
        if sorted {
            // The rule's face on ties: of the closest, the nearest centroid's (`best_of`).
            maybe.push((d2[near], g.id[near]));
            return Some((self.best_of(p, maybe.iter().map(|&(d, item)| (item, d))), need));
        }
        let rest = self.best_of(p, maybe.iter().map(|&(d, item)| (item, d)));
        Some((if rest.distance < best.distance { rest } else { best }, need))
    }

    /// The k-nearest search's answer for `p`, and a radius around `p` that holds its k
    /// nearest.
    fn fallback(&self, tiers: &Tiers, p: &P3, sorted: bool) -> (Nearest, f64) {
        let q = [p.x, p.y, p.z];
        let query = self.tree.query(&q).nearest_n::<SquaredEuclidean<f64>>(self.k);
        let cand = if sorted { query.execute() } else { query.unsorted().execute() };
        let best = self.best_of(p, cand.iter().map(|n| (n.item, n.distance)));
        let dk = cand.iter().map(|n| n.distance).fold(0.0, f64::max).sqrt();
        (best, dk.max(best.distance + tiers.small_max) * (1.0 + SLACK))
    }
}
