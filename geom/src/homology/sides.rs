//! One mesh's side domains (canonical basis, fundamental domain, flat torus), each built once
//! per job. The natural-class search composes every pair of bases, and aligning a pair
//! ([`super::map::aligned`]) asks for one side again at the other's refinement attempt; the
//! relaxation then rebuilds the chosen classes. The same (basis index, attempt) was searched
//! up to twenty times on a genus-2 job, so the sides already built are kept and cloned.
//!
//! A request (index `k`, first attempt `m`) returns the first basis found at an attempt `a ≥ m`;
//! the search is deterministic, so every `m'` in `m..=a` returns the same one, and one entry
//! answers them all.

use super::basis::{CanonicalBasisOptions, CanonicalBasisResult, canonical_basis};
use super::compose::Planar;
use super::domain::{FundamentalDomainResult, fundamental_domain};
use super::flat::{FlatTorusResult, flat_torus};
use crate::error::{Error, InputError, Result};
use crate::mesh::{Mesh, VertexId};
use std::sync::Mutex;

/// One side's basis and domain.
#[derive(Debug, Clone)]
pub struct SideDomain {
    pub basis: CanonicalBasisResult,
    pub domain: FundamentalDomainResult,
    /// Genus 1: the flat torus, when its embedding is bijective.
    pub flat: Option<FlatTorusResult>,
}

impl SideDomain {
    /// The disk and its planar positions, for composing maps.
    pub fn planar(&self) -> Planar<'_> {
        Planar { disk: &self.basis.disk, uv: &self.domain.uv, refined: Some(&self.basis.refined) }
    }

    /// The disk on its flat torus, when it has one.
    pub fn flat_planar(&self) -> Option<Planar<'_>> {
        let f = self.flat.as_ref()?;
        Some(Planar { disk: &self.basis.disk, uv: &f.uv, refined: Some(&self.basis.refined) })
    }
}

/// Basis and domain of one mesh through `base`.
///
/// # Errors
/// As [`canonical_basis`] and [`fundamental_domain`].
pub fn side_domain(
    mesh: &Mesh,
    base: VertexId,
    index: usize,
    max_subdivisions: Option<usize>,
    stretch_iterations: usize,
    min_attempt: usize,
) -> Result<SideDomain> {
    let mut o = CanonicalBasisOptions { basis_index: index, min_attempt, ..Default::default() };
    if let Some(m) = max_subdivisions {
        o.max_subdivisions = m;
    }
    let basis = canonical_basis(mesh, base, &o)?;
    let domain = fundamental_domain(&basis, stretch_iterations)?;
    // Genus 1: maps go through the flat torus; the square stays for the meta-mesh overlay, and
    // takes over should the flat embedding not be bijective.
    let flat = if basis.genus() == 1 {
        Some(flat_torus(&basis, &domain.uv)?).filter(|f| f.injectivity.is_injective())
    } else {
        None
    };
    Ok(SideDomain { basis, domain, flat })
}

/// Side domains kept per mesh at most; later ones are built but not kept, which bounds the
/// memory of a job that asks for many bases (each entry holds a refined copy of the mesh).
pub const MAX_KEPT: usize = 24;

/// Side domains of one mesh through one base vertex, built on demand and kept.
pub struct Sides<'a> {
    mesh: &'a Mesh,
    base: VertexId,
    max_subdivisions: Option<usize>,
    stretch_iterations: usize,
    /// (basis index, first attempt asked for, the side found).
    kept: Mutex<Vec<(usize, usize, SideDomain)>>,
    /// (basis index, first attempt asked for, why no basis was found from there): no later
    /// first attempt finds one either, and the failing search is the costliest (both passes
    /// over every refinement).
    missing: Mutex<Vec<(usize, usize, InputError)>>,
    built: std::sync::atomic::AtomicUsize,
}

impl<'a> Sides<'a> {
    /// Sides of `mesh` through `base`, as [`side_domain`] builds them with these options.
    pub fn new(mesh: &'a Mesh, base: VertexId, max_subdivisions: Option<usize>, stretch_iterations: usize) -> Self {
        Self {
            mesh,
            base,
            max_subdivisions,
            stretch_iterations,
            kept: Mutex::new(Vec::new()),
            missing: Mutex::new(Vec::new()),
            built: Default::default(),
        }
    }

    pub fn mesh(&self) -> &'a Mesh {
        self.mesh
    }

    /// Side domains built so far (requests answered by a kept one are not counted).
    pub fn built(&self) -> usize {
        self.built.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Basis `index` first found at an attempt ≥ `min_attempt`, with its domains.
    ///
    /// # Errors
    /// As [`side_domain`]. An input error (no basis from that attempt on) is kept and answers
    /// every later first attempt; other errors are not kept.
    pub fn get(&self, index: usize, min_attempt: usize) -> Result<SideDomain> {
        if let Some(sd) = self.lookup(index, min_attempt) {
            return Ok(sd);
        }
        if let Some(e) = self.known_missing(index, min_attempt) {
            return Err(e.into());
        }
        self.built.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let sd =
            match side_domain(self.mesh, self.base, index, self.max_subdivisions, self.stretch_iterations, min_attempt)
            {
                Ok(sd) => sd,
                Err(Error::Input(e)) => {
                    lock(&self.missing).push((index, min_attempt, e.clone()));
                    return Err(e.into());
                }
                Err(e) => return Err(e),
            };
        let mut kept = lock(&self.kept);
        // Another thread may have built the same side meanwhile.
        if kept.len() < MAX_KEPT && !kept.iter().any(|e| Self::answers(e, index, min_attempt)) {
            kept.push((index, min_attempt, sd.clone()));
        }
        Ok(sd)
    }

    /// Why basis `index` has no basis from `min_attempt` on, when a search from that attempt
    /// or an earlier one already failed.
    fn known_missing(&self, index: usize, min_attempt: usize) -> Option<InputError> {
        let missing = lock(&self.missing);
        missing.iter().find(|(k, m, _)| *k == index && *m <= min_attempt).map(|(.., e)| e.clone())
    }

    fn lookup(&self, index: usize, min_attempt: usize) -> Option<SideDomain> {
        let kept = lock(&self.kept);
        kept.iter().find(|e| Self::answers(e, index, min_attempt)).map(|(.., s)| s.clone())
    }

    /// Whether a kept entry is what a request for (`index`, `min_attempt`) would build.
    fn answers((k, m, s): &(usize, usize, SideDomain), index: usize, min_attempt: usize) -> bool {
        *k == index && (*m..=s.basis.attempt).contains(&min_attempt)
    }
}

/// The data behind `m`, also after a thread panicked holding it: entries are pushed whole, so
/// a poisoned list is still a consistent one.
fn lock<T>(m: &Mutex<T>) -> std::sync::MutexGuard<'_, T> {
    m.lock().unwrap_or_else(std::sync::PoisonError::into_inner)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    /// A side asked for again, at its own attempt or any earlier first attempt, is the kept one;
    /// a later first attempt builds anew and finds the basis at that attempt or after.
    #[test]
    fn kept_sides_answer_every_attempt_up_to_the_one_found() {
        let torus = shapes::torus(24, 12, 1.0, 0.35);
        let sides = Sides::new(&torus, VertexId(0), None, 0);
        let first = sides.get(0, 0).expect("a torus has a basis");
        assert_eq!(sides.built(), 1);
        let again = sides.get(0, first.basis.attempt).expect("kept");
        assert_eq!(sides.built(), 1, "answered by the kept side");
        assert_eq!(again.basis.loops, first.basis.loops);
        assert_eq!(again.domain.uv, first.domain.uv);
        let later = sides.get(0, first.basis.attempt + 1).expect("a refined basis");
        assert_eq!(sides.built(), 2);
        assert!(later.basis.attempt > first.basis.attempt);
        let other = sides.get(1, 0).expect("a second basis");
        assert_eq!(sides.built(), 3);
        assert_ne!(other.basis.loops, first.basis.loops, "basis 1 is another basis");
    }

    /// A basis that cannot be built from an attempt on is not searched again from that attempt
    /// or a later one; the error is the same.
    #[test]
    fn a_missing_basis_is_searched_once() {
        let torus = shapes::torus(24, 12, 1.0, 0.35);
        let sides = Sides::new(&torus, VertexId(0), Some(0), 0);
        let beyond = 10 * crate::homology::basis::ATTEMPTS_PER_ROUND;
        let e1 = sides.get(0, beyond).expect_err("no attempt that late without subdivisions").to_string();
        assert_eq!(sides.built(), 1);
        let e2 = sides.get(0, beyond + 1).expect_err("later still").to_string();
        assert_eq!((sides.built(), e2), (1, e1), "answered by the kept failure");
        sides.get(0, 0).expect("an earlier attempt finds the basis");
        assert_eq!(sides.built(), 2);
    }
}
