//! A map's images optimized on the target surface itself, measured as the shared evaluator
//! measures them: each source triangle against the straight (chord) triangle through its three
//! images. Every source vertex's image is a point of the target (face, barycentric
//! coordinates); a step in its face's tangent plane walks along the surface, straight across
//! each edge with the rest of the step unfolded into the next face (a retraction, as in the
//! tangent-space steps of Schmidt, Pieper & Kobbelt 2023, here on the target mesh instead of a
//! sphere).
//!
//! A chord is measured in its own plane and counts as inverted when it faces against the target
//! faces under all three of its corners, which is the evaluator's flip rule without its fourth
//! face (the one under the centroid): a chord positive here is not flipped for the evaluator,
//! and [`crate::optim::InjectiveNewton`] keeps every chord positive at every accepted step.

use crate::mesh::{FaceId, Mesh, P3, V3, VertexId};
use crate::optim::newton::MapDomain;
use crate::optim::sym_dirichlet::Mat2;
use crate::param::Uv;
use crate::topology::plane_barycentric;

/// A barycentric coordinate this close to zero puts a point on an edge for the flip rule.
const TIE: f64 = 1e-12;

/// Edges a walk may cross in one step.
const MAX_CROSSINGS: usize = 64;

/// Rounds of held vertices per trial step ([`crate::optim::InjectiveNewtonOptions::hold_rounds`]).
const HOLD_ROUNDS: usize = 30;

/// The target surface as the domain of a map's images.
pub struct OnSurface<'a> {
    target: &'a Mesh,
    normals: Vec<V3>,
    /// An orthonormal tangent basis per target face.
    frames: Vec<[V3; 2]>,
    /// Chords are scaled by this (the source's area over the start map's chord area,
    /// square-rooted), as the evaluator scales the mapped mesh before measuring.
    scale: f64,
}

/// Every source vertex's image: its target face, barycentric coordinates and position.
#[derive(Debug, Clone)]
pub struct Images {
    pub face: Vec<FaceId>,
    pub bary: Vec<[f64; 3]>,
    pub pos: Vec<P3>,
}

impl<'a> OnSurface<'a> {
    pub fn new(source: &Mesh, target: &'a Mesh, start: &crate::map::SurfaceMap) -> Self {
        let normals: Vec<V3> = (0..target.n_faces())
            .map(|f| {
                let n = target.face_normal_raw(FaceId::from_idx(f));
                let l = n.norm();
                if l > 0.0 { n / l } else { V3::zeros() }
            })
            .collect();
        let frames = (0..target.n_faces())
            .map(|f| {
                let [a, b, _] = target.face_points(FaceId::from_idx(f));
                let n = normals[f];
                if n == V3::zeros() {
                    return [V3::x(), V3::y()];
                }
                let e = b - a;
                let u = e - n * e.dot(&n);
                let u = if u.norm() > 0.0 { u.normalize() } else { perpendicular(&n) };
                [u, n.cross(&u)]
            })
            .collect();
        let pos: Vec<P3> = (0..start.len()).map(|v| start.position(VertexId::from_idx(v), target)).collect();
        let chords: f64 = source
            .faces()
            .iter()
            .map(|f| 0.5 * (pos[f[1].idx()] - pos[f[0].idx()]).cross(&(pos[f[2].idx()] - pos[f[0].idx()])).norm())
            .sum();
        let scale = (source.area() / chords.max(f64::MIN_POSITIVE)).sqrt();
        Self { target, normals, frames, scale }
    }

    /// The images of `map`.
    pub fn images(&self, map: &crate::map::SurfaceMap) -> Images {
        let pos = (0..map.len()).map(|v| map.position(VertexId::from_idx(v), self.target)).collect();
        Images { face: map.face.clone(), bary: map.bary.clone(), pos }
    }

    /// Whether direction `c` agrees with the target's normal at the point `b` of face `f`; on an
    /// edge or a corner (a coordinate within [`TIE`] of zero), with every face there, as the
    /// evaluator may take any of them as the point's face.
    fn agrees(&self, c: &V3, f: FaceId, b: [f64; 3]) -> bool {
        let up = |g: FaceId| c.dot(&self.normals[g.idx()]) > 0.0;
        if !up(f) {
            return false;
        }
        let zero = b.map(|x| x <= TIE);
        match zero.iter().filter(|&&z| z).count() {
            0 => true,
            1 => {
                let k = zero.iter().position(|&z| z).unwrap_or(0);
                self.target.twin(crate::mesh::HalfedgeId::of(f, (k + 1) % 3)).is_none_or(|t| up(t.face()))
            }
            _ => {
                let corner = zero.iter().position(|&z| !z).unwrap_or(0);
                self.target.vertex_faces(self.target.face(f)[corner]).all(up)
            }
        }
    }

    /// Walks from `p` on face `f` along the tangent vector `d` for its whole length, straight
    /// across each edge it meets with the rest of `d` unfolded into the next face (turned about
    /// the edge), stopping on the boundary. `None` after [`MAX_CROSSINGS`] edges.
    fn walk(&self, mut f: FaceId, mut p: P3, mut d: V3) -> Option<(FaceId, [f64; 3], P3)> {
        for _ in 0..MAX_CROSSINGS {
            let tri = self.target.face_points(f);
            let (bp, bq) = (plane_barycentric(tri, p), plane_barycentric(tri, p + d));
            // The first edge the segment leaves through: corner k's coordinate reaching zero.
            let mut exit: Option<(f64, usize)> = None;
            for k in 0..3 {
                if bq[k] < 0.0 {
                    let s = (bp[k].max(0.0) / (bp[k].max(0.0) - bq[k])).clamp(0.0, 1.0);
                    if exit.is_none_or(|(e, _)| s < e) {
                        exit = Some((s, k));
                    }
                }
            }
            let Some((s, k)) = exit else {
                let b = clamp_bary(bq);
                let at = P3::from(tri[0].coords * b[0] + tri[1].coords * b[1] + tri[2].coords * b[2]);
                return Some((f, b, at));
            };
            let x = p + d * s;
            let h = crate::mesh::HalfedgeId::of(f, (k + 1) % 3);
            let Some(t) = self.target.twin(h) else {
                return Some((f, clamp_bary(plane_barycentric(tri, x)), x));
            };
            let g = t.face();
            let e = (tri[(k + 2) % 3] - tri[(k + 1) % 3]).normalize();
            let r = d * (1.0 - s);
            let (nf, ng) = (self.normals[f.idx()], self.normals[g.idx()]);
            d = e * r.dot(&e) + ng.cross(&e) * r.dot(&nf.cross(&e));
            p = x;
            f = g;
        }
        None
    }
}

impl MapDomain for OnSurface<'_> {
    type State = Images;

    /// The chord in its own plane, first edge along x, turned over when it faces against the
    /// target at every corner (the evaluator's flip rule at the corners; a corner on an edge
    /// or a vertex agrees only when every face there does), so that its orientation is the
    /// flip test and its shape exactly what the evaluator measures. A corner's tangent move is
    /// projected into that plane: to first order the chord's shape changes by that part only.
    fn element(&self, s: &Images, tri: [u32; 3]) -> ([Uv; 3], [Mat2; 3]) {
        let [p0, p1, p2] = tri.map(|v| s.pos[v as usize]);
        let (e1, e2) = (p1 - p0, p2 - p0);
        let c = e1.cross(&e2);
        let (l1, lc) = (e1.norm(), c.norm());
        if l1 == 0.0 || lc == 0.0 || !lc.is_finite() {
            return ([[0.0; 2]; 3], [[[0.0; 2]; 2]; 3]);
        }
        let agrees = tri.iter().any(|&v| self.agrees(&c, s.face[v as usize], s.bary[v as usize]));
        let n = if agrees { c / lc } else { -c / lc };
        let u = e1 / l1;
        let w = n.cross(&u);
        let k = self.scale;
        let x = [[0.0, 0.0], [k * l1, 0.0], [k * e2.dot(&u), k * e2.dot(&w)]];
        let m = tri.map(|v| {
            let [b0, b1] = self.frames[s.face[v as usize].idx()];
            [[k * u.dot(&b0), k * u.dot(&b1)], [k * w.dot(&b0), k * w.dot(&b1)]]
        });
        (x, m)
    }

    fn moved(&self, s: &Images, d: &[Uv]) -> Option<Images> {
        use rayon::prelude::*;
        let mut out = s.clone();
        // Each image walks on its own (in parallel); an image whose walk does not end (too
        // long a step) stays put for this trial.
        let walked: Vec<Option<(FaceId, [f64; 3], P3)>> = d
            .par_iter()
            .enumerate()
            .map(|(v, q)| {
                if q[0] == 0.0 && q[1] == 0.0 {
                    return None;
                }
                let [b0, b1] = self.frames[s.face[v].idx()];
                self.walk(s.face[v], s.pos[v], b0 * q[0] + b1 * q[1])
            })
            .collect();
        for (v, w) in walked.into_iter().enumerate() {
            if let Some((f, b, at)) = w {
                out.face[v] = f;
                out.bary[v] = b;
                out.pos[v] = at;
            }
        }
        Some(out)
    }

    fn restore(&self, trial: &mut Images, from: &Images, v: usize) -> bool {
        trial.face[v] = from.face[v];
        trial.bary[v] = from.bary[v];
        trial.pos[v] = from.pos[v];
        true
    }
}

/// A unit vector orthogonal to the unit vector `n`.
fn perpendicular(n: &V3) -> V3 {
    let a = if n.x.abs() <= n.y.abs() && n.x.abs() <= n.z.abs() {
        V3::x()
    } else if n.y.abs() <= n.z.abs() {
        V3::y()
    } else {
        V3::z()
    };
    n.cross(&a).normalize()
}

fn coord(p: Uv) -> robust::Coord<f64> {
    robust::Coord { x: p[0], y: p[1] }
}

/// Barycentric coordinates clipped to the triangle and renormalized.
fn clamp_bary(b: [f64; 3]) -> [f64; 3] {
    let c = b.map(|x| x.max(0.0));
    let s: f64 = c.iter().sum();
    if s > 0.0 { c.map(|x| x / s) } else { [1.0 / 3.0; 3] }
}

/// Options for [`optimize_on_surface`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OnSurfaceOptions {
    /// Newton iterations at most.
    pub max_iterations: usize,
}

impl Default for OnSurfaceOptions {
    fn default() -> Self {
        Self { max_iterations: 12 }
    }
}

/// What [`optimize_on_surface`] did.
#[derive(Debug, Clone, Copy, PartialEq, Default, serde::Serialize)]
pub struct OnSurfaceResult {
    /// Chords folded at the start (held as they are).
    pub folded_at_start: usize,
    pub iterations: usize,
    /// Symmetric Dirichlet energy over four times the source's area (1 for an isometry).
    pub energy_before: f64,
    pub energy_after: f64,
}

/// Minimizes the symmetric Dirichlet energy of `map`'s chords (source → target) by injective
/// projected Newton on the target surface, `fixed` vertices (and the source's boundary) held,
/// and so are the corners of chords that start folded.
///
/// # Errors
/// `Numerical` when a Newton system cannot be solved; `Cancelled`.
pub fn optimize_on_surface(
    source: &Mesh,
    target: &Mesh,
    map: &mut crate::map::SurfaceMap,
    fixed: &[VertexId],
    o: &OnSurfaceOptions,
    progress: &dyn crate::progress::Progress,
) -> crate::Result<OnSurfaceResult> {
    use crate::optim::{InjectiveNewton, InjectiveNewtonOptions, RestTriangle};
    let mut tris = Vec::with_capacity(source.n_faces());
    let mut rest = Vec::with_capacity(source.n_faces());
    for f in source.faces() {
        if let Some(r) = RestTriangle::from_3d(f.map(|v| source.position(v))) {
            tris.push(f.map(|v| v.idx() as u32));
            rest.push(r);
        }
    }
    let mut held: Vec<u32> = fixed.iter().map(|v| v.idx() as u32).collect();
    held.extend(
        (0..source.n_vertices()).filter(|&v| source.is_boundary_vertex(VertexId::from_idx(v))).map(|v| v as u32),
    );
    let domain = OnSurface::new(source, target, map);
    let mut s = domain.images(map);
    // Chords that start folded (or on an edge or corner where the evaluator may see them so)
    // are held as they are, corners and all, and left out: every other chord stays positive.
    let positive = |t: &[u32; 3]| {
        let [a, b, c] = domain.element(&s, *t).0;
        robust::orient2d(coord(a), coord(b), coord(c)) > 0.0
    };
    let (keep, out): (Vec<usize>, Vec<usize>) = (0..tris.len()).partition(|&i| positive(&tris[i]));
    held.extend(out.iter().flat_map(|&i| tris[i]));
    // A vertex left without a kept triangle has nothing to lower: held too.
    let mut in_kept = vec![false; source.n_vertices()];
    keep.iter().flat_map(|&i| tris[i]).for_each(|v| in_kept[v as usize] = true);
    held.extend((0..source.n_vertices() as u32).filter(|&v| !in_kept[v as usize]));
    held.sort_unstable();
    held.dedup();
    let mut r = OnSurfaceResult { folded_at_start: out.len(), ..Default::default() };
    if held.len() == source.n_vertices() {
        return Ok(r);
    }
    let tris: Vec<[u32; 3]> = keep.iter().map(|&i| tris[i]).collect();
    let rest: Vec<RestTriangle> = keep.iter().map(|&i| rest[i]).collect();
    let newton = InjectiveNewton::new(source.n_vertices(), tris, rest, &held)?;
    let norm = 4.0 * source.area().max(f64::MIN_POSITIVE);
    let opts =
        InjectiveNewtonOptions { max_iterations: o.max_iterations, hold_rounds: HOLD_ROUNDS, ..Default::default() };
    let n = newton.minimize(&domain, &mut s, &opts, progress)?;
    r.iterations = n.iterations;
    r.energy_before = n.energy_before / norm;
    r.energy_after = n.energy_after / norm;
    map.face = s.face;
    map.bary = s.bary;
    Ok(r)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::map::SurfaceMap;
    use crate::mesh::shapes;
    use crate::progress::NoProgress;

    /// The identity of a sphere, perturbed along the surface, is pulled back towards the
    /// identity, every chord kept positive.
    #[test]
    fn a_perturbed_identity_relaxes_back() {
        let mesh = shapes::icosphere(3);
        let loc = crate::topology::Locator::new(&mesh).unwrap();
        let n = mesh.n_vertices();
        let pos: Vec<P3> = (0..n)
            .map(|v| {
                let p = mesh.positions()[v];
                let k = v as f64;
                let d = V3::new((k * 1.3).sin(), (k * 2.1).cos(), (k * 0.7).sin()) * 0.02;
                P3::from((p.coords + d).normalize())
            })
            .collect();
        let mut map = SurfaceMap::from_positions(&pos, &mesh, Some(&loc)).unwrap();
        let fixed: Vec<VertexId> = [0, 5, 9, 40, 100].map(VertexId::from_idx).to_vec();
        for v in &fixed {
            let (f, b) = crate::topology::SurfacePoint::Vertex { vertex: *v }.in_face(&mesh);
            map.face[v.idx()] = f;
            map.bary[v.idx()] = b;
        }
        let err = |m: &SurfaceMap| {
            (0..n).map(|v| (m.position(VertexId::from_idx(v), &mesh) - mesh.positions()[v]).norm()).sum::<f64>()
                / n as f64
        };
        let before = err(&map);
        let r = optimize_on_surface(&mesh, &mesh, &mut map, &fixed, &OnSurfaceOptions::default(), &NoProgress).unwrap();
        eprintln!("{r:?} error {before} -> {}", err(&map));
        assert_eq!(r.folded_at_start, 0);
        assert!(r.energy_after < r.energy_before);
        assert!(r.energy_after < 1.001, "{r:?}");
        assert!(err(&map) < 0.1 * before);
    }

    /// A start with folded chords: they are held, corners and all, and the rest is optimized
    /// without a fold more (the evaluator's count).
    #[test]
    fn folded_chords_are_held_and_no_fold_is_added() {
        let mesh = shapes::icosphere(3);
        let mut map = SurfaceMap::identity(&mesh);
        // Vertex 50's image moved onto its farthest neighbour's far side: its star folds.
        let v = VertexId::from_idx(50);
        let far = mesh.vertex_neighbors(v).next().unwrap();
        let beyond = mesh.position(far) + (mesh.position(far) - mesh.position(v)) * 0.5;
        let loc = crate::topology::Locator::new(&mesh).unwrap();
        let pr = loc.project(&P3::from(beyond.coords.normalize()));
        map.face[50] = pr.face;
        map.bary[50] = pr.bary;
        let flips = |m: &SurfaceMap| crate::crossparam::visible::evaluator_flip_count(&mesh, &mesh, m).unwrap();
        let before = flips(&map);
        assert!(before > 0);
        let start = map.clone();
        let r = optimize_on_surface(
            &mesh,
            &mesh,
            &mut map,
            &[VertexId::from_idx(0)],
            &OnSurfaceOptions::default(),
            &NoProgress,
        )
        .unwrap();
        assert!(r.folded_at_start > 0, "{r:?}");
        assert!(flips(&map) <= before);
        // Vertex 50, a corner of every folded chord, did not move; the rest relaxed.
        assert_eq!((map.face[50], map.bary[50]), (start.face[50], start.bary[50]));
        assert!(r.iterations > 0 && r.energy_after < r.energy_before, "{r:?}");
    }
}
