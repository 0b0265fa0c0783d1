//! Coarse to fine on the sphere (Praun & Hoppe 2003; the peer's multi-resolution embedding):
//! the mesh is decimated by quadric half-edge collapses ([`crate::simplify`]), the base mesh is
//! embedded from Tutte's start, and the collapses are undone in reverse order. Each vertex that
//! comes back goes inside the kernel of its ring ([`super::kernel`]) and its star is checked
//! with the exact predicate, so every intermediate mesh stays a bijective spherical
//! triangulation; after the vertex count grows by [`LEVEL_GROWTH`], a few injective Newton
//! iterations on that level's mesh remove the distortion the insertions left.
//!
//! Tutte's embedding of a whole detailed mesh crowds long limbs into specks (its layout shrinks
//! geometrically along them); on a base of a few hundred vertices it cannot, and each level
//! starts close to its optimum, so the Newton work is a few iterations per level.

use super::barrier::barrier;
use super::kernel::kernel_candidates;
use super::measure::{OnSphere, chord_layout};
use super::newton::{SphereNewton, SphereNewtonOptions, SphereNewtonResult};
use super::orient::orient;
use crate::error::{Error, Result};
use crate::mesh::{Mesh, P3};
use crate::optim::RestTriangle;
use crate::optim::sym_dirichlet::IDENTITY;
use crate::progress::Progress;
use crate::simplify::{DecimateOptions, DecimateResult, decimate};

/// Vertices of the base mesh.
pub const BASE_VERTICES: usize = 400;
/// Each level has this many times the vertices of the one before.
pub const LEVEL_GROWTH: f64 = 2.0;
/// Newton iterations at most on each intermediate level.
pub const LEVEL_ITERATIONS: usize = 8;

/// The decimated hierarchy of a mesh and the state of its refinement.
pub struct Hierarchy<'m> {
    mesh: &'m Mesh,
    dec: DecimateResult,
    /// The current faces in input vertex ids (dead ones kept as they died).
    faces: Vec<[u32; 3]>,
    alive_face: Vec<bool>,
    alive_vertex: Vec<bool>,
    /// Collapses not yet undone: `dec.collapses[..pending]`.
    pending: usize,
    /// The mesh's scale to the unit sphere's area.
    scale: f64,
}

impl<'m> Hierarchy<'m> {
    /// Decimates `mesh` to about `base` vertices.
    ///
    /// # Errors
    /// As [`decimate`].
    pub fn new(mesh: &'m Mesh, base: usize) -> Result<Self> {
        let dec = decimate(mesh, &DecimateOptions { target_vertices: base, ..Default::default() })?;
        let mut alive_vertex = vec![false; mesh.n_vertices()];
        for v in &dec.kept {
            alive_vertex[v.idx()] = true;
        }
        Ok(Self {
            mesh,
            faces: dec.history.faces.clone(),
            alive_face: dec.history.alive.clone(),
            alive_vertex,
            pending: dec.collapses.len(),
            scale: (4.0 * std::f64::consts::PI / mesh.area()).sqrt(),
            dec,
        })
    }

    /// The base mesh (vertex `i` is input vertex `kept()[i]`).
    pub fn base(&self) -> &Mesh {
        &self.dec.mesh
    }

    pub fn kept(&self) -> &[crate::VertexId] {
        &self.dec.kept
    }

    /// Vertices currently alive.
    pub fn alive_count(&self) -> usize {
        self.mesh.n_vertices() - self.pending
    }

    /// Whether every collapse has been undone.
    pub fn is_done(&self) -> bool {
        self.pending == 0
    }

    /// Undoes collapses until `target` vertices are alive, placing each returning vertex inside
    /// its ring's kernel on the sphere (`points` indexed by input vertex).
    ///
    /// # Errors
    /// `Numerical` when a ring's kernel is empty or the new star is not positive.
    pub fn refine_to(&mut self, target: usize, points: &mut [P3]) -> Result<()> {
        while self.pending > 0 && self.alive_count() < target {
            let k = self.pending - 1;
            let c = self.dec.collapses[k];
            let (from, to) = (c.from.0, c.to.0);
            for &f in &self.dec.history.rewritten[k] {
                for v in &mut self.faces[f as usize] {
                    if *v == to {
                        *v = from;
                    }
                }
            }
            for &f in &self.dec.history.deleted[k] {
                self.alive_face[f as usize] = true;
            }
            self.alive_vertex[from as usize] = true;
            self.pending = k;
            let star: Vec<[u32; 3]> = self.dec.history.rewritten[k]
                .iter()
                .chain(&self.dec.history.deleted[k])
                .map(|&f| self.faces[f as usize])
                .collect();
            let ring = ring_of(from, &star)
                .ok_or_else(|| Error::Internal(format!("vertex {from}'s returning star is not a disk")))?;
            let ring_points: Vec<P3> = ring.iter().map(|&v| points[v as usize]).collect();
            let fits =
                |x: &P3| (0..ring.len()).all(|i| orient(x, &ring_points[i], &ring_points[(i + 1) % ring.len()]) > 0.0);
            // Of the candidates that fit, the one whose star has the lowest energy.
            let x = kernel_candidates(&ring_points)
                .into_iter()
                .chain(beside(to, &ring, &ring_points))
                .filter(|x| fits(x))
                .map(|x| (self.star_energy(from, &ring, &ring_points, &x), x))
                .min_by(|a, b| a.0.total_cmp(&b.0))
                .ok_or_else(|| Error::Numerical(format!("no room on the sphere for vertex {from}")))?
                .1;
            points[from as usize] = x;
        }
        Ok(())
    }

    /// The energy of `v`'s star with `v` at `x` (the optimization's energy, the mesh scaled to
    /// the sphere's area); infinite when a triangle is inverted or degenerate.
    fn star_energy(&self, v: u32, ring: &[u32], ring_points: &[P3], x: &P3) -> f64 {
        let pos = self.mesh.positions();
        let n = ring.len();
        (0..n)
            .map(|i| {
                let (a, b) = (ring[i], ring[(i + 1) % n]);
                let rest = RestTriangle::from_3d([v, a, b].map(|u| P3::from(pos[u as usize].coords * self.scale)));
                let corners = [*x, ring_points[i], ring_points[(i + 1) % n]];
                let guard = barrier(rest.map_or(0.0, |r| r.area()), [&corners[0], &corners[1], &corners[2]]);
                match (rest, chord_layout(corners), guard) {
                    (Some(r), Some((l, _)), Some(g)) => r.energy_in(l, &IDENTITY).map_or(f64::INFINITY, |e| e + g.0),
                    _ => f64::INFINITY,
                }
            })
            .sum()
    }

    /// The alive faces, in input vertex ids.
    pub fn faces(&self) -> Vec<[u32; 3]> {
        self.faces.iter().zip(&self.alive_face).filter(|(_, a)| **a).map(|(t, _)| *t).collect()
    }

    /// Optimizes the alive vertices' points with `held` fixed (input ids), on the current level.
    ///
    /// # Errors
    /// As [`SphereNewton::minimize`].
    pub fn optimize(
        &self,
        points: &mut [P3],
        held: &[u32],
        opts: &SphereNewtonOptions,
        progress: &dyn Progress,
    ) -> Result<SphereNewtonResult> {
        let faces = self.faces();
        let alive: Vec<u32> = (0..self.mesh.n_vertices() as u32).filter(|&v| self.alive_vertex[v as usize]).collect();
        let mut local = vec![u32::MAX; self.mesh.n_vertices()];
        for (i, &v) in alive.iter().enumerate() {
            local[v as usize] = i as u32;
        }
        let tris: Vec<[u32; 3]> = faces.iter().map(|t| t.map(|v| local[v as usize])).collect();
        let rest = rest_on_unit_sphere(self.mesh.positions(), &faces)?;
        let fixed: Vec<u32> = held.iter().map(|&v| local[v as usize]).filter(|&v| v != u32::MAX).collect();
        let newton = SphereNewton::new(alive.len(), tris, rest, &fixed)?;
        let mut s: Vec<P3> = alive.iter().map(|&v| points[v as usize]).collect();
        let r = newton.minimize(&OnSphere, &mut s, opts, progress)?;
        for (i, &v) in alive.iter().enumerate() {
            points[v as usize] = s[i];
        }
        Ok(r)
    }
}

/// The rest shapes of `faces` (over `positions`), scaled so their total area is the unit
/// sphere's 4π.
///
/// # Errors
/// `Numerical` for a degenerate face.
pub fn rest_on_unit_sphere(positions: &[P3], faces: &[[u32; 3]]) -> Result<Vec<RestTriangle>> {
    let corners = |t: &[u32; 3]| t.map(|v| positions[v as usize]);
    let area: f64 = faces
        .iter()
        .map(|t| {
            let [a, b, c] = corners(t);
            0.5 * (b - a).cross(&(c - a)).norm()
        })
        .sum();
    let scale = (4.0 * std::f64::consts::PI / area).sqrt();
    faces
        .iter()
        .enumerate()
        .map(|(f, t)| {
            RestTriangle::from_3d(corners(t).map(|p| P3::from(p.coords * scale)))
                .ok_or_else(|| Error::Numerical(format!("face {f} is degenerate")))
        })
        .collect()
}

/// Points ever closer to `to` inside its fan over the ring (the fan's widest triangle, toward
/// its centroid): before the split the fan from `to` covered the ring's polygon positively, so
/// close enough to `to` inside it every triangle of the new star is positive.
fn beside(to: u32, ring: &[u32], ring_points: &[P3]) -> Vec<P3> {
    let Some(k) = ring.iter().position(|&v| v == to) else { return Vec::new() };
    let n = ring.len();
    let t = ring_points[k];
    // The fan triangles (to, ring[i], ring[i + 1]) for the ring edges not touching `to`.
    let widest = (1..n - 1)
        .map(|j| (ring_points[(k + j) % n], ring_points[(k + j + 1) % n]))
        .max_by(|a, b| angle_at(&t, &a.0, &a.1).total_cmp(&angle_at(&t, &b.0, &b.1)));
    let Some((a, b)) = widest else { return Vec::new() };
    let toward = (t.coords + a.coords + b.coords) / 3.0;
    (1..40).map(|i| P3::from((t.coords + (toward - t.coords) * 0.5f64.powi(i)).normalize())).collect()
}

/// The angle at `t` between the great-circle directions to `a` and `b`.
fn angle_at(t: &P3, a: &P3, b: &P3) -> f64 {
    let n = t.coords;
    let ta = a.coords - n * n.dot(&a.coords);
    let tb = b.coords - n * n.dot(&b.coords);
    ta.angle(&tb)
}

/// The ring of `v` in `star` (faces around `v`), counter-clockwise; `None` unless it closes.
fn ring_of(v: u32, star: &[[u32; 3]]) -> Option<Vec<u32>> {
    // Each face (v, a, b) in rotation gives the ring edge a -> b.
    let next: Vec<(u32, u32)> = star
        .iter()
        .map(|t| {
            let k = t.iter().position(|&x| x == v)?;
            Some((t[(k + 1) % 3], t[(k + 2) % 3]))
        })
        .collect::<Option<_>>()?;
    let mut ring = vec![next.first()?.0];
    while ring.len() < next.len() {
        let last = *ring.last()?;
        ring.push(next.iter().find(|e| e.0 == last)?.1);
    }
    let last = *ring.last()?;
    (next.iter().find(|e| e.0 == last)?.1 == ring[0]).then_some(ring)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ring_is_read_in_rotation_order() {
        let star = [[0, 1, 2], [2, 4, 0], [4, 3, 0], [3, 1, 0]];
        assert_eq!(ring_of(0, &star), Some(vec![1, 2, 4, 3]));
        assert_eq!(ring_of(0, &star[..3]), None);
    }
}
