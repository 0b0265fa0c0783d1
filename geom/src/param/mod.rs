//! Disk parameterization: boundary maps onto convex polygons by arc length, the fixed-boundary
//! embeddings of Tutte (uniform), Eck et al. (harmonic, cotangent) and Floater (mean value),
//! Sander's stretch and its minimization by reweighting (Yoshizawa et al.), and an exact
//! injectivity check of the planar result.

mod boundary;
mod disk;
mod injectivity;
mod stretch;

pub use boundary::{BoundaryShape, disk_boundary, map_boundary_to_polygon};
pub use disk::{DiskParamOptions, DiskParamResult, parameterize_disk};
pub use injectivity::{InjectivityReport, check_injective};
pub use stretch::{StretchOptions, StretchResult, face_stretch, minimize_stretch, stretch, stretch_jacobian};

/// A 2D point.
pub type Uv = [f64; 2];
