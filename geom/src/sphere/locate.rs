//! Points of the sphere located in a bijective spherical triangulation, and carried onto the
//! surface it embeds.
//!
//! A point `q` lies in the geodesic triangle `(a, b, c)` when `det(q, b, c)`, `det(a, q, c)`
//! and `det(a, b, q)` are all non-negative; normalized, those three are the barycentric
//! coordinates of where the ray through `q` meets the chord triangle (the gnomonic projection,
//! which maps the geodesic triangle onto the chord one). The surface point is the same
//! combination of the mesh triangle's corners. Location is a visibility walk from a hint
//! across the edge whose determinant is negative, rotating which edge is tried first so it
//! cannot cycle on a non-Delaunay triangulation, with a scan of every face as the last resort.

use super::measure::{Image, SphereImage};
use crate::mesh::{HalfedgeId, Mesh, P3, V3};
use std::sync::atomic::{AtomicU32, Ordering};

/// A mesh and its bijective embedding on the sphere, ready to locate points in.
pub struct SphereLocator<'m> {
    mesh: &'m Mesh,
    points: &'m [P3],
    tris: Vec<[u32; 3]>,
    /// Unit face normals.
    face_normals: Vec<V3>,
    /// Per vertex, the area-weighted mean of its faces' normals (interpolated across a face, a
    /// normal field without jumps at edges).
    smooth_normals: Vec<V3>,
}

/// A located point: the face, its barycentric coordinates, and the surface point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Located {
    pub face: u32,
    pub bary: [f64; 3],
}

impl<'m> SphereLocator<'m> {
    /// `points` is `mesh`'s bijective sphere embedding (one unit vector per vertex).
    pub fn new(mesh: &'m Mesh, points: &'m [P3]) -> Self {
        let face_raw: Vec<V3> = (0..mesh.n_faces()).map(|f| mesh.face_normal_raw(crate::FaceId::from_idx(f))).collect();
        let tris = mesh.face_indices();
        let unit = |n: &V3| n.try_normalize(0.0).unwrap_or_else(V3::zeros);
        let face_normals: Vec<V3> = face_raw.iter().map(unit).collect();
        let mut smooth = vec![V3::zeros(); mesh.n_vertices()];
        for (t, n) in tris.iter().zip(&face_raw) {
            for &v in t {
                smooth[v as usize] += n;
            }
        }
        let smooth_normals = smooth.iter().map(unit).collect();
        Self { mesh, points, face_normals, smooth_normals, tris }
    }

    pub fn mesh(&self) -> &Mesh {
        self.mesh
    }

    fn corners(&self, f: u32) -> [&P3; 3] {
        self.tris[f as usize].map(|v| &self.points[v as usize])
    }

    /// The three edge determinants of `q` in face `f`.
    fn dets(&self, f: u32, q: &V3) -> [f64; 3] {
        let [a, b, c] = self.corners(f).map(|p| p.coords);
        [q.dot(&b.cross(&c)), q.dot(&c.cross(&a)), q.dot(&a.cross(&b))]
    }

    /// Locates `q` (a unit vector), starting from face `hint`.
    pub fn locate(&self, q: &P3, hint: u32) -> Located {
        let n = self.tris.len() as u32;
        let mut f = if hint < n { hint } else { 0 };
        let limit = 4 * (n as usize).isqrt() + 64;
        for step in 0..limit {
            let d = self.dets(f, &q.coords);
            // Edge k of the face runs from corner k to k + 1; it is opposite corner k + 2.
            let start = step % 3;
            let across = (0..3).map(|i| (start + i) % 3).find(|&k| d[(k + 2) % 3] < 0.0);
            match across {
                None => return self.finish(f, d),
                Some(k) => match self.mesh.twin(HalfedgeId::of(crate::FaceId(f), k)) {
                    Some(t) => f = t.face().0,
                    None => break,
                },
            }
        }
        // The walk gave up: the face whose smallest determinant is largest.
        let best = (0..n)
            .max_by(|&a, &b| {
                let m = |f: u32| self.dets(f, &q.coords).into_iter().fold(f64::INFINITY, f64::min);
                m(a).total_cmp(&m(b))
            })
            .unwrap_or(0);
        self.finish(best, self.dets(best, &q.coords))
    }

    fn finish(&self, f: u32, d: [f64; 3]) -> Located {
        let d = d.map(|x| x.max(0.0));
        let s = d[0] + d[1] + d[2];
        let bary = if s > 0.0 { d.map(|x| x / s) } else { [1.0 / 3.0; 3] };
        Located { face: f, bary }
    }

    /// The surface point of a location.
    pub fn surface_point(&self, l: &Located) -> P3 {
        let t = self.tris[l.face as usize];
        let p = |k: usize| self.mesh.positions()[t[k] as usize].coords;
        P3::from(p(0) * l.bary[0] + p(1) * l.bary[1] + p(2) * l.bary[2])
    }

    /// The surface normal at a location: the face's, or the vertex's smooth normal when it
    /// sits on one (as an anchor does), since which of its faces a triangle leaves it through
    /// is not known from the point alone. (The face nearest by centroid, where the
    /// evaluator's closest-point search may settle, called 26 faces of the cow's identity map
    /// turned over at its sharp vertices.)
    pub fn normal(&self, l: &Located) -> V3 {
        match l.bary.iter().position(|&b| b >= 1.0 - 1e-9) {
            Some(k) => self.smooth_normals[self.tris[l.face as usize][k] as usize],
            None => self.face_normals[l.face as usize],
        }
    }

    /// The smooth normal at a location: the vertices' mean normals, interpolated.
    pub fn smooth_normal(&self, l: &Located) -> V3 {
        let t = self.tris[l.face as usize];
        (0..3).map(|k| self.smooth_normals[t[k] as usize] * l.bary[k]).sum()
    }

    /// The surface point of `q` in face `f` and its derivatives along `frame` (exact inside the
    /// face: the barycentric coordinates are ratios of linear functions of `q`).
    fn image_in(&self, f: u32, q: &P3, frame: &[V3; 2]) -> (P3, [V3; 2]) {
        let [a, b, c] = self.corners(f).map(|p| p.coords);
        let m = [b.cross(&c), c.cross(&a), a.cross(&b)];
        let normal = m[0] + m[1] + m[2];
        let qn = q.coords.dot(&normal);
        let lambda = m.map(|mi| q.coords.dot(&mi) / qn);
        let t = self.tris[f as usize];
        let pos = |k: usize| self.mesh.positions()[t[k] as usize].coords;
        let x = pos(0) * lambda[0] + pos(1) * lambda[1] + pos(2) * lambda[2];
        let deriv = frame.map(|d| {
            let nd = normal.dot(&d);
            (0..3).map(|i| pos(i) * ((m[i].dot(&d) - lambda[i] * nd) / qn)).sum::<V3>()
        });
        (P3::from(x), deriv)
    }
}

/// The target surface as a [`SphereImage`]: a vertex's sphere point is located in the target's
/// embedding (walking from where that vertex was last found) and carried onto the surface.
pub struct OnTarget<'m> {
    locator: SphereLocator<'m>,
    hints: Vec<AtomicU32>,
}

impl<'m> OnTarget<'m> {
    /// For `n` moving vertices over `locator`'s triangulation.
    pub fn new(locator: SphereLocator<'m>, n: usize) -> Self {
        Self { locator, hints: (0..n).map(|_| AtomicU32::new(0)).collect() }
    }

    /// How many vertices keep a hint of their own.
    pub fn hint_count(&self) -> usize {
        self.hints.len()
    }

    pub fn locator(&self) -> &SphereLocator<'m> {
        &self.locator
    }

    /// Locates vertex `v`'s point `q`, updating its hint.
    pub fn locate(&self, v: u32, q: &P3) -> Located {
        let hint = self.hints.get(v as usize).map_or(0, |h| h.load(Ordering::Relaxed));
        let l = self.locator.locate(q, hint);
        if let Some(h) = self.hints.get(v as usize) {
            h.store(l.face, Ordering::Relaxed);
        }
        l
    }
}

impl SphereImage for OnTarget<'_> {
    fn image(&self, v: u32, p: &P3, frame: &[V3; 2]) -> Option<Image> {
        let l = self.locate(v, p);
        let (x, d) = self.locator.image_in(l.face, p, frame);
        let at_vertex = l.bary.iter().any(|&b| b >= 1.0 - 1e-9);
        Some(Image { x, d, up: self.locator.normal(&l), at_vertex, smooth: self.locator.smooth_normal(&l) })
    }
    fn up_at(&self, near: u32, p: &P3) -> V3 {
        let hint = self.hints.get(near as usize).map_or(0, |h| h.load(Ordering::Relaxed));
        self.locator.normal(&self.locator.locate(p, hint))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn every_vertex_of_an_icosphere_is_found_where_it_is() {
        let mesh = shapes::icosphere(2);
        let points: Vec<P3> = mesh.positions().iter().map(|p| P3::from(p.coords.normalize())).collect();
        let loc = SphereLocator::new(&mesh, &points);
        for (f, t) in mesh.face_indices().iter().enumerate() {
            // The centroid of each face, walked to from face 0.
            let c = P3::from(
                ((points[t[0] as usize].coords + points[t[1] as usize].coords + points[t[2] as usize].coords) / 3.0)
                    .normalize(),
            );
            let l = loc.locate(&c, 0);
            assert_eq!(l.face as usize, f);
            assert!(l.bary.iter().all(|&b| (b - 1.0 / 3.0).abs() < 0.05), "{:?}", l.bary);
            let s = loc.surface_point(&l);
            let expect = (mesh.position(crate::VertexId(t[0])).coords
                + mesh.position(crate::VertexId(t[1])).coords
                + mesh.position(crate::VertexId(t[2])).coords)
                / 3.0;
            assert!((s.coords - expect).norm() < 0.05);
        }
    }

    #[test]
    fn the_image_derivative_matches_finite_differences() {
        let mesh = shapes::icosphere(1);
        let points: Vec<P3> = mesh.positions().iter().map(|p| P3::from(p.coords.normalize())).collect();
        let loc = SphereLocator::new(&mesh, &points);
        let t = mesh.face_indices()[3];
        let q = P3::from(
            (points[t[0] as usize].coords * 0.5
                + points[t[1] as usize].coords * 0.3
                + points[t[2] as usize].coords * 0.2)
                .normalize(),
        );
        let frame = super::super::newton::tangent_frame(&q);
        let (x, d) = loc.image_in(3, &q, &frame);
        let h = 1e-7;
        for k in 0..2 {
            let qp = P3::from(q.coords + frame[k] * h);
            let (xp, _) = loc.image_in(3, &qp, &frame);
            let fd = (xp - x) / h;
            assert!((fd - d[k]).norm() < 1e-5 * (1.0 + fd.norm()), "{fd:?} vs {:?}", d[k]);
        }
    }
}
