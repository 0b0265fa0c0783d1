//! The flat torus of a genus-1 mesh: a periodic Tutte embedding (Gortler, Gotsman & Thurston
//! 2006, "Discrete one-forms on meshes") with symmetric mean-value weights, on the lattice of the
//! canonical square, then up to three rounds of stretch reweighting (Yoshizawa, Belyaev &
//! Seidel 2004), so that both meshes of a pair are flattened by their geometry rather than by
//! their triangulations. Every vertex sits at the weighted mean of its neighbours *across the cut as well*
//! (a neighbour reached over loop `a` or `b` is shifted by one period), so the torus has no
//! boundary and no corner: the square domain's arc-length sides and its four corners at the base
//! vertex are gone. With positive weights the embedding is a bijection onto the flat torus, and
//! the cut disk's copy of it is a fundamental domain of the lattice.
//!
//! Why: two near-isometric tori cut by loops that lie differently on each (a small handle, a
//! twisted tube) get square domains that disagree far from the cut; the composed map is then
//! turned about the single anchor, a local minimum the relaxation does not leave. Between flat
//! tori the class fixes the map up to a translation, and the anchor fixes that.

use super::basis::CanonicalBasisResult;
use super::compose::{Planar, locate_all_by};
use crate::error::{Error, Result};
use crate::linalg::{DirectedWeights, FixedBoundarySystem, Weights, directed_weights};
use crate::map::SurfaceMap;
use crate::mesh::VertexId;
use crate::mesh::cut::CutMesh;
use crate::param::{InjectivityReport, Uv};

/// Stretch-reweighting rounds at most (Yoshizawa, Belyaev & Seidel 2004, each face's weights
/// divided by its stretch, so they stay symmetric and positive).
const REWEIGHT_ROUNDS: usize = 3;
/// A round that lowers the L2 stretch by less than this fraction is the last.
const MIN_GAIN: f64 = 0.05;

/// A flat torus embedding of a cut disk.
#[derive(Debug, Clone)]
pub struct FlatTorusResult {
    /// Per vertex of the cut disk: its position, a fundamental domain of `period · Z²`.
    pub uv: Vec<Uv>,
    /// The lattice's period (the square domain's side).
    pub period: f64,
    /// Orientation of the disk's faces.
    pub injectivity: InjectivityReport,
    /// Relative residual of the solve.
    pub residual: f64,
}

/// Embeds the torus of `basis` periodically. `square` is the disk on the canonical square
/// ([`super::domain::fundamental_domain`]), which tells on which copy of a cut vertex each face
/// lies: two copies of one vertex differ there by a whole number of periods.
///
/// # Errors
/// `InvalidInput`-free: `Internal` when the basis is not of genus 1; `Numerical` when the
/// solve fails.
pub fn flat_torus(basis: &CanonicalBasisResult, square: &[Uv]) -> Result<FlatTorusResult> {
    if basis.genus() != 1 {
        return Err(Error::Internal(format!("flat torus of a genus-{} basis", basis.genus())));
    }
    let closed = &basis.refined.mesh;
    let disk = &basis.disk;
    let lattice = Lattice::new(disk, square, closed.n_vertices());
    let base = basis.base;
    let anchor = square[lattice.first[base.idx()] as usize];
    let mut sys = FixedBoundarySystem::new(closed, &[base])?;
    sys.prepare_cholesky()?;
    let embed = |w: &DirectedWeights| -> Result<(Vec<Uv>, f64)> {
        let load = lattice.loads(w);
        let (x, residual) =
            sys.factor_weights(w, true)?.solve_loaded::<2>(&|_| anchor, &|v: VertexId| load[v.idx()])?;
        Ok((lattice.on_disk(&x), residual))
    };
    let mut w = torus_weights(closed);
    let (mut uv, mut residual) = embed(&w)?;
    let mut l2 = crate::param::stretch(&disk.mesh, &uv).0;
    for _ in 0..REWEIGHT_ROUNDS {
        let (s2, _) = crate::param::face_stretch(&disk.mesh, &uv);
        if s2.iter().any(|s| s.is_none_or(|s| !s.is_finite() || s <= 0.0)) {
            break;
        }
        for (h, (f, r)) in w.fwd.iter_mut().zip(w.rev.iter_mut()).enumerate() {
            let sigma = s2[h / 3].unwrap_or(1.0).sqrt();
            *f /= sigma;
            *r /= sigma;
        }
        let (next, res) = embed(&w)?;
        let l = crate::param::stretch(&disk.mesh, &next).0;
        tracing::debug!(l2, next = l, "flat torus: stretch reweighting round");
        if l >= l2 {
            break;
        }
        let gained = l < l2 * (1.0 - MIN_GAIN);
        (uv, residual, l2) = (next, res, l);
        if !gained {
            break;
        }
    }
    let injectivity = super::domain::exact_orientation(&disk.mesh, &uv);
    Ok(FlatTorusResult { uv, period: lattice.period, injectivity, residual })
}

/// Which lattice translate each disk copy of a vertex is: the copies of one cut vertex differ by
/// whole periods on the square.
struct Lattice<'a> {
    disk: &'a CutMesh,
    period: f64,
    /// Per closed vertex, its first disk copy.
    first: Vec<u32>,
    /// Per disk vertex, its translate against the first copy.
    shift: Vec<Uv>,
}

impl<'a> Lattice<'a> {
    fn new(disk: &'a CutMesh, square: &[Uv], n_closed: usize) -> Self {
        let period = (super::domain::polygon_corner(4, 1)[1] - super::domain::polygon_corner(4, 0)[1]).abs();
        let mut first = vec![u32::MAX; n_closed];
        for (d, o) in disk.orig.iter().enumerate() {
            if first[o.idx()] == u32::MAX {
                first[o.idx()] = d as u32;
            }
        }
        let whole = |x: f64| (x / period).round() * period;
        let shift = disk
            .orig
            .iter()
            .enumerate()
            .map(|(d, o)| {
                let (p, q) = (square[d], square[first[o.idx()] as usize]);
                [whole(p[0] - q[0]), whole(p[1] - q[1])]
            })
            .collect();
        Lattice { disk, period, first, shift }
    }

    /// The load of each closed vertex's equation, `Σ_j w_ij · (shift of j's copy − shift of i's
    /// copy)`, face by face (the sliced disk keeps the closed mesh's faces and corners in order,
    /// so half-edge `3f + k` is the same on both).
    fn loads(&self, w: &DirectedWeights) -> Vec<Uv> {
        let mut load = vec![[0.0; 2]; self.first.len()];
        for (f, tri) in self.disk.mesh.faces().iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                let h = 3 * f + k;
                let (oa, ob) = (self.disk.orig[a.idx()].idx(), self.disk.orig[b.idx()].idx());
                let (sa, sb) = (self.shift[a.idx()], self.shift[b.idx()]);
                let d = [sb[0] - sa[0], sb[1] - sa[1]];
                load[oa] = [load[oa][0] + w.fwd[h] * d[0], load[oa][1] + w.fwd[h] * d[1]];
                load[ob] = [load[ob][0] - w.rev[h] * d[0], load[ob][1] - w.rev[h] * d[1]];
            }
        }
        load
    }

    /// Closed-mesh positions `x` laid on the disk, each copy at its translate.
    fn on_disk(&self, x: &[Uv]) -> Vec<Uv> {
        let s = &self.shift;
        self.disk.orig.iter().enumerate().map(|(d, o)| [x[o.idx()][0] + s[d][0], x[o.idx()][1] + s[d][1]]).collect()
    }
}

/// Every original vertex of the `n` vertices of `from`'s mesh (through its first disk copy)
/// located on `to`'s flat torus after `tau`: the lattice translate of the point that falls in
/// `to`'s fundamental domain (the translate in the square about the origin first, then its
/// neighbours; a point no walk reaches, which rounding on the domain's rim can leave, is
/// located as `Grid::locate` does, on the nearest triangle).
pub fn locate_all_periodic(n: usize, from: &Planar, to: &Planar, period: f64, tau: &dyn Fn(Uv) -> Uv) -> SurfaceMap {
    let mut shifts: Vec<[f64; 2]> =
        (-2..=2).flat_map(|i| (-2..=2).map(move |j| [f64::from(i) * period, f64::from(j) * period])).collect();
    shifts.sort_by(|a, b| (a[0].abs() + a[1].abs()).total_cmp(&(b[0].abs() + b[1].abs())));
    let whole = |x: f64| (x / period).round() * period;
    locate_all_by(n, from, to, tau, &|grid, tris, p| {
        let p = [p[0] - whole(p[0]), p[1] - whole(p[1])];
        shifts
            .iter()
            .find_map(|s| grid.locate_inside(to.uv, tris, [p[0] + s[0], p[1] + s[1]]))
            .unwrap_or_else(|| grid.locate(to.uv, tris, p))
    })
}

/// Mean-value weights (Floater 2003) made symmetric, each face's two directed weights of an edge
/// replaced by their mean: positive, so the periodic embedding is a bijection (Gortler et al.
/// prove it for symmetric positive weights; with the directed mean-value weights one face in a
/// few thousand folded at the base vertex, measured on the torus).
fn torus_weights(mesh: &crate::mesh::Mesh) -> DirectedWeights {
    let mut w = directed_weights(mesh, Weights::MeanValue);
    for (f, r) in w.fwd.iter_mut().zip(w.rev.iter_mut()) {
        let m = 0.5 * (*f + *r);
        (*f, *r) = (m, m);
    }
    w
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::homology::{CanonicalBasisOptions, canonical_basis, fundamental_domain};
    use crate::mesh::shapes;

    /// A torus of revolution's canonical basis and its flat torus.
    fn flat_of_torus(n: usize, m: usize, r: f64) -> (CanonicalBasisResult, FlatTorusResult) {
        let mesh = shapes::torus(n, m, 2.0, r);
        let basis = canonical_basis(&mesh, VertexId(0), &CanonicalBasisOptions::default()).unwrap();
        let square = fundamental_domain(&basis, 0).unwrap();
        let flat = flat_torus(&basis, &square.uv).unwrap();
        (basis, flat)
    }

    /// A torus of revolution: the periodic embedding is bijective, the copies of every cut
    /// vertex differ by whole periods, and the disk tiles one lattice cell (its signed area is
    /// `period²`), which is what makes it a fundamental domain; the solve's residual is small.
    #[test]
    fn a_torus_lies_on_one_cell_of_its_lattice() {
        let (basis, flat) = flat_of_torus(32, 14, 0.6);
        assert!(flat.injectivity.is_injective(), "{:?}", flat.injectivity);
        assert!(flat.residual < 1e-10, "residual {}", flat.residual);
        let p = flat.period;
        let disk = &basis.disk;
        let mut first = vec![usize::MAX; basis.refined.mesh.n_vertices()];
        for (d, o) in disk.orig.iter().enumerate() {
            let f = &mut first[o.idx()];
            if *f == usize::MAX {
                *f = d;
                continue;
            }
            for c in 0..2 {
                let k = (flat.uv[d][c] - flat.uv[*f][c]) / p;
                assert!((k - k.round()).abs() < 1e-9, "copy {d} of vertex {o:?} is off the lattice: {k}");
            }
        }
        let area: f64 = disk
            .mesh
            .faces()
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|v| flat.uv[v.idx()]);
                0.5 * ((b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]))
            })
            .sum();
        assert!((area - p * p).abs() < 1e-9 * p * p, "area {area}, cell {}", p * p);
    }

    /// Every point of the plane falls in the fundamental domain once: points spread over three
    /// cells are each located on a triangle that contains them up to a lattice translate.
    #[test]
    fn every_translate_is_found_in_the_domain() {
        let (basis, flat) = flat_of_torus(24, 10, 0.7);
        let planar = Planar { disk: &basis.disk, uv: &flat.uv, refined: None };
        let tris = basis.disk.mesh.face_indices();
        // Move every disk vertex by a fraction of a period and by up to one whole period: the
        // located triangle must hold the point after a lattice translate.
        let p = flat.period;
        let moved: Vec<Uv> =
            flat.uv.iter().enumerate().map(|(i, q)| [q[0] + 0.37 * p + (i % 3) as f64 * p, q[1] - 0.21 * p]).collect();
        let from = Planar { disk: &basis.disk, uv: &moved, refined: None };
        let n = basis.disk.orig.iter().map(|o| o.idx() + 1).max().unwrap();
        let map = locate_all_periodic(n, &from, &planar, p, &|q| q);
        for (v, (f, b)) in map.face.iter().zip(&map.bary).enumerate() {
            let t = tris[f.idx()].map(|c| flat.uv[c as usize]);
            let at = [0, 1].map(|c| b[0] * t[0][c] + b[1] * t[1][c] + b[2] * t[2][c]);
            let d = basis.disk.orig.iter().position(|o| o.idx() == v).unwrap();
            for c in 0..2 {
                let k = (moved[d][c] - at[c]) / p;
                assert!((k - k.round()).abs() < 1e-7, "vertex {v}: {:?} located at {at:?}", moved[d]);
            }
        }
    }
}
