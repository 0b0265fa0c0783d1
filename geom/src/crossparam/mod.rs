//! Cross-parameterization over a common base domain (Kraevoy & Sheffer 2004, section 4): every
//! patch of both refined meshes is mapped onto one shared canonical triangle ([`patch_param`]),
//! and a vertex of one mesh is carried to the other by locating its triangle coordinates in the
//! other mesh's embedding of the same patch ([`compose`], [`crate::planar::locate`]). [`global`] maps each
//! closed mesh onto the whole base domain at once, path vertices free, as a second candidate
//! composition that does not depend on where each mesh's paths were traced. [`smooth`] then lowers
//! the stretch by relocating vertices inside the common domain; [`visible`] and [`slide`] fix what
//! the shared evaluator would count as folded, one vertex at a time; [`untangle`] re-embeds whole
//! regions around the folds that remain.

pub mod compose;
pub mod foldover_free;
pub mod global;
pub mod on_surface;
pub mod patch_param;
pub mod planar_untangle;
pub mod slide;
pub mod smooth;
pub mod untangle;
pub mod visible;

pub use compose::compose;
pub use patch_param::{PatchParam, PatchParamOptions, SideFractions, parameterize_patches, parameterize_patches_with};

/// The canonical triangle's corners, counter-clockwise.
pub const TRIANGLE: [[f64; 2]; 3] = [[0.0, 0.0], [1.0, 0.0], [0.5, 0.866_025_403_784_438_6]];
