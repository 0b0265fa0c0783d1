//! The natural homotopy class of a `homology` job that names none. Carner et al. leave the
//! class to the user; a user mapping two shapes of one genus wants the class in which the map
//! is least distorted (on the same shape, the true one).
//!
//! Every class the method can build from the first [`NaturalClassOptions::bases`] canonical
//! bases on each mesh and every rotation τ is composed (point location in two planar domains,
//! cheap next to relaxing a map) and measured by the L2 stretch of its chords both ways, before
//! any relaxation: a wrong class wraps one handle's loops around another's and stretches by
//! factors, not percent. Classes are told apart by the induced map on H1 read in the reference
//! bases ([`super::classes`]); the least stretched realization of each class stands for it.
//! The pipeline relaxes candidates in this order and keeps the best relaxed one.

use super::map::{SideDomain, aligned, map_between, rotation_count, side_domain};
use super::matching::{Frame, reference_h1};
use crate::error::{Error, InputError, Result};
use crate::map::SurfaceMap;
use crate::mesh::{Mesh, VertexId};
use crate::progress::{Progress, Stage};

/// Options for [`natural_classes`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct NaturalClassOptions {
    /// Canonical bases tried on each mesh (0 = shortest loops first).
    pub bases: usize,
}

impl Default for NaturalClassOptions {
    fn default() -> Self {
        Self { bases: 2 }
    }
}

/// One homotopy class: the basis indices and rotation that realize it best.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct ClassCandidate {
    pub basis: [usize; 2],
    pub rotation: usize,
    /// Induced map on H1 in the reference bases (basis 0 on each mesh).
    pub h1_reference: Vec<Vec<i32>>,
    /// Mean of both directions' L2 stretch before relaxation.
    pub stretch: f64,
}

/// Every class found, least stretched first, and how many compositions were measured.
#[derive(Debug, Clone, PartialEq)]
pub struct NaturalClassResult {
    pub candidates: Vec<ClassCandidate>,
    pub composed: usize,
}

/// The classes reachable from the first `o.bases` bases on each mesh through `bases` (the
/// first anchor pair), `anchors` (the others) warped in as [`map_between`] does.
///
/// # Errors
/// As [`side_domain`] for basis 0 (later bases that cannot be built are skipped);
/// `Cancelled`.
pub fn natural_classes(
    source: &Mesh,
    target: &Mesh,
    bases: (VertexId, VertexId),
    anchors: &[(VertexId, VertexId)],
    o: &NaturalClassOptions,
    progress: &mut dyn Progress,
) -> Result<NaturalClassResult> {
    let sides = |m: &Mesh, b: VertexId| -> Result<Vec<SideDomain>> {
        let mut out = vec![side_domain(m, b, 0, None, 0, 0)?];
        out.extend((1..o.bases.max(1)).map_while(|k| side_domain(m, b, k, None, 0, 0).ok()));
        Ok(out)
    };
    let (s, t) = std::thread::scope(|sc| {
        let h = sc.spawn(|| sides(target, bases.1));
        (sides(source, bases.0), h.join())
    });
    let (s, t) = (s?, t.map_err(|_| Error::Internal("target basis thread panicked".into()))??);
    let (fs, ft) = (Frame::new(source, &s[0].basis)?, Frame::new(target, &t[0].basis)?);
    let g = s[0].basis.genus();
    if g != t[0].basis.genus() {
        return Err(
            InputError::TopologyMismatch(format!("source genus {g}, target genus {}", t[0].basis.genus())).into()
        );
    }
    let total = s.len() * t.len() * rotation_count(g);
    let mut found: Vec<ClassCandidate> = Vec::new();
    let mut composed = 0;
    for (ks, sk) in s.iter().enumerate() {
        for (kt, tk) in t.iter().enumerate() {
            let (sa, ta) = aligned(
                (sk.clone(), tk.clone()),
                &mut |min| side_domain(source, bases.0, ks, None, 0, min),
                &mut |min| side_domain(target, bases.1, kt, None, 0, min),
            )?;
            for rotation in 0..rotation_count(g) {
                progress.check()?;
                progress.report(Stage::Basis, composed as f64 / total as f64);
                composed += 1;
                let m = map_between(source, target, sa.clone(), ta.clone(), rotation, anchors)?;
                let h1_reference =
                    reference_h1((source, target), (&fs, &ft), (&m.source.basis, &m.target.basis), &m.h1)?;
                let stretch =
                    0.5 * (l2(source, target, &m.source_to_target)? + l2(target, source, &m.target_to_source)?);
                let c = ClassCandidate { basis: [ks, kt], rotation, h1_reference, stretch };
                match found.iter_mut().find(|x| x.h1_reference == c.h1_reference) {
                    Some(x) if x.stretch <= c.stretch => {}
                    Some(x) => *x = c,
                    None => found.push(c),
                }
            }
        }
    }
    found.sort_by(|a, b| a.stretch.total_cmp(&b.stretch));
    Ok(NaturalClassResult { candidates: found, composed })
}

/// The evaluator's L2 stretch of `map`'s chords (infinite for a map that cannot be embedded).
fn l2(from: &Mesh, to: &Mesh, map: &SurfaceMap) -> Result<f64> {
    let s = crate::metrics::distortion(from, &map.embed(from, to)?).l2_stretch;
    Ok(if s.is_finite() { s } else { f64::INFINITY })
}
