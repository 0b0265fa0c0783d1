//! One linear solve of the global map onto the base domain: every non-anchor vertex is the
//! weighted mean of its neighbours, each neighbour expressed in the vertex's own chart through
//! the transition between their patches (a connection Laplacian with rigid transitions, as in
//! Khodakovsky, Litke & Schröder 2003). Anchors are fixed at their corners. The system couples
//! the two coordinates (the transitions rotate): one sparse `2n × 2n` Cholesky (faer), see
//! [`System`].

use super::charts::{Affine, Charts};
use crate::error::{Error, Result};
use crate::mesh::{FaceId, Mesh, VertexId};
use crate::param::Uv;
use faer::Mat;
use faer::Side;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Llt, SymbolicLlt};
use faer::sparse::{SparseColMat, Triplet};

/// The map's state: per vertex its patch, chart position and anchor index (`u32::MAX`: none),
/// and per ordered neighbour pair (the slots of [`Rows`]) the *link*, the map from the
/// neighbour's chart into the vertex's. Links fix which way round each cone point an edge runs
/// (its homotopy class): they are chosen once, from a valid starting map, and afterwards only
/// carried along when a vertex changes chart, never chosen again by distance.
#[derive(Debug, Clone)]
pub struct State {
    pub patch: Vec<u32>,
    pub uv: Vec<Uv>,
    pub anchor: Vec<u32>,
    pub link: Vec<Option<Affine>>,
}

impl State {
    /// Fills every slot of `rows` without a link (all of them when `link` is empty) with the
    /// link on the sheet that puts the neighbour closest to the vertex (an anchor: at its
    /// corner whenever the vertex's patch has it).
    pub fn fill_links(&mut self, charts: &Charts, rows: &Rows) {
        self.link.resize(rows.nbr.len(), None);
        for i in 0..self.uv.len() {
            for s in rows.start[i]..rows.start[i + 1] {
                if self.link[s].is_some() {
                    continue;
                }
                let j = rows.nbr[s].0 as usize;
                let (p, x) = (self.patch[i], self.uv[i]);
                self.link[s] = match self.anchor[j] {
                    u32::MAX => charts.transition(self.patch[j], p, self.uv[j], x),
                    a => charts.anchor_link(a, p, x),
                };
            }
        }
    }

    /// Neighbour `j` (slot `s` of `i`'s row) in `i`'s chart.
    pub fn neighbour(&self, s: usize, j: usize) -> Option<Uv> {
        self.link[s].map(|a| a.apply(self.uv[j]))
    }

    /// Carries the links along after vertex `v` moved into another chart by `moved[v]`.
    pub fn carry_links(&mut self, rows: &Rows, moved: &[Option<Affine>]) {
        for i in 0..self.uv.len() {
            for s in rows.start[i]..rows.start[i + 1] {
                let j = rows.nbr[s].0 as usize;
                if moved[i].is_none() && moved[j].is_none() {
                    continue;
                }
                if let Some(mut a) = self.link[s] {
                    if let Some(mj) = moved[j] {
                        a = a.after(&mj.inverse());
                    }
                    if let Some(mi) = moved[i] {
                        a = mi.after(&a);
                    }
                    self.link[s] = Some(a);
                }
            }
        }
    }
}

/// Ordered-pair weights as compressed rows: `nbr[start[i]..start[i + 1]]` are `i`'s
/// neighbours `(j, w_ij)`.
#[derive(Debug, Clone)]
pub struct Rows {
    pub start: Vec<usize>,
    pub nbr: Vec<(u32, f64)>,
}

impl Rows {
    /// Mean-value weights (Floater 2003) of `mesh` (closed), symmetrized: `(w_ij + w_ji) / 2`
    /// for both orders. Still positive (a Tutte system), and symmetric, so the global system
    /// is solved by Cholesky.
    pub fn mean_value(mesh: &Mesh) -> Rows {
        let w = crate::linalg::directed_weights(mesh, crate::linalg::Weights::MeanValue);
        let mut start = Vec::with_capacity(mesh.n_vertices() + 1);
        let mut nbr = Vec::with_capacity(mesh.n_halfedges());
        start.push(0);
        for v in 0..mesh.n_vertices() {
            for h in mesh.outgoing(VertexId::from_idx(v)) {
                let mut x = w.fwd[h.idx()];
                if let Some(t) = mesh.twin(h) {
                    x += w.rev[t.idx()];
                }
                nbr.push((mesh.head(h).0, x));
            }
            start.push(nbr.len());
        }
        let mut rows = Rows { start, nbr };
        let sym: Vec<f64> = (0..mesh.n_vertices())
            .flat_map(|i| (rows.start[i]..rows.start[i + 1]).map(move |s| (i, s)))
            .map(|(i, s)| {
                let (j, w) = rows.nbr[s];
                slot_of(&rows, j as usize, i).map_or(w, |r| 0.5 * (w + rows.nbr[r].1))
            })
            .collect();
        for (x, w) in rows.nbr.iter_mut().zip(sym) {
            x.1 = w;
        }
        rows
    }

    pub fn of(&self, i: usize) -> &[(u32, f64)] {
        &self.nbr[self.start[i]..self.start[i + 1]]
    }
}

/// The global map's linear system: unknowns are the free vertices' two chart coordinates,
/// and every free pair of neighbours gets its whole 2 × 2 block whether or not its link
/// rotates, so the sparsity pattern depends on the mesh alone and the symbolic Cholesky
/// factorization is computed once and reused by every solve (faer's symbolic / numeric split).
pub struct System {
    index: Vec<u32>,
    free: usize,
    symbolic: Option<SymbolicLlt<usize>>,
}

impl System {
    pub fn new(fixed: &[bool]) -> System {
        let mut index = vec![u32::MAX; fixed.len()];
        let mut free = 0usize;
        for (v, &f) in fixed.iter().enumerate() {
            if !f {
                index[v] = free as u32;
                free += 1;
            }
        }
        System { index, free, symbolic: None }
    }

    /// Solves for every free vertex with weights `rows` (symmetric: `w_ij = w_ji`); fixed
    /// vertices keep `st`'s position. The row of vertex `i` is `Σ_j w_ij (x_i − L_ij x_j) = 0`
    /// with `L_ij` the link of the pair; the link of `j` to `i` is taken as the inverse of
    /// that of `i` to `j` (rigid, so its linear part is the transpose), which makes the matrix
    /// symmetric positive definite once an anchor is fixed. Returns the new positions (in
    /// each vertex's current chart) and the relative residual.
    ///
    /// # Errors
    /// `Numerical` when the factorization fails, the solution is not finite, or the residual
    /// exceeds [`crate::tol::SOLVE_RESIDUAL_REL`].
    pub fn solve(&mut self, st: &State, fixed: &[bool], rows: &Rows) -> Result<(Vec<Uv>, f64)> {
        let n = st.uv.len();
        let free = self.free;
        let mut trip: Vec<Triplet<usize, usize, f64>> = Vec::with_capacity(rows.nbr.len() * 4 + 2 * free);
        let mut rhs = vec![0.0; 2 * free];
        for i in 0..n {
            if fixed[i] {
                continue;
            }
            let fi = 2 * self.index[i] as usize;
            let mut diag = 0.0;
            for s in rows.start[i]..rows.start[i + 1] {
                let (j, w) = rows.nbr[s];
                let j = j as usize;
                // One link per edge: the smaller end's, inverted for the larger end.
                let link =
                    if i < j { st.link[s] } else { slot_of(rows, j, i).and_then(|r| st.link[r]).map(|a| a.inverse()) };
                let Some(a) = link else {
                    continue;
                };
                diag += w;
                if fixed[j] {
                    let x = a.apply(st.uv[j]);
                    rhs[fi] += w * x[0];
                    rhs[fi + 1] += w * x[1];
                } else {
                    let fj = 2 * self.index[j] as usize;
                    for r in 0..2 {
                        rhs[fi + r] += w * a.t[r];
                        for c in 0..2 {
                            trip.push(Triplet::new(fi + r, fj + c, -w * a.m[r][c]));
                        }
                    }
                }
            }
            if !(diag > 0.0 && diag.is_finite()) {
                return Err(Error::Numerical(format!("vertex {i} has no usable weight in the global map")));
            }
            trip.push(Triplet::new(fi, fi, diag));
            trip.push(Triplet::new(fi + 1, fi + 1, diag));
        }
        if trip.iter().any(|t| !t.val.is_finite()) {
            return Err(Error::Numerical("non-finite weight in the global map (degenerate triangle?)".into()));
        }
        let mat = SparseColMat::<usize, f64>::try_new_from_triplets(2 * free, 2 * free, &trip)
            .map_err(|e| Error::Numerical(format!("global map system: {e:?}")))?;
        let symbolic = match &self.symbolic {
            Some(s) => s.clone(),
            None => {
                let s = SymbolicLlt::try_new(mat.symbolic(), Side::Lower)
                    .map_err(|e| Error::Numerical(format!("global map symbolic factorization: {e:?}")))?;
                self.symbolic = Some(s.clone());
                s
            }
        };
        let llt = Llt::try_new_with_symbolic(symbolic, mat.as_ref(), Side::Lower)
            .map_err(|e| Error::Numerical(format!("global map factorization: {e:?}")))?;
        let mut x = Mat::<f64>::from_fn(2 * free, 1, |r, _| rhs[r]);
        llt.solve_in_place(x.as_mut());
        // Relative residual ||A x - b|| / ||b||.
        let mut ax = vec![0.0; 2 * free];
        for t in &trip {
            ax[t.row] += t.val * x[(t.col, 0)];
        }
        let num: f64 = ax.iter().zip(&rhs).map(|(a, b)| (a - b) * (a - b)).sum();
        let den: f64 = rhs.iter().map(|b| b * b).sum();
        let residual = num.sqrt() / den.sqrt().max(crate::tol::TINY);
        if !residual.is_finite() || residual > crate::tol::SOLVE_RESIDUAL_REL {
            return Err(Error::Numerical(format!("global map residual {residual:.3e}")));
        }
        let mut out = st.uv.clone();
        for v in 0..n {
            if !fixed[v] {
                let f = 2 * self.index[v] as usize;
                out[v] = [x[(f, 0)], x[(f + 1, 0)]];
            }
        }
        Ok((out, residual))
    }
}

/// The slot of `j` in `i`'s row.
pub fn slot_of(rows: &Rows, i: usize, j: usize) -> Option<usize> {
    (rows.start[i]..rows.start[i + 1]).find(|&s| rows.nbr[s].0 as usize == j)
}

/// The face's three chart positions in the chart of its first corner that is not an anchor
/// (an anchor's chart is its home patch's, which need not be near the face), through the links
/// of that corner's row.
pub(crate) fn face_uv(mesh: &Mesh, st: &State, rows: &Rows, fixed: &[bool], f: FaceId) -> Option<[Uv; 3]> {
    let t = mesh.face(f);
    let r = (0..3).find(|&k| !fixed[t[k].idx()]).unwrap_or(0);
    let i = t[r].idx();
    let mut out = [st.uv[i]; 3];
    for k in 0..3 {
        if k != r {
            let j = t[k].idx();
            let s = slot_of(rows, i, j)?;
            out[k] = st.neighbour(s, j)?;
        }
    }
    Some(out)
}
