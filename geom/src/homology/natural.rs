//! The natural homotopy class of a `homology` job that names none. Carner et al. leave the
//! class to the user; a user mapping two shapes of one genus wants the class in which the map
//! is least distorted (on the same shape, the true one).
//!
//! Every class the method can build from the first [`NaturalClassOptions::bases`] canonical
//! bases on each mesh (doubled up to [`NaturalClassOptions::more_bases`] while none of those is
//! nearly isometric) and every rotation τ is composed (point location in two planar domains,
//! cheap next to relaxing a map) and measured by the L2 stretch of its chords both ways, before
//! any relaxation: a wrong class wraps one handle's loops around another's and stretches by
//! factors, not percent. Classes are told apart by the induced map on H1 read in the reference
//! bases ([`super::classes`]); the least stretched realization of each class stands for it.
//! The pipeline relaxes candidates in this order and keeps the best relaxed one.

use super::map::{aligned, chord_l2, map_between, rotation_count};
use super::matching::{Frame, reference_h1};
use super::sides::Sides;
use crate::error::{Error, InputError, Result};
use crate::mesh::VertexId;
use crate::progress::{Progress, Stage};

/// Options for [`natural_classes`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NaturalClassOptions {
    /// Canonical bases tried on each mesh first (0 = shortest loops first).
    pub bases: usize,
    /// Bases tried on each mesh at most: while no class is stretched by at most `near`, the
    /// bases tried are doubled (2, 4, 8). Genus 2 and more has classes the first bases and the
    /// polygon's rotations do not reach (a turn inside one handle); on same-shape genus-2
    /// cases the true class came from bases 4–5 on one mesh (git show 32d23d1:bench/NOTES.md).
    pub more_bases: usize,
    /// `more_bases` from genus 3 on, where a basis through a crowded anchor can take tens of
    /// seconds to build (genus3 seed 1: 117 s with four bases; over 10 minutes with eight, measured
    /// before the sides were kept, `homology::sides`).
    pub more_bases_genus3: usize,
    pub near: f64,
}

impl Default for NaturalClassOptions {
    fn default() -> Self {
        Self { bases: 2, more_bases: 8, more_bases_genus3: 4, near: 1.10 }
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

/// The classes reachable from the first `o.bases` bases of `s` and `t` (each mesh's sides
/// through the first anchor pair), `anchors` (the others) warped in as [`map_between`] does.
/// The sides built stay in `s` and `t` for the relaxation that follows.
///
/// # Errors
/// As [`super::sides::side_domain`] for basis 0 (later bases that cannot be built are
/// skipped); `Cancelled`.
pub fn natural_classes(
    s: &Sides<'_>,
    t: &Sides<'_>,
    anchors: &[(VertexId, VertexId)],
    o: &NaturalClassOptions,
    progress: &mut dyn Progress,
) -> Result<NaturalClassResult> {
    let source = s.mesh();
    let mut search = Search { s, t, anchors, have: [0, 0], genus: 0, frames: None };
    let mut found: Vec<ClassCandidate> = Vec::new();
    let mut composed = 0;
    let most = if crate::topology::summary(source).genus >= 3 { o.more_bases_genus3 } else { o.more_bases };
    let mut rounds: Vec<std::ops::Range<usize>> = Vec::new();
    let mut end = o.bases.max(1);
    rounds.push(0..end);
    while end < most {
        let next = (2 * end).min(most);
        rounds.push(end..next);
        end = next;
    }
    for round in rounds {
        if round.start > 0 && found.first().is_some_and(|c| c.stretch <= o.near) {
            break;
        }
        // A mesh whose bases ran out (an index that cannot be built) adds none.
        if round.start > search.have[0].max(search.have[1]) {
            break;
        }
        let first = round.start;
        search.add_bases(round)?;
        let g = search.genus;
        let [ns, nt] = search.have;
        let pairs: Vec<(usize, usize)> =
            (0..ns).flat_map(|ks| (0..nt).map(move |kt| (ks, kt))).filter(|&(ks, kt)| ks.max(kt) >= first).collect();
        // Two basis pairs at a time, one on a side thread.
        for (i, two) in pairs.chunks(2).enumerate() {
            progress.check()?;
            progress.report(Stage::Basis, (2 * i) as f64 / pairs.len() as f64);
            let search = &search;
            let (a, b) = std::thread::scope(|sc| {
                let h = two.get(1).map(|&(ks, kt)| sc.spawn(move || search.pair(ks, kt, g)));
                (search.pair(two[0].0, two[0].1, g), h.map(|h| h.join()))
            });
            let b = match b {
                Some(r) => r.map_err(|_| Error::Internal("natural class thread panicked".into()))??,
                None => Vec::new(),
            };
            for c in a?.into_iter().chain(b) {
                composed += 1;
                tracing::debug!(basis = ?c.basis, rotation = c.rotation, stretch = c.stretch, h1 = ?c.h1_reference, "natural class composed");
                match found.iter_mut().find(|x| x.h1_reference == c.h1_reference) {
                    Some(x) if x.stretch <= c.stretch => {}
                    Some(x) => *x = c,
                    None => found.push(c),
                }
            }
            found.sort_by(|a, b| a.stretch.total_cmp(&b.stretch));
        }
    }
    Ok(NaturalClassResult { candidates: found, composed })
}

/// Both meshes' sides, how many bases each has so far, and the reference frames.
struct Search<'s, 'm> {
    s: &'s Sides<'m>,
    t: &'s Sides<'m>,
    anchors: &'s [(VertexId, VertexId)],
    /// Bases built on the source and on the target (indices `0..have`).
    have: [usize; 2],
    genus: usize,
    frames: Option<(Frame, Frame)>,
}

impl Search<'_, '_> {
    /// Bases `ks` on each mesh (both on two threads); a basis index that cannot be built ends
    /// that mesh's list, except basis 0, whose failure is the job's.
    fn add_bases(&mut self, ks: std::ops::Range<usize>) -> Result<()> {
        let more = |side: &Sides<'_>, have: usize| -> Result<usize> {
            let mut n = have;
            for k in ks.clone() {
                if k != n {
                    break;
                }
                match side.get(k, 0) {
                    Ok(_) => n += 1,
                    Err(e) if k == 0 => return Err(e),
                    Err(_) => break,
                }
            }
            Ok(n)
        };
        let (a, b) = std::thread::scope(|sc| {
            let h = sc.spawn(|| more(self.t, self.have[1]));
            (more(self.s, self.have[0]), h.join())
        });
        self.have = [a?, b.map_err(|_| Error::Internal("target basis thread panicked".into()))??];
        if self.frames.is_none() {
            let (s0, t0) = (self.s.get(0, 0)?, self.t.get(0, 0)?);
            let (g, gt) = (s0.basis.genus(), t0.basis.genus());
            if g != gt {
                return Err(InputError::TopologyMismatch(format!("source genus {g}, target genus {gt}")).into());
            }
            self.genus = g;
            self.frames = Some((Frame::new(self.s.mesh(), &s0.basis)?, Frame::new(self.t.mesh(), &t0.basis)?));
        }
        Ok(())
    }

    /// Every rotation of basis pair (`ks`, `kt`), composed and measured.
    fn pair(&self, ks: usize, kt: usize, g: usize) -> Result<Vec<ClassCandidate>> {
        let (source, target) = (self.s.mesh(), self.t.mesh());
        let (sa, ta) = aligned((self.s.get(ks, 0)?, self.t.get(kt, 0)?), &mut |min| self.s.get(ks, min), &mut |min| {
            self.t.get(kt, min)
        })?;
        let (fs, ft) = self.frames.as_ref().ok_or_else(|| Error::Internal("natural: no frames".into()))?;
        (0..rotation_count(g))
            .map(|rotation| {
                let m = map_between(source, target, sa.clone(), ta.clone(), rotation, self.anchors, false)?;
                let h1_reference = reference_h1((source, target), (fs, ft), (&m.source.basis, &m.target.basis), &m.h1)?;
                let stretch = 0.5
                    * (chord_l2(source, target, &m.source_to_target)? + chord_l2(target, source, &m.target_to_source)?);
                Ok(ClassCandidate { basis: [ks, kt], rotation, h1_reference, stretch })
            })
            .collect()
    }
}
