//! A map between two meshes as one mesh's images in the common base domain, optimized as a
//! whole with every step injective ([`crate::optim::InjectiveNewton`]).
//!
//! The target is fixed through its own bijective map onto the domain (its per-patch maps,
//! seen through its [`PatchLocator`]s); the unknowns are the source vertices' chart positions,
//! free to cross patch sides (a vertex walks into the patch it enters, [`Charts::settle`], and
//! its links are carried along). A source triangle is measured in the chart of its first free
//! corner; its energy is the symmetric Dirichlet energy of the composed map source → target,
//! with the target's metric in that chart taken from the target face under the triangle's
//! centroid (frozen for one Newton step, as Schmidt, Pieper & Kobbelt 2023 freeze the face of
//! each point). A source map that is injective in the domain composed with a bijective target
//! map is injective, so every accepted step keeps the surface map injective.

use super::charts::Charts;
use super::locate::PatchLocator;
use super::solve::{Rows, State, slot_of};
use crate::mesh::{FaceId, Mesh};
use crate::optim::newton::MapDomain;
use crate::optim::sym_dirichlet::{IDENTITY, Mat2};
use crate::param::Uv;

/// The source's images in the base domain, measured through the target's map.
pub struct DomainMap<'a> {
    pub charts: &'a Charts,
    pub rows: &'a Rows,
    pub fixed: &'a [bool],
    pub target: &'a Mesh,
    pub locators: &'a [PatchLocator],
    /// Source area over target area: the target's metric is scaled by it, so a map between
    /// meshes of different sizes is measured as the evaluator does (areas normalized).
    pub area_scale: f64,
}

impl DomainMap<'_> {
    fn reference(&self, tri: [u32; 3]) -> usize {
        reference(self.fixed, tri)
    }
}

/// The first free corner of `tri` (the triangle's chart), or corner 0.
fn reference(fixed: &[bool], tri: [u32; 3]) -> usize {
    (0..3).find(|&k| !fixed[tri[k] as usize]).unwrap_or(0)
}

/// Triangle `tri`'s corners in the chart of its reference corner, through the links, and per
/// corner the linear part of its link.
fn element_in(rows: &Rows, fixed: &[bool], s: &State, tri: [u32; 3]) -> ([Uv; 3], [Mat2; 3]) {
    let r = reference(fixed, tri);
    let i = tri[r] as usize;
    let mut x = [s.uv[i]; 3];
    let mut m = [IDENTITY; 3];
    for k in 0..3 {
        if k == r {
            continue;
        }
        let j = tri[k] as usize;
        let link = slot_of(rows, i, j).and_then(|slot| s.link[slot]);
        match link {
            Some(a) => {
                x[k] = a.apply(s.uv[j]);
                m[k] = a.m;
            }
            // No link: a degenerate element the optimizer refuses (no energy).
            None => x[k] = s.uv[i],
        }
    }
    (x, m)
}

impl MapDomain for DomainMap<'_> {
    type State = State;

    fn element(&self, s: &State, tri: [u32; 3]) -> ([Uv; 3], [Mat2; 3]) {
        element_in(self.rows, self.fixed, s, tri)
    }

    /// The target's metric under the triangle's centroid, which may lie in another patch than
    /// the triangle's chart: the centroid walks there from the reference corner
    /// ([`Charts::settle`]) and the metric comes back through the crossing's linear part. Where
    /// no target triangle is found, the metric at the reference corner.
    fn metric(&self, s: &State, tri: [u32; 3]) -> Mat2 {
        let (x, _) = self.element(s, tri);
        let c = [(x[0][0] + x[1][0] + x[2][0]) / 3.0, (x[0][1] + x[1][1] + x[2][1]) / 3.0];
        let v = tri[self.reference(tri)] as usize;
        let p = s.patch[v];
        let (q, y, a) = self.charts.settle(p, s.uv[v], c);
        self.target_metric(q, y).map(|l| mul(&l, &a.m)).or_else(|| self.target_metric(p, s.uv[v])).unwrap_or(IDENTITY)
    }

    fn moved(&self, s: &State, d: &[Uv]) -> Option<State> {
        let mut next = s.clone();
        let mut moved_by = vec![None; s.uv.len()];
        let mut any = false;
        for (v, dv) in d.iter().enumerate() {
            if self.fixed[v] || (dv[0] == 0.0 && dv[1] == 0.0) {
                continue;
            }
            let to = [s.uv[v][0] + dv[0], s.uv[v][1] + dv[1]];
            let (p, x, a) = self.charts.settle(s.patch[v], s.uv[v], to);
            if p != s.patch[v] {
                moved_by[v] = Some(a);
                any = true;
            }
            next.patch[v] = p;
            next.uv[v] = x;
        }
        if any {
            next.carry_links(self.rows, &moved_by);
        }
        Some(next)
    }
}

impl DomainMap<'_> {
    /// The target's metric factor `L` (`LᵀL` the target surface's metric) at chart point `x`
    /// of patch `p`, scaled to the source's area; `None` where no target triangle is found.
    pub fn target_metric(&self, p: u32, x: Uv) -> Option<Mat2> {
        let (f, q) = self.locators.get(p as usize)?.locate_triangle(x)?;
        metric_factor(self.target, f, q, self.area_scale)
    }
}

fn mul(a: &Mat2, b: &Mat2) -> Mat2 {
    [
        [a[0][0] * b[0][0] + a[0][1] * b[1][0], a[0][0] * b[0][1] + a[0][1] * b[1][1]],
        [a[1][0] * b[0][0] + a[1][1] * b[1][0], a[1][0] * b[0][1] + a[1][1] * b[1][1]],
    ]
}

/// `L` with `LᵀL = AᵀA · scale`, `A` the affine map from the chart triangle `q` onto target
/// face `f` (upper triangular, by Cholesky of the 2×2 metric).
fn metric_factor(target: &Mesh, f: FaceId, q: [Uv; 3], scale: f64) -> Option<Mat2> {
    let p = target.face_points(f);
    let (e1, e2) = (p[1] - p[0], p[2] - p[0]);
    let (u1, u2) = ([q[1][0] - q[0][0], q[1][1] - q[0][1]], [q[2][0] - q[0][0], q[2][1] - q[0][1]]);
    let det = u1[0] * u2[1] - u2[0] * u1[1];
    if det == 0.0 || !det.is_finite() {
        return None;
    }
    // U⁻¹ for U = [u1 u2] (columns); A = E U⁻¹ has columns a = E U⁻¹[:,0], b = E U⁻¹[:,1].
    let inv = [[u2[1] / det, -u2[0] / det], [-u1[1] / det, u1[0] / det]];
    let a = e1 * inv[0][0] + e2 * inv[1][0];
    let b = e1 * inv[0][1] + e2 * inv[1][1];
    let (m00, m01, m11) = (a.dot(&a) * scale, a.dot(&b) * scale, b.dot(&b) * scale);
    let l00 = m00.sqrt();
    if l00 <= 0.0 || !l00.is_finite() {
        return None;
    }
    let l01 = m01 / l00;
    let l11 = (m11 - l01 * l01).max(0.0).sqrt();
    (l11 > 0.0).then_some([[l00, l01], [0.0, l11]])
}

/// Untangling iterations: cat → horse's target seed (22 folded triangles) needs more than 60.
const UNTANGLE_ITERATIONS: usize = 150;

/// A domain measured in its own charts' metric (the identity).
struct Plain<'a, D>(&'a D);

impl<D: MapDomain> MapDomain for Plain<'_, D> {
    type State = D::State;
    fn element(&self, s: &D::State, tri: [u32; 3]) -> ([Uv; 3], [Mat2; 3]) {
        self.0.element(s, tri)
    }
    fn moved(&self, s: &D::State, d: &[Uv]) -> Option<D::State> {
        self.0.moved(s, d)
    }
}

/// What one direction's untangling and minimization did.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct DomainMapReport {
    /// The minimization; none when the seed stayed folded after untangling (the seed is then
    /// left as untangling left it, and the map is not injective).
    pub newton: Option<crate::optim::InjectiveNewtonResult>,
    /// Source triangles folded in the domain at the start, and after untangling them (the
    /// optimization needs none).
    pub folded_at_start: usize,
    pub folded_after_untangling: usize,
}

/// One mesh's images in the base domain, ready to be untangled and optimized against another
/// mesh's map (its rest shapes and the sparse system's symbolic factorization, built once).
pub struct DomainOptimizer {
    triangles: Vec<[u32; 3]>,
    newton: crate::optim::InjectiveNewton,
    area: f64,
}

impl DomainOptimizer {
    /// # Errors
    /// `Numerical` when a face of `mesh` has no area; as [`crate::optim::InjectiveNewton::new`].
    pub fn new(mesh: &Mesh, seed: &super::Seed) -> crate::error::Result<Self> {
        use crate::optim::{InjectiveNewton, RestTriangle};
        let triangles: Vec<[u32; 3]> = mesh.faces().iter().map(|f| f.map(|v| v.0)).collect();
        let rest = mesh
            .faces()
            .iter()
            .map(|f| RestTriangle::from_3d(f.map(|v| mesh.position(v))))
            .collect::<Option<Vec<_>>>()
            .ok_or_else(|| crate::error::Error::Numerical("a face has no area".into()))?;
        let fixed: Vec<u32> = (0..mesh.n_vertices() as u32).filter(|&v| seed.fixed[v as usize]).collect();
        let newton = InjectiveNewton::new(mesh.n_vertices(), triangles.clone(), rest, &fixed)?;
        Ok(Self { triangles, newton, area: mesh.area() })
    }

    fn domain<'a>(&'a self, seed: &'a super::Seed, target: &'a Mesh, locators: &'a [PatchLocator]) -> DomainMap<'a> {
        DomainMap {
            charts: &seed.charts,
            rows: &seed.rows,
            fixed: &seed.fixed,
            target,
            locators,
            area_scale: self.area / target.area().max(f64::MIN_POSITIVE),
        }
    }

    /// Triangles of `seed` not positively oriented in the domain.
    pub fn folded(&self, seed: &super::Seed) -> usize {
        let c = |p: Uv| robust::Coord { x: p[0], y: p[1] };
        self.triangles
            .iter()
            .filter(|&&t| {
                let [a, b, e] = element_in(&seed.rows, &seed.fixed, &seed.state, t).0;
                robust::orient2d(c(a), c(b), c(e)) <= 0.0
            })
            .count()
    }

    /// Untangles `seed` in place (Garanzha et al. 2021), measured in the domain's own metric:
    /// the target's metric under a folded triangle's centroid is read where the seed is wrong
    /// (cat → horse's target seed: 22 folds, 49 after 200 iterations in the target's metric,
    /// none after 150 in the domain's). Returns the triangles folded before and after.
    ///
    /// # Errors
    /// `Numerical`; `Cancelled`.
    pub fn untangle(
        &self,
        seed: &mut super::Seed,
        target: &Mesh,
        locators: &[PatchLocator],
        progress: &dyn crate::progress::Progress,
    ) -> crate::error::Result<(usize, usize)> {
        let before = self.folded(seed);
        if before == 0 {
            return Ok((0, 0));
        }
        let domain = self.domain(seed, target, locators);
        let mut state = seed.state.clone();
        let left = self.newton.untangle(&Plain(&domain), &mut state, UNTANGLE_ITERATIONS, progress)?;
        seed.state = state;
        Ok((before, left))
    }

    /// Minimizes the energy of `seed`'s map onto `target` (through its `locators`) in place,
    /// every step injective; `None` (nothing done) when the seed is folded.
    ///
    /// # Errors
    /// `Numerical`; `Cancelled`.
    pub fn minimize(
        &self,
        seed: &mut super::Seed,
        target: &Mesh,
        locators: &[PatchLocator],
        opts: &crate::optim::InjectiveNewtonOptions,
        progress: &dyn crate::progress::Progress,
    ) -> crate::error::Result<Option<crate::optim::InjectiveNewtonResult>> {
        if self.folded(seed) > 0 {
            return Ok(None);
        }
        let domain = self.domain(seed, target, locators);
        let mut state = seed.state.clone();
        let r = self.newton.minimize(&domain, &mut state, opts, progress)?;
        seed.state = state;
        Ok(Some(r))
    }
}
