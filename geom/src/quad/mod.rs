//! Method `quad` (Yu & Chuang, "Consistent Mesh Parameterizations and Its Application in Mesh
//! Morphing"): N models cut the same way into quad patches, every patch parameterized over the
//! unit square with stretch optimization and feature alignment, then resampled on one
//! semi-regular grid so all remeshes share their connectivity.
//!
//! - [`layout`]: the patch/corner/curve combinatorics shared by all models.
//! - [`partition`]: the genus-0 two-quad partition from four partition points.
//! - [`patch_param`]: progressive mesh, mean-value base embedding, coarse-to-fine refinement.
//! - [`stretch`], [`brent`], [`kernel`]: Sander's vertex optimization and its helpers.
//! - [`sides`], [`separate`]: keeping each feature on its side of the loop on every model.
//! - [`remesh`]: uniform resampling; [`warp`]: feature alignment; [`consistent`]: all models.
//! - [`morph`], [`wavelet`]: spatial, multi-target and wavelet-domain morphs.

pub mod adaptive;
pub mod brent;
pub mod consistent;
pub mod kernel;
pub mod layout;
pub mod morph;
pub mod partition;
pub mod patch_param;
pub mod remesh;
pub mod separate;
pub mod sides;
pub mod stretch;
pub mod surface;
pub mod tri_quads;
pub mod warp;
pub mod wavelet;

pub use layout::{QuadLayout, QuadPatchLayout, QuadSide};
pub use partition::{PartitionOptions, PartitionResult, PatchMesh, partition_genus0, partition_genus0_sided};
pub use patch_param::{BaseEmbedding, PatchParamResult, QuadParamOptions, base_embedding, coarse_to_fine};
