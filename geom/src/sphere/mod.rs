//! Genus-0 surfaces on the unit sphere, bijectively at every step (issue 50).
//!
//! - [`orient`]: the exact orientation of spherical triangles and the check that a placement is
//!   a bijective spherical triangulation (every triangle positive, degree 1).
//! - [`tutte`]: a known-bijective start, Tutte's embedding through the gnomonic plane.
//! - [`max_step`]: the longest step along a direction before a triangle inverts (a cubic).
//! - [`barrier`]: the orientation barrier of triangles too large for their chord to see it.
//! - [`measure`]: images of sphere points and how an image triangle is measured on its surface.
//! - [`newton`]: injective projected Newton for points on the sphere, any image energy.
//! - [`kernel`]: where a vertex goes inside its ring when a collapse is undone.
//! - [`multires`]: coarse to fine over a quadric decimation's collapses.
//! - [`embed`]: a mesh's low-distortion bijective sphere embedding.
//! - [`align`]: the rotation that carries one embedding's anchors onto the other's.
//! - [`locate`]: points located in a spherical triangulation and carried onto its surface.
//! - [`landmarks`]: anchors brought onto their partners' points, the triangulation kept bijective.
//! - [`untangle`]: image triangles turned back upright on the surface, on the sphere.
//! - [`pair`]: a map between two genus-0 surfaces, bijective at every step.
//!
//! Imports run downward: `pair` → `landmarks`, `untangle`, `locate`, `align`; `locate` → `measure`; `embed` → `multires` → `kernel`, `newton` → `measure`, `barrier`, `max_step`, `orient`;
//! `tutte` → `linalg`.

pub mod align;
pub mod barrier;
pub mod embed;
pub mod kernel;
pub mod landmarks;
pub mod locate;
pub mod max_step;
pub mod measure;
pub mod multires;
pub mod newton;
pub mod orient;
pub mod pair;
pub mod tutte;
pub mod untangle;

pub use embed::{SphereEmbedOptions, SphereEmbedReport, SphereEmbedding, embed_sphere};
pub use measure::{OnSphere, SphereImage};
pub use newton::{SphereNewton, SphereNewtonOptions, SphereNewtonResult};
pub use pair::{SpherePair, SpherePairOptions, SpherePairReport, sphere_pair};
