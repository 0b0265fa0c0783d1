//! The line searches of the injective Newton optimizer: plain backtracking, and the search
//! with held vertices for domains where the linear step bound cannot see every inversion
//! (images retracted onto a curved surface). A trial the held search accepts has every
//! triangle positively oriented under Shewchuk's exact `orient2d`.

use super::domain::MapDomain;
use crate::param::Uv;
use crate::tol::MIN_STEP;
use rayon::prelude::*;

/// The triangles at each vertex (compressed rows).
pub struct Stars {
    start: Vec<usize>,
    triangles: Vec<u32>,
}

impl Stars {
    /// The stars of `triangles` over `n_vertices` (every vertex index below it).
    pub fn new(n_vertices: usize, triangles: &[[u32; 3]]) -> Self {
        let mut start = vec![0usize; n_vertices + 1];
        triangles.iter().flatten().for_each(|&v| start[v as usize + 1] += 1);
        for v in 0..n_vertices {
            start[v + 1] += start[v];
        }
        let mut next = start.clone();
        let mut out = vec![0u32; start[n_vertices]];
        for (t, tri) in triangles.iter().enumerate() {
            for &v in tri {
                out[next[v as usize]] = t as u32;
                next[v as usize] += 1;
            }
        }
        Self { start, triangles: out }
    }

    fn of(&self, v: u32) -> &[u32] {
        &self.triangles[self.start[v as usize]..self.start[v as usize + 1]]
    }
}

/// Whether the triangle `x` is positively oriented (exact predicate).
pub fn positive(x: [Uv; 3]) -> bool {
    let c = |p: Uv| robust::Coord { x: p[0], y: p[1] };
    robust::orient2d(c(x[0]), c(x[1]), c(x[2])) > 0.0
}

/// Triangles not positively oriented (exact predicate) in state `s`.
pub fn inverted<D: MapDomain>(d: &D, s: &D::State, triangles: &[[u32; 3]]) -> Vec<usize> {
    (0..triangles.len()).into_par_iter().filter(|&t| !positive(d.element(s, triangles[t]).0)).collect()
}

/// Triangles around `vertices` not positively oriented (exact predicate) in state `s`.
fn inverted_around<D: MapDomain>(
    d: &D,
    s: &D::State,
    (triangles, stars): (&[[u32; 3]], &Stars),
    vertices: &[u32],
) -> Vec<usize> {
    let mut out: Vec<usize> = vertices
        .iter()
        .flat_map(|&v| stars.of(v))
        .map(|&t| t as usize)
        .filter(|&t| !positive(d.element(s, triangles[t]).0))
        .collect();
    out.sort_unstable();
    out.dedup();
    out
}

/// The line search with held vertices from step `t` along `dir`: a trial that inverts
/// triangles is tried again at the same length with their vertices held (up to `rounds` times
/// in all), then halved. A trial is accepted when every triangle is positive and `accept` gives
/// it an energy. Holding a vertex restores its image in place ([`MapDomain::restore`]) and
/// re-tests only the triangles around it, so a round costs the size of what it holds, not of
/// the mesh. Returns the trial, its energy and the refused trials.
pub fn held_search<D: MapDomain>(
    d: &D,
    s: &D::State,
    (dir, mut t): (&[Uv], f64),
    (triangles, stars): (&[[u32; 3]], &Stars),
    rounds: usize,
    accept: impl Fn(&D::State) -> Option<f64>,
) -> Option<(D::State, f64, usize)> {
    let mut dir = dir.to_vec();
    let mut refused = 0;
    let mut held = 0;
    let mut is_held = vec![false; dir.len()];
    while t > MIN_STEP {
        let step: Vec<Uv> = dir.iter().map(|q| [t * q[0], t * q[1]]).collect();
        let Some(mut trial) = d.moved(s, &step) else {
            refused += 1;
            t *= 0.5;
            continue;
        };
        let mut bad = inverted(d, &trial, triangles);
        while !bad.is_empty() && held < rounds {
            held += 1;
            refused += 1;
            let mut vs: Vec<u32> = bad.iter().flat_map(|&tri| triangles[tri]).collect();
            vs.retain(|&v| !std::mem::replace(&mut is_held[v as usize], true));
            vs.iter().for_each(|&v| dir[v as usize] = [0.0; 2]);
            if vs.iter().all(|&v| d.restore(&mut trial, s, v as usize)) {
                bad = inverted_around(d, &trial, (triangles, stars), &vs);
            } else {
                let step: Vec<Uv> = dir.iter().map(|q| [t * q[0], t * q[1]]).collect();
                let Some(again) = d.moved(s, &step) else { break };
                trial = again;
                bad = inverted(d, &trial, triangles);
            }
        }
        if bad.is_empty()
            && let Some(e) = accept(&trial)
        {
            return Some((trial, e, refused));
        }
        refused += 1;
        t *= 0.5;
    }
    None
}

/// Halves the step `t` along `dir` from its start until `accept` gives the trial an energy;
/// returns the trial, that energy and the refused trials.
pub fn backtrack<D: MapDomain>(
    d: &D,
    s: &D::State,
    dir: &[Uv],
    mut t: f64,
    accept: impl Fn(&D::State, f64) -> Option<f64>,
) -> Option<(D::State, f64, usize)> {
    let mut refused = 0;
    while t > MIN_STEP {
        let step: Vec<Uv> = dir.iter().map(|q| [t * q[0], t * q[1]]).collect();
        if let Some(trial) = d.moved(s, &step)
            && let Some(e) = accept(&trial, t)
        {
            return Some((trial, e, refused));
        }
        refused += 1;
        t *= 0.5;
    }
    None
}
