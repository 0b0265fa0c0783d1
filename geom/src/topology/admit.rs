//! The checks a mesh passes before anything runs on it (the server's upload, the CLI's
//! `inspect`, `map` and `remesh`): every number its summary holds is finite, it has an extent,
//! and a closed mesh has no zero-area face. Both faces call [`checked_summary`].

use super::{Summary, summary};
use crate::error::{InputError, Result};
use crate::mesh::{FaceId, Mesh};
use crate::tol::{DEGENERATE_AREA_REL, MAX_COORDINATE};

/// The [`Summary`] of a mesh jobs can run on; `input_vertices` is the file's own vertex count
/// when it splits vertices at seams (glTF).
///
/// # Errors
/// `InputError::NotFinite` (`mesh_not_finite`) for a coordinate beyond ±[`MAX_COORDINATE`] or a
/// summary number that overflows; `InputError::NoExtent` (`mesh_no_extent`) when all vertices
/// sit at one point or all faces are flat; `InputError::ZeroAreaFace` (`zero_area_face`) for a
/// closed mesh with a face of zero area.
pub fn checked_summary(mesh: &Mesh, input_vertices: Option<usize>) -> Result<Summary> {
    check_coordinates(mesh)?;
    let s = Summary { input_vertices, ..summary(mesh) };
    s.check_finite()?;
    if s.bbox_diagonal <= 0.0 {
        return Err(InputError::NoExtent(format!("all {} vertices sit at one point", s.vertices)).into());
    }
    let largest = (0..mesh.n_faces()).map(|f| mesh.face_area(FaceId::from_idx(f))).fold(0.0, f64::max);
    if largest <= DEGENERATE_AREA_REL * s.bbox_diagonal * s.bbox_diagonal {
        return Err(InputError::NoExtent(format!(
            "every face is flat (largest face area {largest:e}, bounding box diagonal {:e})",
            s.bbox_diagonal
        ))
        .into());
    }
    if s.boundary_loops == 0 {
        let flat = (0..mesh.n_faces())
            .map(|f| (f, mesh.face_area(FaceId::from_idx(f))))
            .find(|&(_, a)| a <= DEGENERATE_AREA_REL * largest);
        if let Some((face, area)) = flat {
            return Err(InputError::ZeroAreaFace { face, area, largest }.into());
        }
    }
    Ok(s)
}

fn check_coordinates(mesh: &Mesh) -> Result<()> {
    for (v, p) in mesh.positions().iter().enumerate() {
        if let Some(c) = p.iter().find(|c| !c.is_finite() || c.abs() > MAX_COORDINATE) {
            return Err(InputError::NotFinite(format!(
                "vertex {v} has the coordinate {c:e}, beyond ±{MAX_COORDINATE:e}: lengths, areas and their \
                 products overflow; scale the mesh down"
            ))
            .into());
        }
    }
    Ok(())
}

impl Summary {
    /// Every floating-point number of the summary is finite.
    ///
    /// # Errors
    /// `InputError::NotFinite` naming the first that is not.
    pub fn check_finite(&self) -> Result<()> {
        let bbox = self.bbox.iter().flatten().copied();
        let named = bbox.map(|v| ("bbox", v)).chain([("bbox_diagonal", self.bbox_diagonal), ("area", self.area)]);
        for (what, v) in named {
            if !v.is_finite() {
                return Err(InputError::NotFinite(format!(
                    "the mesh's {what} is {v}: its coordinates overflow f64; scale the mesh down"
                ))
                .into());
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{P3, shapes};

    fn scaled(m: &Mesh, k: f64) -> Mesh {
        m.with_positions(m.positions().iter().map(|p| P3::from(p.coords * k)).collect()).unwrap()
    }

    #[test]
    fn ordinary_meshes_pass_with_their_summary() {
        for m in [shapes::tetrahedron(), shapes::icosphere(2), shapes::grid(4), shapes::torus(8, 6, 1.0, 0.3)] {
            assert_eq!(checked_summary(&m, None).unwrap(), summary(&m));
        }
        assert!(checked_summary(&scaled(&shapes::icosphere(1), 1e70), None).is_ok());
        assert!(checked_summary(&scaled(&shapes::icosphere(1), 1e-70), None).is_ok());
    }

    #[test]
    fn overflow_no_extent_and_flat_faces_are_named() {
        let code = |m: &Mesh| checked_summary(m, None).unwrap_err().code();
        assert_eq!(code(&scaled(&shapes::tetrahedron(), 1e200)), "mesh_not_finite");
        assert_eq!(code(&scaled(&shapes::tetrahedron(), 0.0)), "mesh_no_extent");
        // A closed tetrahedron with one corner of face 0 moved onto the midpoint of the
        // face's opposite edge: face 0 is flat, the others are not.
        let t = shapes::tetrahedron();
        let mut p = t.positions().to_vec();
        let [_, b, c] = t.face_points(FaceId::from_idx(0));
        p[t.faces()[0][0].0 as usize] = P3::from((b.coords + c.coords) * 0.5);
        assert_eq!(code(&t.with_positions(p).unwrap()), "zero_area_face");
        // The same flat face in an open mesh is allowed.
        let g = shapes::grid(3);
        let mut q = g.positions().to_vec();
        let f = g.faces()[0];
        q[f[0].0 as usize] = P3::from((q[f[1].0 as usize].coords + q[f[2].0 as usize].coords) * 0.5);
        assert!(checked_summary(&g.with_positions(q).unwrap(), None).is_ok());
    }

    #[test]
    fn a_summary_with_an_overflowed_number_is_refused() {
        let mut s = summary(&shapes::tetrahedron());
        assert!(s.check_finite().is_ok());
        s.area = f64::INFINITY;
        assert_eq!(s.check_finite().unwrap_err().code(), "mesh_not_finite");
    }
}
