//! Graph geodesics on a mesh: Dijkstra over vertices, multi-source Dijkstra over the face dual
//! graph (approximate geodesic Voronoi clusters), and shortest paths over vertices plus
//! adaptive edge nodes (Kwok et al., section 4). Every search can be restricted to a face subset.

mod edge_nodes;
mod face_voronoi;
mod heap;
mod vertex_dijkstra;

pub use edge_nodes::{EdgeNodeGraph, EdgeNodeOptions, NodeId, PathOptions, SearchFilter, SurfacePath, shortest_path};
pub use face_voronoi::{FaceVoronoiOptions, FaceVoronoiResult, face_voronoi};
pub(crate) use heap::MinHeap;
pub use vertex_dijkstra::{VertexDijkstraOptions, VertexDijkstraResult, vertex_dijkstra};
