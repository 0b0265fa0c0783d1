//! Which homotopy classes a `homology` job relaxes, in order: the one named (basis and
//! rotation, or a curve matching realized by them), or, with none named, the natural-class
//! candidates of [`crate::homology::natural`], least stretched first.

use crate::error::Result;
use crate::homology::matching::{MatchingOptions, find_matching, parse_matching};
use crate::homology::natural::{ClassCandidate, NaturalClassOptions, natural_classes};
use crate::homology::sides::Sides;
use crate::mesh::VertexId;
use crate::pipeline::spec::ClassChoice;
use crate::progress::Progress;
use serde::Serialize;

/// Natural-class candidates relaxed at most.
pub const MAX_RELAXED: usize = 3;

/// Candidates whose stretch before relaxation is within this fraction of the least are all
/// relaxed and compared afterwards: a symmetric shape (a torus of revolution turned about an
/// axis through the anchor) has two classes of nearly equal stretch, and only the true one
/// relaxes to an isometry (measured: 1.0949 and 1.1012 before, 1.034 against 1.003 after).
pub const CLOSE: f64 = 0.15;

/// The classes to relax and what the choice needs afterwards.
#[derive(Debug, Clone)]
pub struct ClassPlan {
    /// Basis indices and rotation, in the order they are relaxed.
    pub tries: Vec<([usize; 2], usize)>,
    /// How many of `tries` are relaxed whatever the outcome (the close ones); the rest only
    /// while no relaxed class is fold-free.
    pub compare: usize,
    /// The H1 matrix a matching asked for (checked on the map built).
    pub want: Option<Vec<Vec<i32>>>,
    /// The natural search's candidates (one per class), least stretched first.
    pub candidates: Vec<ClassCandidate>,
}

impl ClassPlan {
    /// Resolves `choice` on the meshes through the base pair `pairs[0]`; the natural search
    /// builds its bases in `sides` (the source's and the target's through that pair).
    ///
    /// # Errors
    /// An unparsable or unreachable matching; what the natural search reports.
    pub fn new(
        choice: ClassChoice<'_>,
        sides: (&Sides<'_>, &Sides<'_>),
        pairs: &[(VertexId, VertexId)],
        progress: &mut dyn Progress,
    ) -> Result<ClassPlan> {
        let (source, target) = (sides.0.mesh(), sides.1.mesh());
        let one = |basis, rotation, want| ClassPlan {
            tries: vec![(basis, rotation)],
            compare: 1,
            want,
            candidates: Vec::new(),
        };
        match choice {
            ClassChoice::Explicit { basis, rotation } => Ok(one(basis, rotation, None)),
            ClassChoice::Matching(entries) => {
                let g = crate::topology::summary(source).genus.max(0) as usize;
                let w = parse_matching(g, entries)?;
                let found = find_matching(source, target, pairs[0], &w, &MatchingOptions::default())?;
                Ok(one(found.basis, found.rotation, Some(w)))
            }
            ClassChoice::Natural => {
                let n = natural_classes(sides.0, sides.1, &pairs[1..], &NaturalClassOptions::default(), progress)?;
                let tries: Vec<_> = n.candidates.iter().take(MAX_RELAXED).map(|c| (c.basis, c.rotation)).collect();
                let least = n.candidates.first().map_or(f64::INFINITY, |c| c.stretch);
                let compare =
                    n.candidates.iter().take(MAX_RELAXED).filter(|c| c.stretch <= least * (1.0 + CLOSE)).count();
                Ok(ClassPlan { tries, compare: compare.max(1), want: None, candidates: n.candidates })
            }
        }
    }
}

/// A candidate as `metrics.json` lists it: the search's figures, and the relaxed map's when it
/// was relaxed.
#[derive(Debug, Clone, Serialize)]
pub struct CandidateReport {
    #[serde(flatten)]
    pub class: ClassCandidate,
    /// Flipped faces (source → target, target → source) after relaxation.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub flips: Option<[usize; 2]>,
    /// L2 stretch both ways after relaxation.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub l2_stretch: Option<[f64; 2]>,
}

/// One relaxed class's outcome, to rank it: fewer flips, then lower mean stretch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Relaxed {
    pub flips: [usize; 2],
    pub l2_stretch: [f64; 2],
}

impl Relaxed {
    /// The outcome of a relaxed pair.
    pub fn of(f: &crate::pipeline::common::relax::FinishedPair) -> Relaxed {
        Relaxed { flips: [f.m1.flipped_faces, f.m2.flipped_faces], l2_stretch: [f.m1.l2_stretch, f.m2.l2_stretch] }
    }

    pub fn better_than(&self, o: &Relaxed) -> bool {
        let key = |r: &Relaxed| (r.flips[0] + r.flips[1], 0.5 * (r.l2_stretch[0] + r.l2_stretch[1]));
        let (a, b) = (key(self), key(o));
        a.0 < b.0 || (a.0 == b.0 && a.1 < b.1)
    }
}

/// The candidates best first: the chosen one (`chosen`, an index into `plan.candidates`), then
/// the other relaxed ones by outcome, then the rest by stretch.
pub fn candidate_reports(plan: &ClassPlan, relaxed: &[Relaxed], chosen: usize) -> Vec<CandidateReport> {
    let mut out: Vec<(usize, CandidateReport)> = plan
        .candidates
        .iter()
        .enumerate()
        .map(|(i, c)| {
            let r = relaxed.get(i);
            (i, CandidateReport { class: c.clone(), flips: r.map(|r| r.flips), l2_stretch: r.map(|r| r.l2_stretch) })
        })
        .collect();
    out.sort_by(|(i, a), (j, b)| {
        let rank = |k: usize, r: &CandidateReport| (k != chosen, r.flips.is_none());
        rank(*i, a).cmp(&rank(*j, b)).then_with(|| match (relaxed.get(*i), relaxed.get(*j)) {
            (Some(x), Some(y)) if x.better_than(y) => std::cmp::Ordering::Less,
            (Some(x), Some(y)) if y.better_than(x) => std::cmp::Ordering::Greater,
            _ => a.class.stretch.total_cmp(&b.class.stretch),
        })
    });
    out.into_iter().map(|(_, r)| r).collect()
}
