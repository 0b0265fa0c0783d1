//! Common base domains: consistent triangular patch layouts on two meshes whose corners are
//! corresponding anchors (Kwok, Zhang, Wang 2012; Kraevoy, Sheffer 2004).
//!
//! [`tracer`] keeps non-crossing paths on one mesh, [`walks`] reads the regions off their
//! rotation system, [`cuts`] finds the Voronoi cues, [`voronoi`] and [`greedy`] build the two
//! layouts, and [`refine`] cuts a mesh along its layout into patches.

pub mod complete;
pub mod cuts;
pub mod flip;
pub mod greedy;
pub mod loops;
mod path;
pub mod refine;
pub mod straighten;
pub mod tracer;
pub mod voronoi;
pub mod walks;

pub(crate) use path::uf_find;
pub use path::{LayoutPath, Sector};

use serde::{Deserialize, Serialize};

/// A triangular patch: corner anchors and the halves that bound it (`sides[i]` runs from
/// `corners[i]` to `corners[i + 1]`, with the patch on its right).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Patch {
    pub corners: [u32; 3],
    pub sides: [u32; 3],
}

/// Options shared by the layout builders.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LayoutOptions {
    /// Edge nodes per edge (the paper's `b` and a cap).
    pub edge_nodes: crate::geodesic::EdgeNodeOptions,
    /// Upper bound on paths tried while triangulating or repairing, against endless searches.
    pub max_attempts: usize,
    /// Rebuilds after a failed layout: first without denser anchor rings, then with twice the
    /// minimal edge-node count (minus one), and so on.
    pub rebuilds: u32,
    /// Rounds of path straightening on both meshes after the layout is built (0: none).
    pub straighten_rounds: usize,
    /// Path flipping after the layout is built, before straightening.
    pub flip: flip::FlipOptions,
    /// Use the other base domain (`voronoi` <-> `greedy`) when a `voronoi` layout cannot be
    /// completed after every rebuild, or when the requested one's maps fold and the other's fold
    /// less (reported in `LayoutStats::fallback`). `greedy_fallback` is its former name.
    #[serde(alias = "greedy_fallback")]
    pub fallback: bool,
}

impl Default for LayoutOptions {
    fn default() -> Self {
        Self {
            edge_nodes: Default::default(),
            max_attempts: 20_000,
            rebuilds: 3,
            straighten_rounds: 1,
            flip: Default::default(),
            fallback: true,
        }
    }
}

/// What a layout construction did.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct LayoutStats {
    pub paths: usize,
    pub patches: usize,
    pub cuts: usize,
    pub multiple_linkages: usize,
    pub triangulation_paths: usize,
    pub postponed: usize,
    pub failed_traces: usize,
    /// Layout rebuilds at higher edge-node density, and the density finally used.
    pub rebuilds: u32,
    pub edge_nodes_min: u32,
    /// Paths shortened by straightening (both meshes).
    pub straightened: usize,
    /// Paths flipped (the same on both meshes).
    pub flipped: usize,
    /// The base domain used instead of the requested one (`"greedy"` or `"voronoi"`), if any:
    /// the requested one could not be laid out, or its maps folded where these do not.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fallback: Option<String>,
}

/// Patches from the walks of a layout: its triangular walks (all of them once the layout is
/// complete).
pub fn patches_of(t: &tracer::Tracer) -> Vec<Patch> {
    walks::walks(t)
        .into_iter()
        .filter(|w| w.halves.len() == 3)
        .map(|w| {
            let c = w.corners(t);
            Patch { corners: [c[0], c[1], c[2]], sides: [w.halves[0], w.halves[1], w.halves[2]] }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::LayoutOptions;

    #[test]
    fn the_fallback_option_keeps_its_former_name() {
        for key in ["fallback", "greedy_fallback"] {
            let o: LayoutOptions = serde_json::from_str(&format!("{{\"{key}\": false}}")).unwrap();
            assert!(!o.fallback, "{key}");
        }
        assert!(LayoutOptions::default().fallback);
    }
}
