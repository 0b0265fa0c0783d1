//! Solving `L u = 0` on free vertices with fixed values on the others: the system
//! `L_FF u_F = -L_FB u_B`, where `L` is the weighted graph Laplacian.
//!
//! [`FixedBoundarySystem`] holds the sparsity pattern and both symbolic factorizations
//! (computed once per mesh and fixed set); [`FixedBoundarySystem::factor`] runs a numeric
//! factorization for one set of weights (Cholesky when symmetric, LU otherwise), and
//! [`FixedBoundaryFactor::solve`] solves for any number of right-hand sides and verifies the
//! relative residual.

use super::ordering::{COARSEN_MIN, coarsened_amd};
use super::weights::{DirectedWeights, Weights, directed_weights};
use crate::error::{Error, InputError, Result};
use crate::mesh::{HalfedgeId, Mesh, VertexId};
use crate::tol;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::perm::PermRef;
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky};
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, Par, Side, linalg::solvers::Solve};

/// Pattern and symbolic factorizations of a fixed-boundary Laplacian system.
pub struct FixedBoundarySystem {
    n_vertices: usize,
    /// Free index of each vertex, `u32::MAX` for fixed vertices.
    free_index: Vec<u32>,
    free: Vec<VertexId>,
    /// CSC pattern of `L_FF` (values filled per factorization).
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// For each half-edge, the slot in `values` of (row tail, col head) and (row head, col tail)
    /// when both ends are free; and the diagonal slots per free vertex.
    slot_fwd: Vec<usize>,
    slot_rev: Vec<usize>,
    diag_slot: Vec<usize>,
    sym_llt: Option<SymbolicCholesky<usize>>,
    sym_lu: Option<SymbolicLu<usize>>,
    /// Half-edge tails/heads cached.
    ends: Vec<(u32, u32)>,
}

/// A numeric factorization of `L_FF` for one set of weights.
pub struct FixedBoundaryFactor<'s> {
    sys: &'s FixedBoundarySystem,
    values: Vec<f64>,
    /// `(free row, fixed vertex, weight)` couplings to the fixed values.
    coupling: Vec<(u32, u32, f64)>,
    /// Values of the Cholesky factor (its structure is the system's symbolic factorization).
    llt: Option<Vec<f64>>,
    lu: Option<Lu<usize, f64>>,
}

const NO: usize = usize::MAX;

impl FixedBoundarySystem {
    /// Builds the pattern of the free-free block for the vertices not in `fixed`.
    ///
    /// # Errors
    /// `InputError::Invalid` if no vertex is fixed or every vertex is; `OutOfRange` for a bad id.
    pub fn new(mesh: &Mesh, fixed: &[VertexId]) -> Result<Self> {
        let nv = mesh.n_vertices();
        let mut free_index = vec![0u32; nv];
        for &v in fixed {
            if v.idx() >= nv {
                return Err(InputError::OutOfRange { what: "fixed vertex", index: v.idx(), count: nv }.into());
            }
            free_index[v.idx()] = u32::MAX;
        }
        let mut free = Vec::with_capacity(nv);
        for (v, fi) in free_index.iter_mut().enumerate() {
            if *fi != u32::MAX {
                *fi = free.len() as u32;
                free.push(VertexId::from_idx(v));
            }
        }
        if free.len() == nv {
            return Err(InputError::Invalid("a fixed-boundary system needs at least one fixed vertex".into()).into());
        }
        let nh = mesh.n_halfedges();
        let ends: Vec<(u32, u32)> = (0..nh)
            .map(|h| {
                let h = HalfedgeId::from_idx(h);
                (mesh.tail(h).0, mesh.head(h).0)
            })
            .collect();
        let n = free.len();
        // Pattern of L_FF, column by column from the one-rings (sorted rows, diagonal included).
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::with_capacity(n + 2 * nh);
        col_ptr.push(0usize);
        let mut ring: Vec<usize> = Vec::with_capacity(32);
        for (c, &v) in free.iter().enumerate() {
            ring.clear();
            ring.push(c);
            for w in mesh.vertex_neighbors(v) {
                let fw = free_index[w.idx()];
                if fw != u32::MAX {
                    ring.push(fw as usize);
                }
            }
            ring.sort_unstable();
            ring.dedup();
            row_idx.extend_from_slice(&ring);
            col_ptr.push(row_idx.len());
        }
        let find = |r: usize, c: usize| -> usize {
            let s = &row_idx[col_ptr[c]..col_ptr[c + 1]];
            s.binary_search(&r).map_or(NO, |k| col_ptr[c] + k)
        };
        let mut slot_fwd = vec![NO; nh];
        let mut slot_rev = vec![NO; nh];
        for (h, &(a, b)) in ends.iter().enumerate() {
            let (fa, fb) = (free_index[a as usize], free_index[b as usize]);
            if fa != u32::MAX && fb != u32::MAX {
                slot_fwd[h] = find(fa as usize, fb as usize);
                slot_rev[h] = find(fb as usize, fa as usize);
            }
        }
        let diag_slot = (0..n).map(|i| find(i, i)).collect();
        let sys = FixedBoundarySystem {
            n_vertices: nv,
            free_index,
            free,
            col_ptr,
            row_idx,
            slot_fwd,
            slot_rev,
            diag_slot,
            sym_llt: None,
            sym_lu: None,
            ends,
        };
        Ok(sys)
    }

    /// Symbolic Cholesky: AMD ordering, on a coarsened graph for large systems.
    fn symbolic_cholesky(&self) -> Result<SymbolicCholesky<usize>> {
        let n = self.free.len();
        let fail = |e: faer::sparse::FaerError| Error::Numerical(format!("symbolic Cholesky: {e:?}"));
        if n < COARSEN_MIN {
            return factorize_symbolic_cholesky(
                self.pattern(),
                Side::Lower,
                SymmetricOrdering::Amd,
                Default::default(),
            )
            .map_err(fail);
        }
        let order = coarsened_amd(&self.col_ptr, &self.row_idx)?;
        let mut inverse = vec![0usize; n];
        for (k, &i) in order.iter().enumerate() {
            inverse[i] = k;
        }
        let perm = PermRef::new_checked(&order, &inverse, n);
        factorize_symbolic_cholesky(self.pattern(), Side::Lower, SymmetricOrdering::Custom(perm), Default::default())
            .map_err(fail)
    }

    fn pattern(&self) -> SymbolicSparseColMatRef<'_, usize> {
        let n = self.free.len();
        SymbolicSparseColMatRef::new_checked(n, n, &self.col_ptr, None, &self.row_idx)
    }

    /// Number of free vertices (unknowns).
    pub fn n_free(&self) -> usize {
        self.free.len()
    }
    /// The free vertices in unknown order.
    pub fn free_vertices(&self) -> &[VertexId] {
        &self.free
    }

    /// Numeric factorization for the given weights of `mesh` (the mesh the system was built on).
    ///
    /// # Errors
    /// `Error::Numerical` if the matrix is singular or (for symmetric weights) not positive definite.
    pub fn factor(&mut self, mesh: &Mesh, weights: Weights) -> Result<FixedBoundaryFactor<'_>> {
        let w = directed_weights(mesh, weights);
        if weights.is_symmetric() {
            self.prepare_cholesky()?;
        } else {
            self.prepare_lu()?;
        }
        self.factor_weights(&w, weights.is_symmetric())
    }

    /// Computes the symbolic Cholesky factorization once (AMD ordering), for symmetric
    /// [`FixedBoundarySystem::factor_weights`] calls.
    ///
    /// # Errors
    /// `Error::Numerical` if the symbolic analysis fails.
    pub fn prepare_cholesky(&mut self) -> Result<()> {
        if self.sym_llt.is_none() {
            self.sym_llt = Some(self.symbolic_cholesky()?);
        }
        Ok(())
    }

    /// Computes the symbolic LU factorization once, for repeated non-symmetric
    /// [`FixedBoundarySystem::factor_weights`] calls.
    ///
    /// # Errors
    /// `Error::Numerical` if the symbolic analysis fails.
    pub fn prepare_lu(&mut self) -> Result<()> {
        if self.sym_lu.is_none() {
            let lu =
                SymbolicLu::try_new(self.pattern()).map_err(|e| Error::Numerical(format!("symbolic LU: {e:?}")))?;
            self.sym_lu = Some(lu);
        }
        Ok(())
    }

    /// Numeric factorization for explicit per-half-edge weights (e.g. reweighted by stretch).
    ///
    /// # Errors
    /// As [`FixedBoundarySystem::factor`].
    pub fn factor_weights(&self, w: &DirectedWeights, symmetric: bool) -> Result<FixedBoundaryFactor<'_>> {
        let mut values = vec![0.0; self.row_idx.len()];
        let mut coupling = Vec::new();
        for (h, &(a, b)) in self.ends.iter().enumerate() {
            let (fa, fb) = (self.free_index[a as usize], self.free_index[b as usize]);
            let (wab, wba) = (w.fwd[h], w.rev[h]);
            if fa != u32::MAX {
                values[self.diag_slot[fa as usize]] += wab;
                if fb != u32::MAX {
                    values[self.slot_fwd[h]] -= wab;
                } else {
                    coupling.push((fa, b, wab));
                }
            }
            if fb != u32::MAX {
                values[self.diag_slot[fb as usize]] += wba;
                if fa != u32::MAX {
                    values[self.slot_rev[h]] -= wba;
                } else {
                    coupling.push((fb, a, wba));
                }
            }
        }
        if values.iter().any(|v| !v.is_finite()) {
            return Err(Error::Numerical("non-finite Laplacian weight (degenerate triangle?)".into()));
        }
        let n = self.free.len();
        let mat = SparseColMatRef::new(self.pattern(), &values);
        let (mut llt, mut lu) = (None, None);
        if symmetric {
            let sym = self
                .sym_llt
                .as_ref()
                .ok_or_else(|| Error::Internal("symmetric factorization without prepare_cholesky()".into()))?;
            llt = Some(numeric_llt(sym, mat)?);
        } else {
            let sym = match &self.sym_lu {
                Some(s) => s.clone(),
                None => {
                    SymbolicLu::try_new(self.pattern()).map_err(|e| Error::Numerical(format!("symbolic LU: {e:?}")))?
                }
            };
            lu = Some(
                Lu::try_new_with_symbolic(sym, mat)
                    .map_err(|e| Error::Numerical(format!("LU factorization failed ({n} unknowns): {e:?}")))?,
            );
        }
        Ok(FixedBoundaryFactor { sys: self, values, coupling, llt, lu })
    }
}

/// The numeric Cholesky factor's values of `mat` (lower triangle read) on the symbolic
/// factorization `sym`, as every fixed-pattern system in the crate runs it.
///
/// # Errors
/// `Numerical` when the workspace cannot be allocated or `mat` is not positive definite.
pub fn numeric_llt(sym: &SymbolicCholesky<usize>, mat: SparseColMatRef<'_, usize, f64>) -> Result<Vec<f64>> {
    let mut l_values = vec![0.0; sym.len_val()];
    let mut buf = MemBuffer::try_new(sym.factorize_numeric_llt_scratch::<f64>(Par::Seq, Default::default()))
        .map_err(|e| Error::Numerical(format!("Cholesky workspace: {e:?}")))?;
    sym.factorize_numeric_llt::<f64>(
        &mut l_values,
        mat,
        Side::Lower,
        Default::default(),
        Par::Seq,
        MemStack::new(&mut buf),
        Default::default(),
    )
    .map_err(|e| Error::Numerical(format!("Cholesky factorization failed ({} unknowns): {e:?}", mat.ncols())))?;
    Ok(l_values)
}

impl FixedBoundaryFactor<'_> {
    /// Solves for `k` coordinates at once: `fixed_values(v)` gives the `k` values of fixed
    /// vertex `v`. Returns all vertices' values (fixed ones copied through).
    ///
    /// # Errors
    /// `Error::Numerical` when the solution is not finite or the relative residual exceeds
    /// [`tol::SOLVE_RESIDUAL_REL`].
    pub fn solve<const K: usize>(&self, fixed_values: &dyn Fn(VertexId) -> [f64; K]) -> Result<Vec<[f64; K]>> {
        Ok(self.solve_with_residual(fixed_values)?.0)
    }

    /// [`FixedBoundaryFactor::solve`], also returning the largest relative residual over the
    /// `K` columns.
    ///
    /// # Errors
    /// As [`FixedBoundaryFactor::solve`].
    pub fn solve_with_residual<const K: usize>(
        &self,
        fixed_values: &dyn Fn(VertexId) -> [f64; K],
    ) -> Result<(Vec<[f64; K]>, f64)> {
        self.solve_loaded(fixed_values, &|_| [0.0; K])
    }

    /// [`FixedBoundaryFactor::solve_with_residual`] with a load on every free vertex's equation:
    /// `Σ_j w_ij (x_i − x_j) = load(i)` (a periodic embedding's jumps across its cut, say).
    ///
    /// # Errors
    /// As [`FixedBoundaryFactor::solve`].
    pub fn solve_loaded<const K: usize>(
        &self,
        fixed_values: &dyn Fn(VertexId) -> [f64; K],
        load: &dyn Fn(VertexId) -> [f64; K],
    ) -> Result<(Vec<[f64; K]>, f64)> {
        let sys = self.sys;
        let n = sys.free.len();
        let mut rhs = Mat::<f64>::zeros(n, K);
        for (i, &v) in sys.free.iter().enumerate() {
            for (k, x) in load(v).iter().enumerate() {
                rhs[(i, k)] = *x;
            }
        }
        for &(row, v, w) in &self.coupling {
            let val = fixed_values(VertexId(v));
            for (k, x) in val.iter().enumerate() {
                rhs[(row as usize, k)] += w * x;
            }
        }
        let b = rhs.clone();
        match (&self.llt, &self.lu) {
            (Some(values), _) => {
                let sym = sys.sym_llt.as_ref().ok_or_else(|| Error::Internal("missing symbolic Cholesky".into()))?;
                let mut buf = MemBuffer::new(sym.solve_in_place_scratch::<f64>(K, Par::Seq));
                LltRef::new(sym, values).solve_in_place_with_conj(
                    Conj::No,
                    rhs.as_mut(),
                    Par::Seq,
                    MemStack::new(&mut buf),
                );
            }
            (_, Some(f)) => f.solve_in_place(rhs.as_mut()),
            _ => return Err(Error::Internal("no factorization".into())),
        }
        // Residual || A x - b || / || b || per column, with the sparse product done by sprs.
        let a = sprs::CsMatView::try_new_csc((n, n), &sys.col_ptr[..], &sys.row_idx[..], &self.values[..])
            .map_err(|(_, _, _, e)| Error::Internal(format!("Laplacian pattern: {e}")))?;
        let mut worst: f64 = 0.0;
        for k in 0..K {
            let x: Vec<f64> = (0..n).map(|i| rhs[(i, k)]).collect();
            let mut axk = vec![0.0; n];
            sprs::prod::mul_acc_mat_vec_csc(a.view(), &x[..], &mut axk[..]);
            let (mut num, mut den) = (0.0, 0.0);
            for i in 0..n {
                let bi = b[(i, k)];
                num += (axk[i] - bi) * (axk[i] - bi);
                den += bi * bi;
            }
            let rel = num.sqrt() / den.sqrt().max(tol::TINY);
            if den > 0.0 {
                worst = worst.max(rel);
            }
            if !rel.is_finite() || (den > 0.0 && rel > tol::SOLVE_RESIDUAL_REL) {
                return Err(Error::Numerical(format!(
                    "linear solve residual {rel:.3e} exceeds {:.0e}",
                    tol::SOLVE_RESIDUAL_REL
                )));
            }
        }
        let mut out = vec![[0.0; K]; sys.n_vertices];
        for (v, o) in out.iter_mut().enumerate() {
            let fi = sys.free_index[v];
            if fi == u32::MAX {
                *o = fixed_values(VertexId::from_idx(v));
            } else {
                for k in 0..K {
                    o[k] = rhs[(fi as usize, k)];
                }
            }
        }
        Ok((out, worst))
    }

    /// Relative residual of a full solution vector (all vertices), for tests and reports.
    pub fn residual<const K: usize>(&self, x: &[[f64; K]]) -> f64 {
        let sys = self.sys;
        let n = sys.free.len();
        let mut r = vec![[0.0; K]; n];
        let mut b = vec![[0.0; K]; n];
        for &(row, v, w) in &self.coupling {
            for k in 0..K {
                b[row as usize][k] += w * x[v as usize][k];
            }
        }
        for c in 0..n {
            let xc = x[sys.free[c].idx()];
            for p in sys.col_ptr[c]..sys.col_ptr[c + 1] {
                for k in 0..K {
                    r[sys.row_idx[p]][k] += self.values[p] * xc[k];
                }
            }
        }
        let mut num = 0.0;
        let mut den = 0.0;
        for i in 0..n {
            for k in 0..K {
                num += (r[i][k] - b[i][k]).powi(2);
                den += b[i][k].powi(2);
            }
        }
        num.sqrt() / den.sqrt().max(tol::TINY)
    }
}
