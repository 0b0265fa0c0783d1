//! Sparse linear algebra for mesh Laplacians: edge weights (uniform, cotangent, mean value),
//! CSC storage and products with `sprs`, and fixed-boundary solvers on `faer`'s sparse Cholesky / LU
//! with the symbolic factorization computed once and reused for every numeric factorization.

mod ordering;
mod solver;
mod weights;

pub use ordering::{COARSEN_MIN, coarsened_amd};
pub use solver::{FixedBoundaryFactor, FixedBoundarySystem, numeric_llt};
pub use weights::{DirectedWeights, Weights, directed_weights};
