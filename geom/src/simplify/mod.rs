//! Mesh simplification: quadric-error half-edge collapses ([`qem`]). Used to build coarse
//! base meshes and multi-resolution test pairs; every output vertex is an input vertex.

pub mod qem;

pub use qem::{Collapse, CollapseHistory, DecimateOptions, DecimateResult, decimate};

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;
    use crate::topology::summary;

    #[test]
    fn decimation_keeps_topology_and_protected_vertices() {
        for (mesh, target) in
            [(shapes::icosphere(3), 60), (shapes::torus(40, 20, 1.0, 0.3), 120), (shapes::grid(20), 40)]
        {
            let before = summary(&mesh);
            let protected = vec![crate::VertexId(0), crate::VertexId(7)];
            let r = decimate(
                &mesh,
                &DecimateOptions { target_vertices: target, protected: protected.clone(), ..Default::default() },
            )
            .expect("decimate");
            let after = summary(&r.mesh);
            assert_eq!(r.mesh.n_vertices(), target, "reaches the target");
            assert_eq!(
                (after.genus, after.boundary_loops, after.components),
                (before.genus, before.boundary_loops, before.components)
            );
            assert_eq!(r.collapses.len(), mesh.n_vertices() - target);
            for p in protected {
                assert!(r.kept.contains(&p));
            }
            for (i, &k) in r.kept.iter().enumerate() {
                assert_eq!(r.mesh.positions()[i], mesh.position(k), "half-edge collapses keep positions");
            }
            // No face turned over relative to the surface it replaces: on the sphere every
            // normal still points outward.
            if before.genus == 0 && before.boundary_loops == 0 {
                for f in 0..r.mesh.n_faces() {
                    let p = r.mesh.face_points(crate::FaceId::from_idx(f));
                    let n = (p[1] - p[0]).cross(&(p[2] - p[0]));
                    assert!(n.dot(&(p[0].coords + p[1].coords + p[2].coords)) > 0.0);
                }
            }
        }
    }

    #[test]
    fn protected_out_of_range_is_an_input_error() {
        let m = shapes::icosphere(1);
        let e = decimate(
            &m,
            &DecimateOptions { target_vertices: 10, protected: vec![crate::VertexId(999)], ..Default::default() },
        );
        assert!(e.is_err_and(|e| e.is_input()));
    }
}
