//! surfmap's geometry core: meshes in, validated, measured.
//!
//! No async, no database, no HTTP: pure functions over [`mesh::Mesh`]. Only [`io`] touches
//! bytes. The flow of a mapping job through this crate is:
//!
//! 1. [`io::read`] parses and validates both meshes ([`mesh::Mesh::from_raw`]).
//! 2. [`topology`] checks that their genus and boundaries agree.
//! 3. [`geodesic`] finds anchor clusters and paths; [`param`] flattens patches over shared
//!    domains with [`linalg`] solvers.
//! 4. [`map::SurfaceMap`] records where every vertex lands; [`metrics`] judges the result with
//!    the definitions of the shared evaluator.

pub mod crossparam;
pub mod domain;
pub mod error;
pub mod geodesic;
pub mod homology;
pub mod io;
pub mod linalg;
pub mod map;
pub mod mesh;
pub mod metrics;
pub mod optim;
pub mod param;
pub mod pipeline;
pub mod planar;
pub mod progress;
pub mod quad;
pub mod simplify;
pub mod sphere;
pub mod tol;
pub mod topology;

pub use error::{Error, InputError, Result};
pub use mesh::{EdgeId, FaceId, HalfedgeId, Mesh, VertexId};
