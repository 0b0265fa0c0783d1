//! Feature curves for the homology method (Carner et al. section 3.4, "feature handle
//! conversion"): validating corresponding curves, and the double cover that turns `n` curves
//! (boundary loops included) on a genus-`g` surface into `n − 1` extra handles, genus
//! `2g + n − 1`.
//!
//! A feature is an open edge path of interior vertices, or a whole boundary loop. Slitting the
//! surface along the open ones and gluing a mirrored copy along every slit and boundary gives
//! the double cover; [`double_cover`] builds it explicitly (its genus is what the report
//! states). The cut that [`super::feature_cut`] makes is the half of a cut of the double cover
//! that is symmetric under the deck involution, see there.

use crate::error::{Error, InputError, Result};
use crate::mesh::cut::{cut_along, edge_between, path_edges};
use crate::mesh::{Mesh, VertexId};
use crate::topology;

/// How a feature curve lies on its mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum CurveKind {
    /// A simple edge path through interior vertices, from its first vertex to its last.
    Open,
    /// A whole boundary loop, listed from its start in the boundary's direction (interior on
    /// the left) and not repeating the start at the end.
    Boundary,
}

/// A validated feature curve.
#[derive(Debug, Clone, PartialEq)]
pub struct Curve {
    pub vertices: Vec<VertexId>,
    pub kind: CurveKind,
}

/// Checks one feature curve given as raw vertex ids. A closed list (last = first) or a list of
/// boundary vertices that runs around a whole boundary loop is a boundary feature; anything
/// else must be a simple path of interior vertices.
///
/// # Errors
/// `InputError::Features` naming `what` and the fault.
pub fn validate_curve(mesh: &Mesh, raw: &[u64], what: &str) -> Result<Curve> {
    let bad = |m: String| -> Error { InputError::Features(format!("{what}: {m}")).into() };
    if raw.len() < 2 {
        return Err(bad(format!("needs at least 2 vertices, has {}", raw.len())));
    }
    if raw.len() > mesh.n_vertices() + 1 {
        return Err(bad(format!("has {} vertices, the mesh only {}", raw.len(), mesh.n_vertices())));
    }
    let mut v = Vec::with_capacity(raw.len());
    for &r in raw {
        if r >= mesh.n_vertices() as u64 {
            return Err(bad(format!("vertex {r} is out of range (the mesh has {} vertices)", mesh.n_vertices())));
        }
        v.push(VertexId(r as u32));
    }
    let closed = v.len() > 2 && v[0] == v[v.len() - 1];
    if closed {
        v.pop();
    }
    let mut seen = std::collections::HashSet::with_capacity(v.len());
    if let Some(r) = v.iter().find(|x| !seen.insert(**x)) {
        return Err(bad(format!("repeats vertex {}", r.0)));
    }
    for w in v.windows(2) {
        if edge_between(mesh, w[0], w[1]).is_none() {
            return Err(bad(format!("vertices {} and {} are not joined by an edge", w[0].0, w[1].0)));
        }
    }
    let on_boundary = v.iter().filter(|x| mesh.is_boundary_vertex(**x)).count();
    if closed || (on_boundary == v.len() && v.len() > 2) {
        return boundary_curve(mesh, v).map_err(&bad);
    }
    if let Some(b) = v.iter().find(|x| mesh.is_boundary_vertex(**x)) {
        return Err(bad(format!(
            "an open feature touches the boundary at vertex {}; list the whole boundary loop as a feature instead",
            b.0
        )));
    }
    Ok(Curve { vertices: v, kind: CurveKind::Open })
}

/// A boundary feature: `v` must run along one whole boundary loop in its direction.
fn boundary_curve(mesh: &Mesh, v: Vec<VertexId>) -> std::result::Result<Curve, String> {
    let loops = topology::boundary_loops(mesh);
    let Some(lp) = loops.iter().find(|l| l.iter().any(|&h| mesh.tail(h) == v[0])) else {
        return Err(format!("closed feature starts at vertex {}, which is not on the boundary", v[0].0));
    };
    let ring: Vec<VertexId> = lp.iter().map(|&h| mesh.tail(h)).collect();
    let s = ring.iter().position(|&x| x == v[0]).unwrap_or(0);
    let rotated: Vec<VertexId> = (0..ring.len()).map(|i| ring[(s + i) % ring.len()]).collect();
    if rotated != v {
        let mut back = rotated.clone();
        back[1..].reverse();
        let hint = if back == v { " (it runs against the boundary's direction)" } else { "" };
        return Err(format!(
            "closed feature must list the whole boundary loop through vertex {} ({} vertices) in order{hint}",
            v[0].0,
            ring.len()
        ));
    }
    Ok(Curve { vertices: v, kind: CurveKind::Boundary })
}

/// Checks that curves share no vertex and that corresponding curves have the same kind.
///
/// # Errors
/// `InputError::Features`.
pub fn check_disjoint(curves: &[Curve], n_vertices: usize, side: &str) -> Result<()> {
    let mut owner = vec![u32::MAX; n_vertices];
    for (i, c) in curves.iter().enumerate() {
        for v in &c.vertices {
            let o = &mut owner[v.idx()];
            if *o != u32::MAX {
                return Err(InputError::Features(format!("{side} features {} and {i} share vertex {}", *o, v.0)).into());
            }
            *o = i as u32;
        }
    }
    Ok(())
}

/// Genus of the double cover of a genus-`g` surface along `n` curves (boundaries included).
pub fn doubled_genus(genus: usize, curves: usize) -> usize {
    if curves == 0 { genus } else { 2 * genus + curves - 1 }
}

/// The double cover: the mesh slit along its open curves, and a mirrored copy glued to it
/// along every slit and every boundary loop. Vertices on slits and boundaries are shared, the
/// others are duplicated (the copy's follow the original's); edges that join two boundary
/// vertices through the interior are split first, so that the result is a manifold.
///
/// # Errors
/// `Internal` if the glued mesh fails validation.
pub fn double_cover(mesh: &Mesh, curves: &[Curve]) -> Result<Mesh> {
    let open: Vec<Vec<VertexId>> =
        curves.iter().filter(|c| c.kind == CurveKind::Open).map(|c| c.vertices.clone()).collect();
    let slit = cut_along(mesh, &path_edges(mesh, &open)?)?;
    // An interior edge between two boundary vertices would be shared by four faces once the
    // boundary is glued: split such chords first (the geometry is unchanged).
    let chords: Vec<[VertexId; 2]> = (0..slit.mesh.n_edges())
        .map(crate::mesh::EdgeId::from_idx)
        .filter(|&e| !slit.mesh.is_boundary_edge(e))
        .map(|e| slit.mesh.edge_vertices(e))
        .filter(|[a, b]| slit.mesh.is_boundary_vertex(*a) && slit.mesh.is_boundary_vertex(*b))
        .collect();
    let refined = crate::mesh::refine::Refined::identity(&slit.mesh).split_edges(&chords)?;
    let m = &refined.mesh;
    let n = m.n_vertices();
    let mut pos = m.positions().to_vec();
    let copy: Vec<u32> = (0..n)
        .map(|v| {
            if m.is_boundary_vertex(VertexId::from_idx(v)) {
                v as u32
            } else {
                pos.push(m.positions()[v]);
                (pos.len() - 1) as u32
            }
        })
        .collect();
    let mut tris = m.face_indices();
    for f in m.face_indices() {
        tris.push([copy[f[0] as usize], copy[f[2] as usize], copy[f[1] as usize]]);
    }
    Mesh::from_triangles(pos, &tris).map_err(|e| Error::Internal(format!("double cover invalid: {e}")))
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::mesh::shapes;

    /// A shortest edge path from `a` to `b` through vertices not in `used` (nor next to them).
    pub fn path(mesh: &Mesh, a: u32, b: u32, used: &mut [bool]) -> Vec<VertexId> {
        let (a, b) = (VertexId(a), VertexId(b));
        let ok = |v: VertexId| v == b || !used[v.idx()];
        let (tree, hit) = super::super::search::dijkstra(mesh, &[a], &ok, &|_| true, &|v| v == b, &|_| 1.0);
        let p = super::super::search::path_to(&tree, hit.expect("a path"));
        for &v in &p {
            used[v.idx()] = true;
            for w in mesh.vertex_neighbors(v) {
                used[w.idx()] = true;
            }
        }
        p
    }

    /// Three disjoint curves on an icosphere, between far-apart vertex pairs.
    pub fn sphere_curves(m: &Mesh) -> Vec<Curve> {
        let mut used = vec![false; m.n_vertices()];
        let near = |p: [f64; 3]| {
            (0..m.n_vertices())
                .min_by(|&x, &y| {
                    let d = |v: usize| (m.positions()[v] - crate::mesh::P3::from(p)).norm();
                    d(x).total_cmp(&d(y))
                })
                .unwrap() as u32
        };
        let ends = [
            ([0.9, 0.3, 0.3], [0.9, -0.3, -0.3]),
            ([-0.9, 0.3, 0.3], [-0.9, -0.3, 0.3]),
            ([0.3, 0.3, 0.9], [-0.3, 0.3, 0.9]),
        ];
        ends.iter()
            .map(|&(a, b)| Curve { vertices: path(m, near(a), near(b), &mut used), kind: CurveKind::Open })
            .collect()
    }

    #[test]
    fn curves_are_checked() {
        let g = shapes::grid(8);
        let id = |i: u64, j: u64| j * 9 + i;
        let ok = validate_curve(&g, &[id(2, 4), id(3, 4), id(4, 4)], "f").unwrap();
        assert_eq!(ok.kind, CurveKind::Open);
        let err = |r: &[u64]| validate_curve(&g, r, "f").unwrap_err().to_string();
        assert!(err(&[id(2, 4), id(4, 4)]).contains("not joined by an edge"));
        assert!(err(&[id(2, 4), id(3, 4), id(2, 4), id(2, 5)]).contains("repeats"));
        assert!(err(&[id(2, 4), 999]).contains("out of range"));
        assert!(err(&[id(0, 4), id(1, 4)]).contains("touches the boundary"));
        assert!(err(&[id(2, 4)]).contains("at least 2"));
        // The whole boundary loop, in its direction, is a boundary feature; backwards it is not.
        let ring: Vec<u64> = topology::boundary_loops(&g)[0].iter().map(|&h| g.tail(h).0 as u64).collect();
        let mut closed = ring.clone();
        closed.push(ring[0]);
        assert_eq!(validate_curve(&g, &closed, "b").unwrap().kind, CurveKind::Boundary);
        let mut back = ring.clone();
        back[1..].reverse();
        back.push(back[0]);
        assert!(err(&back).contains("against the boundary's direction"));
        assert!(
            err(&closed[..5].iter().copied().chain([closed[0]]).collect::<Vec<_>>()).contains("whole boundary loop")
        );
        let a = Curve { vertices: vec![VertexId(10), VertexId(11)], kind: CurveKind::Open };
        let b = Curve { vertices: vec![VertexId(11), VertexId(12)], kind: CurveKind::Open };
        assert!(check_disjoint(&[a, b], 81, "source").unwrap_err().to_string().contains("share vertex 11"));
    }

    #[test]
    fn the_double_cover_has_genus_2g_plus_n_minus_1() {
        let s = shapes::icosphere(2);
        let c = sphere_curves(&s);
        for n in 1..=3 {
            let d = double_cover(&s, &c[..n]).unwrap();
            let ds = topology::summary(&d);
            assert_eq!((ds.genus as usize, ds.boundary_loops, ds.components), (doubled_genus(0, n), 0, 1), "n = {n}");
        }
        // A disk: its boundary loop is a feature too.
        let g = shapes::grid(8);
        let f = validate_curve(&g, &[40, 41, 42], "f").unwrap();
        let d = double_cover(&g, &[f]).unwrap();
        assert_eq!(topology::summary(&d).genus as usize, doubled_genus(0, 2));
    }
}
