//! A symmetric positive definite system with two unknowns per free vertex, assembled from
//! per-triangle 6×6 blocks. The pattern (free vertices coupled through a triangle) never
//! changes during an optimization, so it is analysed once: [`BlockSystem::new`] builds the CSC
//! pattern, the slot of every triangle block entry and the symbolic Cholesky factorization
//! (AMD); each iteration only assembles values, factors numerically and solves
//! ([`BlockSystem::solve`]), checking the residual, as `linalg::solver` does for Laplacians.

use crate::error::{Error, InputError, Result};
use crate::tol;
use faer::dyn_stack::{MemBuffer, MemStack};
use faer::sparse::linalg::cholesky::{LltRef, SymbolicCholesky, SymmetricOrdering, factorize_symbolic_cholesky};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, Mat, Par, Side};

const NO: usize = usize::MAX;

/// Pattern, slots and symbolic factorization of the block system.
pub struct BlockSystem {
    /// Unknowns: `2 × free vertices`.
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Per triangle, the 36 value slots of its 6×6 block (`NO` where a corner is fixed).
    slots: Vec<[usize; 36]>,
    /// Per triangle, the unknown index of each of its six coordinates (`NO` when fixed).
    dofs: Vec<[usize; 6]>,
    diag: Vec<usize>,
    symbolic: SymbolicCholesky<usize>,
}

impl BlockSystem {
    /// The system of `triangles` over `n_vertices` with the vertices in `fixed` held, and which
    /// vertices are fixed: what every optimizer over a triangulation builds first.
    ///
    /// # Errors
    /// `Invalid` for a vertex out of range (in a triangle or in `fixed`); as [`BlockSystem::new`].
    pub fn for_vertices(n_vertices: usize, triangles: &[[u32; 3]], fixed: &[u32]) -> Result<(BlockSystem, Vec<bool>)> {
        if triangles.iter().flatten().any(|&v| v as usize >= n_vertices) {
            return Err(InputError::Invalid("a triangle names a vertex out of range".into()).into());
        }
        let mut is_fixed = vec![false; n_vertices];
        for &v in fixed {
            *is_fixed.get_mut(v as usize).ok_or_else(|| InputError::Invalid(format!("fixed vertex {v}")))? = true;
        }
        let mut next = 0u32;
        let free_index: Vec<u32> = is_fixed
            .iter()
            .map(|&f| {
                if f {
                    u32::MAX
                } else {
                    next += 1;
                    next - 1
                }
            })
            .collect();
        Ok((BlockSystem::new(&free_index, triangles)?, is_fixed))
    }

    /// Solves `(H + shift·I) x = rhs` from `shift = first`, growing the shift a hundredfold
    /// while the factorization fails and it is below `last` (a projected Hessian is only
    /// semi-definite).
    ///
    /// # Errors
    /// As [`BlockSystem::solve`], for the last shift tried.
    pub fn solve_shifted(&self, values: &[f64], rhs: &[f64], first: f64, last: f64) -> Result<Vec<f64>> {
        let mut shift = first;
        loop {
            match self.solve(values, shift, rhs) {
                Ok(x) => return Ok(x),
                Err(_) if shift < last => shift *= 100.0,
                Err(e) => return Err(e),
            }
        }
    }

    /// The system of `triangles` over vertices whose free index is `free_index[v]`
    /// (`u32::MAX` for fixed vertices).
    ///
    /// # Errors
    /// `Numerical` if the symbolic analysis fails; `Internal` if nothing is free.
    pub fn new(free_index: &[u32], triangles: &[[u32; 3]]) -> Result<BlockSystem> {
        let n_free = free_index.iter().filter(|&&i| i != u32::MAX).count();
        if n_free == 0 {
            return Err(Error::Internal("an optimization without free vertices".into()));
        }
        let n = 2 * n_free;
        let dofs: Vec<[usize; 6]> = triangles
            .iter()
            .map(|t| {
                let mut d = [NO; 6];
                for (k, &v) in t.iter().enumerate() {
                    let f = free_index[v as usize];
                    if f != u32::MAX {
                        d[2 * k] = 2 * f as usize;
                        d[2 * k + 1] = 2 * f as usize + 1;
                    }
                }
                d
            })
            .collect();
        // Rows of each column: every unknown of a triangle couples with every other one.
        let mut cols: Vec<Vec<usize>> = vec![Vec::new(); n];
        for d in &dofs {
            for &i in d.iter().filter(|&&i| i != NO) {
                cols[i].extend(d.iter().copied().filter(|&j| j != NO));
            }
        }
        let mut col_ptr = Vec::with_capacity(n + 1);
        let mut row_idx = Vec::new();
        col_ptr.push(0);
        for c in &mut cols {
            c.sort_unstable();
            c.dedup();
            row_idx.extend_from_slice(c);
            col_ptr.push(row_idx.len());
        }
        let slot = |r: usize, c: usize| -> usize {
            let rows = &row_idx[col_ptr[c]..col_ptr[c + 1]];
            col_ptr[c] + rows.binary_search(&r).expect("a pattern entry")
        };
        let slots = dofs
            .iter()
            .map(|d| {
                let mut s = [NO; 36];
                for a in 0..6 {
                    for b in 0..6 {
                        if d[a] != NO && d[b] != NO {
                            s[6 * a + b] = slot(d[a], d[b]);
                        }
                    }
                }
                s
            })
            .collect();
        let diag = (0..n).map(|i| slot(i, i)).collect();
        let pattern = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let symbolic = factorize_symbolic_cholesky(pattern, Side::Lower, SymmetricOrdering::Amd, Default::default())
            .map_err(|e| Error::Numerical(format!("symbolic Cholesky: {e:?}")))?;
        Ok(BlockSystem { n, col_ptr, row_idx, slots, dofs, diag, symbolic })
    }

    /// Unknowns of the system.
    pub fn len(&self) -> usize {
        self.n
    }

    pub fn is_empty(&self) -> bool {
        self.n == 0
    }

    /// The unknown index of each coordinate of triangle `t` (`usize::MAX` when fixed).
    pub fn dofs(&self, t: usize) -> &[usize; 6] {
        &self.dofs[t]
    }

    /// A zeroed value array of the pattern.
    pub fn zero_values(&self) -> Vec<f64> {
        vec![0.0; self.row_idx.len()]
    }

    /// Adds triangle `t`'s 6×6 block into `values`.
    pub fn add_block(&self, values: &mut [f64], t: usize, h: &[[f64; 6]; 6]) {
        let s = &self.slots[t];
        for a in 0..6 {
            for b in 0..6 {
                if s[6 * a + b] != NO {
                    values[s[6 * a + b]] += h[a][b];
                }
            }
        }
    }

    /// Multiplies every diagonal entry of `values` by `factor` (Marquardt's damping,
    /// `H + λ diag(H)` with `factor = 1 + λ`: each unknown damped on its own scale).
    pub fn scale_diagonal(&self, values: &mut [f64], factor: f64) {
        for &d in &self.diag {
            values[d] *= factor;
        }
    }

    /// Solves `(H + shift·I) x = rhs`, with `H` assembled in `values`: factors numerically on the
    /// symbolic analysis and checks the relative residual.
    ///
    /// # Errors
    /// `Numerical` when the factorization fails (not positive definite) or the residual
    /// exceeds [`tol::SOLVE_RESIDUAL_REL`].
    pub fn solve(&self, values: &[f64], shift: f64, rhs: &[f64]) -> Result<Vec<f64>> {
        let mut values = values.to_vec();
        for &d in &self.diag {
            values[d] += shift;
        }
        let pattern = SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx);
        let mat = SparseColMatRef::new(pattern, &values);
        let sym = &self.symbolic;
        let l = crate::linalg::numeric_llt(sym, mat)?;
        let mut x = Mat::<f64>::from_fn(self.n, 1, |i, _| rhs[i]);
        let mut buf = MemBuffer::try_new(sym.solve_in_place_scratch::<f64>(1, Par::Seq))
            .map_err(|e| Error::Numerical(format!("solve workspace: {e:?}")))?;
        LltRef::new(sym, &l).solve_in_place_with_conj(Conj::No, x.as_mut(), Par::Seq, MemStack::new(&mut buf));
        let x: Vec<f64> = (0..self.n).map(|i| x[(i, 0)]).collect();
        // Residual with the full (both triangles stored) pattern.
        let mut ax = vec![0.0; self.n];
        for (c, xc) in x.iter().enumerate() {
            for k in self.col_ptr[c]..self.col_ptr[c + 1] {
                ax[self.row_idx[k]] += values[k] * xc;
            }
        }
        let num: f64 = ax.iter().zip(rhs).map(|(a, b)| (a - b) * (a - b)).sum::<f64>().sqrt();
        let den: f64 = rhs.iter().map(|b| b * b).sum::<f64>().sqrt();
        let rel = num / den.max(tol::TINY);
        if !rel.is_finite() || (den > 0.0 && rel > tol::SOLVE_RESIDUAL_REL) {
            return Err(Error::Numerical(format!(
                "Newton system residual {rel:.3e} exceeds {:.0e}",
                tol::SOLVE_RESIDUAL_REL
            )));
        }
        Ok(x)
    }
}
