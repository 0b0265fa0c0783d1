//! Method `homology` (Carner, Jin, Gu, Qin 2005): canonical homology bases through one base
//! vertex, the 4g-gon fundamental domain they cut, and maps between two surfaces through it.
//!
//! Shared tools it builds on live below it: [`crate::mesh::refine`] (midpoint refinement that
//! remembers where every refined face lies), [`crate::mesh::cut`] (slicing a mesh open along edge
//! paths) and [`crate::planar`] (point location in a plane).
//!
//! - [`cocycle`]: Z2 cohomology by tree–cotree (which loops are non-separating).
//! - [`search`]: shortest non-separating loops and side-to-side paths on a cut surface.
//! - [`word`]: boundary words, the canonical rotation, intersection numbers at the base.
//! - [`basis`]: the canonical basis itself.
//! - [`classes`]: integer classes of basis loops; H1 in reference bases.
//! - [`domain`]: the cut disk on the regular 4g-gon.
//! - [`flat`]: a genus-1 mesh on its flat torus (periodic Tutte embedding).
//! - [`sides`]: one mesh's basis, fundamental domain and flat torus, built once per job.
//! - [`map`]: maps both ways through the two domains, rotation τ, induced map on H1.
//! - [`matching`]: an explicit curve matching (`a1 -> b1`, …) realized by basis and rotation.
//! - [`natural`]: the classes reachable by bases and rotations, least stretched first.
//! - [`compose`]: two planar disks composed into maps, the interior anchor warp.
//! - [`overlay`]: the meta-mesh, both tessellations merged.
//! - [`prune`]: the meta-mesh reduced to the edges needed above a dihedral-angle threshold.
//! - [`features`]: feature curves (boundary loops included), the double cover they define.
//! - [`feature_cut`]: a genus-0 surface cut open so that every feature lies on the boundary.
//! - [`feature_domain`]: that disk on the unit circle, arcs shared by both meshes.
//! - [`feature_handles`]: the same cut on a surface with handles (basis loops around the curves).
//! - [`feature_map`]: maps both ways that take every feature onto its partner.

pub mod basis;
pub mod classes;
pub mod cocycle;
pub mod compose;
pub mod curve_align;
pub mod domain;
pub mod feature_cut;
pub mod feature_domain;
pub mod feature_handles;
pub mod feature_map;
pub mod feature_overlay;
pub mod features;
pub mod flat;
pub mod map;
pub mod matching;
pub mod natural;
pub mod overlay;
pub mod prune;
pub mod search;
pub mod sides;
pub mod word;

pub use basis::{CanonicalBasisOptions, CanonicalBasisResult, canonical_basis};
pub use domain::{FundamentalDomainResult, fundamental_domain};
pub use map::{HomologyMapOptions, HomologyMapResult, homology_map, rotation_count};
