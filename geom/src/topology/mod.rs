//! Topology queries: connected components, boundary loops, Euler characteristic and genus,
//! the summary `surfmap inspect` prints and the checks a mesh passes before any job (`admit`),
//! surface points and closest-point location (BVH).

mod admit;
mod components;
mod locate;
mod surface_point;

pub use crate::mesh::boundary_loops;
pub use admit::checked_summary;
pub use components::{Components, PartSummary, components, parts};
pub(crate) use locate::plane_barycentric;
pub use locate::{Locator, Projection};
pub use surface_point::SurfacePoint;

use crate::mesh::Mesh;
use serde::Serialize;

/// Topological and size summary of a mesh (the body of `surfmap inspect`).
#[derive(Debug, Clone, PartialEq, Serialize, serde::Deserialize)]
pub struct Summary {
    pub vertices: usize,
    pub faces: usize,
    pub edges: usize,
    pub components: usize,
    pub boundary_loops: usize,
    /// Euler characteristic V - E + F.
    pub euler_characteristic: i64,
    /// Sum of the genus of each component.
    pub genus: i64,
    /// Always true for a built [`Mesh`] (construction refuses non-manifold input).
    pub manifold: bool,
    /// Always true for a built [`Mesh`] (construction refuses non-orientable input).
    pub orientable: bool,
    /// `[[xmin, ymin, zmin], [xmax, ymax, zmax]]`.
    pub bbox: [[f64; 3]; 2],
    pub bbox_diagonal: f64,
    pub area: f64,
    /// The file's own vertex count when it splits vertices at seams (glTF): the range of the
    /// vertex ids a job names on it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub input_vertices: Option<usize>,
    /// The file's vertex attributes by glTF name (`TEXCOORD_0`, `COLOR_0`...), as a job's
    /// `transfer` names them; absent when not recorded (checked at run time then).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub attribute_names: Option<Vec<String>>,
}

impl Summary {
    /// How many vertex ids a job may name on this mesh.
    pub fn id_count(&self) -> usize {
        self.input_vertices.unwrap_or(self.vertices)
    }
}

/// Euler characteristic V - E + F.
pub fn euler_characteristic(mesh: &Mesh) -> i64 {
    mesh.n_vertices() as i64 - mesh.n_edges() as i64 + mesh.n_faces() as i64
}

/// Genus from V - E + F = 2C - 2g - b, summed over components.
pub fn genus(mesh: &Mesh) -> i64 {
    let c = components(mesh).count as i64;
    let b = boundary_loops(mesh).len() as i64;
    (2 * c - b - euler_characteristic(mesh)) / 2
}

/// Computes the [`Summary`].
pub fn summary(mesh: &Mesh) -> Summary {
    let comps = components(mesh).count;
    let loops = boundary_loops(mesh).len();
    let chi = euler_characteristic(mesh);
    let (lo, hi) = mesh.bbox();
    Summary {
        vertices: mesh.n_vertices(),
        faces: mesh.n_faces(),
        edges: mesh.n_edges(),
        components: comps,
        boundary_loops: loops,
        euler_characteristic: chi,
        genus: (2 * comps as i64 - loops as i64 - chi) / 2,
        manifold: true,
        orientable: true,
        bbox: [[lo.x, lo.y, lo.z], [hi.x, hi.y, hi.z]],
        bbox_diagonal: (hi - lo).norm(),
        area: mesh.area(),
        input_vertices: None,
        attribute_names: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn closed_shapes_have_expected_genus() {
        let t = shapes::tetrahedron();
        assert_eq!(euler_characteristic(&t), 2);
        assert_eq!(genus(&t), 0);
        let s = shapes::icosphere(2);
        assert_eq!(genus(&s), 0);
        assert_eq!(boundary_loops(&s).len(), 0);
        let tor = shapes::torus(12, 8, 2.0, 0.5);
        assert_eq!(euler_characteristic(&tor), 0);
        assert_eq!(genus(&tor), 1);
    }

    #[test]
    fn grid_is_a_disk() {
        let g = shapes::grid(5);
        let s = summary(&g);
        assert_eq!(s.boundary_loops, 1);
        assert_eq!(s.genus, 0);
        assert_eq!(s.euler_characteristic, 1);
        assert_eq!(s.components, 1);
    }
}
