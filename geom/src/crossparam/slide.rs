//! Sliding boundary images along the target's boundary. A map that takes boundary onto
//! boundary places a boundary "ear" (a face whose three corners are boundary vertices) with all
//! three corners on the target's boundary polyline, where it is nearly degenerate and faces
//! whichever way that polyline turns. A free boundary vertex whose star the evaluator counts
//! as flipped is tried at the target's boundary vertices (and edge midpoints and quarter
//! points) strictly between its two boundary neighbours' images — alone, then with the next
//! one or two boundary vertices — so the boundary's order is kept and every image stays on the
//! boundary; the best placement that lowers the count wins.

use super::visible::evaluator_flips_in_star;
use crate::map::SurfaceMap;
use crate::mesh::{FaceId, Mesh, P3, V3, VertexId};
use crate::metrics::SurfaceIndex;
use crate::topology;

/// Passes at most.
const PASSES: usize = 6;

/// Placements tried per move at most.
const MAX_COMBOS: usize = 4096;

/// Strictly increasing `k`-tuples of `0..n` (positions in order, so the boundary's order is
/// kept), at most `cap` of them, in lexicographic order.
fn increasing(n: usize, k: usize, cap: usize) -> Vec<Vec<usize>> {
    let mut out = Vec::new();
    let mut cur: Vec<usize> = (0..k).collect();
    if k == 0 || k > n {
        return out;
    }
    loop {
        out.push(cur.clone());
        if out.len() >= cap {
            return out;
        }
        // Advance the last index that can still move.
        let Some(i) = (0..k).rev().find(|&i| cur[i] < n - k + i) else { return out };
        cur[i] += 1;
        for j in i + 1..k {
            cur[j] = cur[j - 1] + 1;
        }
    }
}

/// Target boundary loops, with where each boundary edge sits (loop, index in loop).
struct Rings {
    loops: Vec<Vec<VertexId>>,
    at: std::collections::HashMap<(u32, u32), (usize, usize)>,
}

impl Rings {
    fn new(mesh: &Mesh) -> Rings {
        let loops: Vec<Vec<VertexId>> =
            topology::boundary_loops(mesh).iter().map(|l| l.iter().map(|&h| mesh.tail(h)).collect()).collect();
        let mut at = std::collections::HashMap::new();
        for (li, l) in loops.iter().enumerate() {
            for k in 0..l.len() {
                let (a, b) = (l[k], l[(k + 1) % l.len()]);
                at.insert((a.0.min(b.0), a.0.max(b.0)), (li, k));
            }
        }
        Rings { loops, at }
    }

    /// Loop and parameter (edge index + fraction) of a mapped point on the boundary.
    fn param(&self, mesh: &Mesh, f: FaceId, b: [f64; 3]) -> Option<(usize, f64)> {
        let t = mesh.face(f);
        let zero = (0..3).find(|&k| b[k] <= 1e-14)?;
        let (p, q) = (t[(zero + 1) % 3], t[(zero + 2) % 3]);
        let &(li, k) = self.at.get(&(p.0.min(q.0), p.0.max(q.0)))?;
        let l = &self.loops[li];
        let (bp, bq) = (b[(zero + 1) % 3], b[(zero + 2) % 3]);
        // Fraction from l[k] to l[k + 1].
        let u = if l[k] == p { bq / (bp + bq).max(f64::MIN_POSITIVE) } else { bp / (bp + bq).max(f64::MIN_POSITIVE) };
        Some((li, k as f64 + u))
    }

    /// The point at parameter `s` of loop `li`, as (face, barycentric, position).
    fn point(&self, mesh: &Mesh, li: usize, s: f64) -> Option<(FaceId, [f64; 3], P3)> {
        let l = &self.loops[li];
        let n = l.len() as f64;
        let s = s.rem_euclid(n);
        let k = (s.floor() as usize).min(l.len() - 1);
        let u = s - k as f64;
        let (p, q) = (l[k], l[(k + 1) % l.len()]);
        let h = mesh.find_halfedge(p, q).or_else(|| mesh.find_halfedge(q, p))?;
        let f = h.face();
        let t = mesh.face(f);
        let b = t.map(|c| {
            if c == p {
                1.0 - u
            } else if c == q {
                u
            } else {
                0.0
            }
        });
        let pos = P3::from(mesh.position(p).coords * (1.0 - u) + mesh.position(q).coords * u);
        Some((f, b, pos))
    }
}

/// Images being slid, with what the evaluator's rule needs.
struct State<'a> {
    pos: Vec<P3>,
    near: Vec<FaceId>,
    map: &'a mut SurfaceMap,
    rings: &'a Rings,
    target: &'a Mesh,
    index: &'a SurfaceIndex<'a>,
    tn: &'a [V3],
    tol: f64,
}

impl State<'_> {
    fn star_flips(&self, source: &Mesh, v: VertexId) -> usize {
        evaluator_flips_in_star(
            source,
            self.tn,
            self.index,
            v,
            (self.pos[v.idx()], self.near[v.idx()]),
            &self.pos,
            &self.near,
        )
    }

    fn flips(&self, source: &Mesh, vs: &[VertexId]) -> usize {
        vs.iter().map(|&v| self.star_flips(source, v)).sum()
    }

    /// Boundary parameter of `v`'s image.
    fn param(&self, v: VertexId) -> Option<(usize, f64)> {
        self.rings.param(self.target, self.map.face[v.idx()], self.map.bary[v.idx()])
    }

    fn set(&mut self, v: VertexId, (f, b, p): (FaceId, [f64; 3], P3), near: FaceId) {
        self.map.face[v.idx()] = f;
        self.map.bary[v.idx()] = b;
        self.pos[v.idx()] = p;
        self.near[v.idx()] = near;
    }

    /// Tries the consecutive boundary vertices `vs` at increasing positions strictly between
    /// the images of `lo` and `hi`; keeps the best placement if it lowers their stars' flips.
    fn improve(&mut self, source: &Mesh, vs: &[VertexId], lo: VertexId, hi: VertexId) -> bool {
        let (Some((la, sa)), Some((lc, sc))) = (self.param(lo), self.param(hi)) else { return false };
        if la != lc {
            return false;
        }
        let len = self.rings.loops[la].len() as f64;
        let mut span = sc - sa;
        if span <= 0.0 {
            span += len;
        }
        let mut cands: Vec<f64> = [0.25, 0.5, 0.75].iter().map(|t| sa + span * t).collect();
        let mut k = sa.floor() + 1.0;
        while k < sa + span && cands.len() < 64 {
            cands.push(k);
            if k + 0.5 < sa + span {
                cands.push(k + 0.5);
            }
            k += 1.0;
        }
        cands.sort_by(f64::total_cmp);
        let mut placed = Vec::with_capacity(cands.len());
        for s in cands {
            let Some(pt) = self.rings.point(self.target, la, s) else { continue };
            let q = self.index.query(&pt.2);
            if q.distance <= self.tol {
                placed.push((pt, q.face));
            }
        }
        let old: Vec<_> = vs
            .iter()
            .map(|v| ((self.map.face[v.idx()], self.map.bary[v.idx()], self.pos[v.idx()]), self.near[v.idx()]))
            .collect();
        let cur = self.flips(source, vs);
        let mut best: Option<(usize, Vec<usize>)> = None;
        let combos = increasing(placed.len(), vs.len(), MAX_COMBOS);
        for combo in combos {
            for (v, &k) in vs.iter().zip(&combo) {
                self.set(*v, placed[k].0, placed[k].1);
            }
            let f = self.flips(source, vs);
            if f < cur && best.as_ref().is_none_or(|b| f < b.0) {
                best = Some((f, combo));
            }
        }
        match best {
            Some((_, combo)) => {
                for (v, &k) in vs.iter().zip(&combo) {
                    self.set(*v, placed[k].0, placed[k].1);
                }
                true
            }
            None => {
                for (v, (pt, near)) in vs.iter().zip(old) {
                    self.set(*v, pt, near);
                }
                false
            }
        }
    }
}

/// Slides free boundary images of flipped stars along the target's boundary; returns the
/// number of moves.
///
/// # Errors
/// `Internal` if the target index cannot be built.
pub fn slide_boundary(source: &Mesh, target: &Mesh, map: &mut SurfaceMap, fixed: &[VertexId]) -> crate::Result<usize> {
    let src_loops = topology::boundary_loops(source);
    if src_loops.is_empty() {
        return Ok(0);
    }
    let rings = Rings::new(target);
    let index = SurfaceIndex::new(target)?;
    let tol = 1e-9 * target.bbox_diagonal();
    let tn: Vec<V3> = (0..target.n_faces())
        .map(|f| {
            let x = target.face_normal_raw(FaceId::from_idx(f));
            x / x.norm().max(crate::tol::TINY)
        })
        .collect();
    let n = source.n_vertices();
    let mut is_fixed = vec![false; n];
    for v in fixed {
        is_fixed[v.idx()] = true;
    }
    let pos: Vec<P3> = (0..n).map(|v| map.position(VertexId::from_idx(v), target)).collect();
    let near: Vec<FaceId> = pos.iter().map(|p| index.query(p).face).collect();
    let mut st = State { pos, near, map, rings: &rings, target, index: &index, tn: &tn, tol };
    let mut moves = 0;
    for _ in 0..PASSES {
        let mut moved = 0;
        for l in &src_loops {
            let ring: Vec<VertexId> = l.iter().map(|&h| source.tail(h)).collect();
            let m = ring.len();
            for i in 0..m {
                let (a, v, c, d) = (ring[(i + m - 1) % m], ring[i], ring[(i + 1) % m], ring[(i + 2) % m]);
                if is_fixed[v.idx()] || st.star_flips(source, v) == 0 {
                    continue;
                }
                // One vertex between its neighbours; failing that, it and the next one together.
                let e = ring[(i + 3) % m];
                if st.improve(source, &[v], a, c)
                    || (!is_fixed[c.idx()] && m > 3 && st.improve(source, &[v, c], a, d))
                    || (!is_fixed[c.idx()] && !is_fixed[d.idx()] && m > 4 && st.improve(source, &[v, c, d], a, e))
                {
                    moved += 1;
                }
            }
        }
        moves += moved;
        if moved == 0 {
            break;
        }
    }
    Ok(moves)
}
