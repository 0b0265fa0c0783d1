//! Surface maps: where every source vertex lands on a target mesh (face + barycentric
//! coordinates), the re-embedded source mesh built from it, composition of maps, and point
//! location (closest point through a BVH) to turn positions into a map.

mod surface_map;

pub mod transfer;
pub use surface_map::SurfaceMap;
