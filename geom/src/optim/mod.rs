//! Injective optimization of maps: the building blocks of a global distortion minimization
//! that keeps a map bijective at every step (issue 35). [`sym_dirichlet`] is the per-triangle
//! energy with its projected Hessian ([`isotropic`]: in closed form), [`max_step`] the flip-avoiding step bound,
//! [`block_system`] the fixed-pattern sparse Newton system, and [`newton`] the optimizer.

pub mod block_system;
mod domain;
pub mod isotropic;
mod line_search;
pub mod max_step;
pub mod newton;
pub mod sym_dirichlet;

pub use newton::{InjectiveNewton, InjectiveNewtonOptions, InjectiveNewtonResult};
pub use sym_dirichlet::RestTriangle;
