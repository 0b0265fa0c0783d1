//! Canonical homology basis through one base vertex (Carner et al. 2005, section 3.2).
//!
//! The paper finds candidate loops as shortest paths between preimages of the base vertex in
//! the universal covering space and searches their intersection matrices for a symplectic set.
//! We build the same object incrementally and certify it combinatorially, which never needs
//! floating-point crossing tests: for each handle, `a` is the shortest simple non-separating
//! loop through the current corner (tree–cotree over the surface cut so far: the covering-space
//! search restricted to one sheet, see [`super::search`]), and `b` is the shortest path that
//! leaves `a` on one side and comes back on the other. Both avoid everything cut before, so the
//! loops meet only at the base vertex, every `a_i` crosses `b_i` once there, and cutting them
//! inserts the commutator `a b a⁻¹ b⁻¹` at the corner. The next handle starts at a corner
//! between commutators, so the final disk reads `a1 b1 a1⁻¹ b1⁻¹ … ag bg ag⁻¹ bg⁻¹`; the word
//! and the intersection matrix are read back from the result and checked.
//!
//! `basis_index = k` takes the `k`-th shortest class (mod 2) for the first loop, giving the
//! enumeration of bases, shortest first. Where the mesh is too coarse for disjoint loops (the
//! paper's "refine the mesh locally where curves would share edges"), the base vertex's
//! valence is raised and, failing that, the mesh is subdivided at edge midpoints.

use super::search::{each_nonseparating_loop, interior_path};
use super::word::{Letter, canonical_rotation, canonical_rotations, intersection_matrix, read_word};
use crate::error::{Error, InputError, Result};
use crate::mesh::cut::{CutMesh, cut_along, path_edges};
use crate::mesh::refine::Refined;
use crate::mesh::{Mesh, VertexId};
use crate::topology;
use serde::{Deserialize, Serialize};

/// Options for [`canonical_basis`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct CanonicalBasisOptions {
    /// Which basis of the enumeration (0 = shortest).
    pub basis_index: usize,
    /// Rounds of midpoint subdivision allowed when loops would touch.
    pub max_subdivisions: usize,
    /// Refinement steps to take before a basis is accepted (see
    /// [`CanonicalBasisResult::attempt`]): two meshes mapped to each other are refined alike.
    pub min_attempt: usize,
}

impl Default for CanonicalBasisOptions {
    fn default() -> Self {
        Self { basis_index: 0, max_subdivisions: 2, min_attempt: 0 }
    }
}

/// A canonical basis and the disk it cuts.
#[derive(Debug, Clone)]
pub struct CanonicalBasisResult {
    /// The refinement the loops live on.
    pub refined: Refined,
    pub base: VertexId,
    /// `a1, b1, a2, b2, …`: vertex lists from the base back to the base.
    pub loops: Vec<Vec<VertexId>>,
    /// Algebraic intersection numbers (`loops[i] · loops[j]`).
    pub intersection: Vec<Vec<i32>>,
    /// The refined mesh cut open along the loops.
    pub disk: CutMesh,
    /// The disk's boundary (vertices of `disk.mesh`), starting at the corner before `a1`.
    pub walk: Vec<VertexId>,
    /// Positions in `walk` of the `4g` corners.
    pub corners: Vec<usize>,
    /// The boundary word, one letter per side.
    pub word: Vec<Letter>,
    /// Subdivision rounds that were needed.
    pub subdivisions: usize,
    /// Searches run before this basis was found (each failed one refines the mesh).
    pub attempt: usize,
}

impl CanonicalBasisResult {
    pub fn genus(&self) -> usize {
        self.loops.len() / 2
    }

    /// The word as text, e.g. `a1 b1 a1^-1 b1^-1`.
    pub fn word_text(&self) -> String {
        self.word
            .iter()
            .map(|l| {
                let name = if l.loop_id % 2 == 0 { 'a' } else { 'b' };
                let inv = if l.dir < 0 { "^-1" } else { "" };
                format!("{name}{}{inv}", l.loop_id / 2 + 1)
            })
            .collect::<Vec<_>>()
            .join(" ")
    }
}

/// Computes a canonical homology basis of a closed mesh through `base`.
///
/// # Errors
/// `InvalidInput` for a mesh with boundary or genus 0 (no basis), or when no disjoint basis
/// is found within the allowed refinement; `Internal` when a certificate fails.
pub fn canonical_basis(mesh: &Mesh, base: VertexId, opts: &CanonicalBasisOptions) -> Result<CanonicalBasisResult> {
    Ok(canonical_basis_avoiding(mesh, base, opts, &[])?.0)
}

/// [`canonical_basis`] with loops that keep off the vertices of `avoid` (feature curves, vertex
/// paths of `mesh`): they are walls for every search, like the boundary of the surface cut so
/// far. Returns the basis and the curves on its refinement (edges split by a refinement step are
/// followed through their midpoints).
///
/// # Errors
/// As [`canonical_basis`]; `InvalidInput` when `base` lies on a curve.
pub fn canonical_basis_avoiding(
    mesh: &Mesh,
    base: VertexId,
    opts: &CanonicalBasisOptions,
    avoid: &[Vec<VertexId>],
) -> Result<(CanonicalBasisResult, Loops)> {
    let s = topology::summary(mesh);
    if s.boundary_loops != 0 {
        return Err(InputError::Invalid(
            "canonical basis: the mesh has boundary loops (treat them as features)".into(),
        )
        .into());
    }
    if s.genus <= 0 {
        return Err(InputError::Invalid("canonical basis: genus 0 has no homology basis".into()).into());
    }
    if base.idx() >= mesh.n_vertices() {
        return Err(InputError::OutOfRange { what: "base vertex", index: base.idx(), count: mesh.n_vertices() }.into());
    }
    if avoid.iter().flatten().any(|&v| v == base) {
        return Err(
            InputError::Invalid(format!("canonical basis: base vertex {} lies on a feature curve", base.0)).into()
        );
    }
    let g = s.genus as usize;
    // The greedy search through every refinement first; only when it finds no basis at all,
    // the same refinements again with backtracking. Only the first bases take the second
    // pass: it costs tens of seconds where the greedy search is stuck (git show 32d23d1:bench/NOTES.md).
    let passes: &[usize] = if opts.basis_index < BACKTRACKED_BASES { &[0, MAX_DETOURS] } else { &[0] };
    for (pass, &detours) in passes.iter().enumerate() {
        if let Some(found) = one_pass(mesh, base, g, opts, avoid, (pass, detours))? {
            return Ok(found);
        }
    }
    let walls = if avoid.is_empty() {
        ""
    } else {
        " that keeps off the feature curves (try another base vertex, i.e. first anchor, another basis index, or curves placed apart from the handles)"
    };
    Err(InputError::Invalid(format!(
        "canonical basis: no {}-loop basis through vertex {} with disjoint loops{walls} after {} subdivisions",
        2 * g,
        base.0,
        opts.max_subdivisions
    ))
    .into())
}

/// One pass of the basis search over every refinement: `detours` dead ends allowed to each
/// search (0: greedy); `None` when no refinement gives a basis.
fn one_pass(
    mesh: &Mesh,
    base: VertexId,
    g: usize,
    opts: &CanonicalBasisOptions,
    avoid: &[Vec<VertexId>],
    (pass, detours): (usize, usize),
) -> Result<Option<(CanonicalBasisResult, Loops)>> {
    let mut refined = Refined::identity(mesh);
    let mut curves = avoid.to_vec();
    refine_with(&mut refined, &mut curves, |r| r.raise_valence(base, 8 * g + 8))?;
    for round in 0..=opts.max_subdivisions {
        // A crowded base vertex first gets more edges (twice, then four times as many); loops
        // that pen the corner in (neighbouring loop vertices joined by an edge) get those
        // edges split, which opens an interior vertex between them.
        let mut local = refined.clone();
        let mut local_curves = curves.clone();
        for extra in 0..ATTEMPTS_PER_ROUND {
            let attempt = round * ATTEMPTS_PER_ROUND + extra;
            let t0 = std::time::Instant::now();
            let blocked = blocked_by(&local.mesh, &local_curves);
            let mut res = search(&local.mesh, &blocked, base, g, opts.basis_index, detours)?;
            // With walls, the first handle's class can leave a later handle no room where the
            // next classes do: try those before refining (the stuck search's loops still
            // decide the refinement). Without walls nothing changes.
            if res.is_err() && !blocked.is_empty() && attempt >= opts.min_attempt {
                for k in 1..=WALLED_EXTRA_CLASSES {
                    if let Ok(loops) = search(&local.mesh, &blocked, base, g, opts.basis_index + k, detours)? {
                        res = Ok(loops);
                        break;
                    }
                }
            }
            debug(|| {
                format!(
                    "attempt pass {pass} round {round} extra {extra}: {} vertices, {:.2} s, {}",
                    local.mesh.n_vertices(),
                    t0.elapsed().as_secs_f64(),
                    if res.is_ok() { "found" } else { "stuck" }
                )
            });
            let partial = match res {
                Ok(loops) if attempt >= opts.min_attempt => {
                    return finish(local, base, loops, local_curves, round, attempt).map(Some);
                }
                Ok(loops) | Err(loops) => loops,
            };
            // Loops that pen a corner in leave no vertex between them: split every edge at
            // their vertices (a band of new vertices along each loop); a crowded base vertex
            // gets twice its edges; chords joining loop vertices are split. Then search again.
            // The second failure takes the whole remedy at once (the loops found so far are
            // threaded through each step); later ones take one step each.
            let mut partial = partial;
            for &step in REFINE_STEPS[extra.min(REFINE_STEPS.len() - 1)] {
                let before = local.mesh.clone();
                refine_with(&mut local, &mut local_curves, |r| match step {
                    Step::Band => r.split_edges(&band_of(&r.mesh, &partial, base)),
                    Step::Chords => r.split_edges(&chords_of(&r.mesh, &partial)),
                    Step::Valence => {
                        let valence = r.mesh.outgoing(base).count();
                        r.raise_valence(base, 2 * valence)
                    }
                })?;
                match rethread(&before, &local.mesh, &partial) {
                    Some(p) => partial = p,
                    None => break,
                }
            }
        }
        if round < opts.max_subdivisions {
            refine_with(&mut refined, &mut curves, |r| r.subdivide()?.raise_valence(base, 8 * g + 8))?;
        }
    }
    Ok(None)
}

/// Applies one refinement to `r` and follows `curves` through it.
///
/// # Errors
/// As the refinement; `Internal` when a curve cannot be followed (a split off the midpoint).
fn refine_with(r: &mut Refined, curves: &mut Loops, step: impl FnOnce(&Refined) -> Result<Refined>) -> Result<()> {
    let next = step(r)?;
    if !curves.is_empty() {
        *curves = rethread(&r.mesh, &next.mesh, curves)
            .ok_or_else(|| Error::Internal("canonical basis: a feature curve lost its edges in a refinement".into()))?;
    }
    *r = next;
    Ok(())
}

/// Per vertex of `mesh`: on one of `curves` (empty without curves).
fn blocked_by(mesh: &Mesh, curves: &[Vec<VertexId>]) -> Vec<bool> {
    if curves.is_empty() {
        return Vec::new();
    }
    let mut b = vec![false; mesh.n_vertices()];
    for v in curves.iter().flatten() {
        b[v.idx()] = true;
    }
    b
}

/// `blocked` (per vertex of the uncut mesh) per vertex of `s`.
fn blocked_on(s: &CutMesh, blocked: &[bool]) -> Vec<bool> {
    if blocked.is_empty() { Vec::new() } else { s.orig.iter().map(|o| blocked[o.idx()]).collect() }
}

/// Further classes of the first loop tried, when curves are walls: by the first handle, and by
/// a whole search before refining.
const WALLED_EXTRA_CLASSES: usize = 2;

/// Searches per subdivision round (each failed one refines before the next).
pub(crate) const ATTEMPTS_PER_ROUND: usize = 6;

/// One local refinement around the loops found by a stuck search.
#[derive(Debug, Clone, Copy)]
enum Step {
    /// Split every edge at a loop vertex (the base's own edges excepted).
    Band,
    /// Double the base vertex's valence.
    Valence,
    /// Split edges that join two loop vertices without being on a loop.
    Chords,
}

/// What each failed search of a round applies before the next.
const REFINE_STEPS: [&[Step]; 6] = [
    &[Step::Band],
    &[Step::Band, Step::Valence, Step::Chords, Step::Band],
    &[Step::Band],
    &[Step::Valence],
    &[Step::Chords],
    &[Step::Band],
];

/// Handle by handle on the surface cut so far; `Err(partial)` when loops would have to touch.
/// Each handle tries the corners between commutators (most reachable interior first) and, at
/// each, the shortest few non-separating classes, until one admits its crossing loop. When a
/// later handle finds no room, the search backtracks: the earlier handles' other classes and
/// corners are tried (after at most `max_detours` dead ends it gives up; 0 is the greedy
/// search), since a lasso cut beside an earlier loop can pen the next corners into pockets
/// that another choice leaves open. The greedy path is tried first; a stuck search reports the
/// greedy path's loops, which direct the refinement.
fn search(
    mesh: &Mesh,
    blocked: &[bool],
    base: VertexId,
    g: usize,
    first: usize,
    max_detours: usize,
) -> Result<std::result::Result<Loops, Loops>> {
    let s = CutMesh { mesh: mesh.clone(), orig: (0..mesh.n_vertices()).map(VertexId::from_idx).collect() };
    let mut h = HandleSearch { blocked, base, g, first, max_detours, detours: 0, partial: None };
    let found = h.descend(0, s, blocked.to_vec(), vec![base], Vec::with_capacity(2 * g))?;
    Ok(found.ok_or_else(|| h.partial.unwrap_or_default()))
}

/// Dead ends the backtracking basis search may back out of before it gives up (each costs a
/// cut and a search or two; genus3 through vertex 6555 needs this pass, see git show 32d23d1:bench/NOTES.md).
const MAX_DETOURS: usize = 30;

/// Basis indices whose search may backtrack: basis 0 is the reference a job cannot do without;
/// 1–3 gave 3holes seeds 2 and 3 their true class.
const BACKTRACKED_BASES: usize = 4;

/// The state shared by the levels of the backtracking search.
struct HandleSearch<'a> {
    blocked: &'a [bool],
    base: VertexId,
    g: usize,
    first: usize,
    max_detours: usize,
    detours: usize,
    /// The first dead end's loops (the greedy path's).
    partial: Option<Loops>,
}

impl HandleSearch<'_> {
    /// Cuts handles `handle..g` from `s`, whose earlier loops are `loops`; `None` at a dead end
    /// (recorded) or when the detour budget is spent.
    fn descend(
        &mut self,
        handle: usize,
        s: CutMesh,
        walls: Vec<bool>,
        corners: Vec<VertexId>,
        loops: Loops,
    ) -> Result<Option<Loops>> {
        if handle == self.g {
            return Ok(Some(loops));
        }
        let blocked = self.blocked;
        let mut out = None;
        let mut admitted = 0;
        for &corner in &corners {
            // With walls (feature curves) the first handle may also try the next two classes:
            // a loop that runs beside a curve can leave its crossing path no room.
            let extra = if blocked.is_empty() { 0 } else { WALLED_EXTRA_CLASSES };
            let (skip, count) = if handle == 0 { (self.first, self.first + 1 + extra) } else { (0, 3) };
            // Candidates one at a time: the first whose handle leads to a whole basis ends it.
            let mut seen = 0;
            let n_cands = each_nonseparating_loop(&s.mesh, &walls, corner, count, &mut |a| {
                seen += 1;
                if seen <= skip || self.exhausted() {
                    return Ok(self.exhausted());
                }
                let Some((a, b, s1_orig_b, s2)) = cross(&s, blocked, corner, &a, handle == 0)? else {
                    return Ok(false);
                };
                admitted += 1;
                let mut next = loops.clone();
                next.push(a.iter().map(|&v| s.orig[v.idx()]).collect());
                next.push(b.iter().map(|&v| s1_orig_b[v.idx()]).collect());
                let Some(w) = read_word(&s2.mesh, &s2.orig, self.base, &next) else {
                    debug(|| format!("handle {handle}: cut surface word unreadable"));
                    self.dead_end(next);
                    return Ok(false);
                };
                // Any corner between commutators will do: most reachable interior first (loops
                // that run side by side can pen a corner into a small pocket), then the widest.
                let mut cs: Vec<VertexId> =
                    canonical_rotations(&w.letters).into_iter().map(|r| w.walk[w.corners[r]]).collect();
                if cs.is_empty() {
                    return Err(Error::Internal(format!("basis: handle {} left a non-canonical word", handle + 1)));
                }
                let walls2 = blocked_on(&s2, blocked);
                {
                    let reach = interior_components(&s2.mesh, &walls2);
                    cs.sort_by_key(|&c| {
                        std::cmp::Reverse((reach(c), s2.mesh.outgoing(c).count(), std::cmp::Reverse(c.0)))
                    });
                }
                out = self.descend(handle + 1, s2, walls2, cs, next)?;
                Ok(out.is_some() || self.exhausted())
            })?;
            if out.is_some() || self.exhausted() {
                break;
            }
            debug(|| {
                format!(
                    "handle {handle}: no loop pair at corner {} ({n_cands} loops, fan {}, interior {})",
                    corner.0,
                    s.mesh.outgoing(corner).count(),
                    interior_components(&s.mesh, &walls)(corner)
                )
            });
        }
        if out.is_none() && admitted == 0 {
            self.dead_end(loops);
        }
        Ok(out)
    }

    fn exhausted(&self) -> bool {
        self.detours > self.max_detours
    }

    /// Records a dead end: the first one's loops are the search's partial result.
    fn dead_end(&mut self, loops: Loops) {
        self.detours += 1;
        if self.partial.is_none() {
            self.partial = Some(loops);
        }
    }
}

type Loops = Vec<Vec<VertexId>>;

/// `loops` (vertex lists of `before`) on `after`, a refinement that split some of their edges at
/// midpoints: each split step goes through its midpoint. `None` when a step cannot be followed.
fn rethread(before: &Mesh, after: &Mesh, loops: &[Vec<VertexId>]) -> Option<Loops> {
    loops
        .iter()
        .map(|l| {
            let mut out = vec![*l.first()?];
            for w in l.windows(2) {
                if crate::mesh::cut::edge_between(after, w[0], w[1]).is_none() {
                    let mid = nalgebra::center(&before.position(w[0]), &before.position(w[1]));
                    let m = after.vertex_neighbors(w[0]).find(|&m| {
                        after.position(m) == mid && crate::mesh::cut::edge_between(after, m, w[1]).is_some()
                    })?;
                    out.push(m);
                }
                out.push(w[1]);
            }
            Some(out)
        })
        .collect()
}

/// Edges at the loops' vertices (the base vertex's own edges excepted).
fn band_of(mesh: &Mesh, loops: &[Vec<VertexId>], base: VertexId) -> Vec<[VertexId; 2]> {
    let mut on = vec![false; mesh.n_vertices()];
    for l in loops {
        for v in l {
            on[v.idx()] = true;
        }
    }
    on[base.idx()] = false;
    (0..mesh.n_edges())
        .map(|e| mesh.edge_vertices(crate::mesh::EdgeId::from_idx(e)))
        .filter(|[a, b]| (on[a.idx()] || on[b.idx()]) && *a != base && *b != base)
        .collect()
}

/// Edges that are not on the loops but join two of their vertices.
fn chords_of(mesh: &Mesh, loops: &[Vec<VertexId>]) -> Vec<[VertexId; 2]> {
    let mut on = vec![false; mesh.n_vertices()];
    for l in loops {
        for v in l {
            on[v.idx()] = true;
        }
    }
    let Ok(cut) = path_edges(mesh, loops) else { return Vec::new() };
    (0..mesh.n_edges())
        .filter(|&e| !cut[e])
        .map(|e| mesh.edge_vertices(crate::mesh::EdgeId::from_idx(e)))
        .filter(|[a, b]| on[a.idx()] && on[b.idx()])
        .collect()
}

/// Cuts `a` (a loop at `corner` of `s`) and looks for `b` from one side of it to the other,
/// keeping off `blocked` (per vertex of the uncut mesh).
/// Returns `a`, `b` (in the ids of `s` and of the intermediate cut), that cut's `orig`, and the
/// surface cut along both.
#[allow(clippy::type_complexity)]
fn cross(
    s: &CutMesh,
    blocked: &[bool],
    corner: VertexId,
    a: &[VertexId],
    interior: bool,
) -> Result<Option<(Vec<VertexId>, Vec<VertexId>, Vec<VertexId>, CutMesh)>> {
    let s1 = compose(s, cut_along(&s.mesh, &path_edges(&s.mesh, &[a.to_vec()])?)?);
    let local: Vec<VertexId> = copies_of(&s1, s, corner);
    if local.len() < 2 {
        return Ok(None);
    }
    // From the copy between a's two ends to a copy on either outer side.
    let from = if interior {
        local[0]
    } else {
        match middle_copy(&s1, s, &local) {
            Some(m) => m,
            None => return Ok(None),
        }
    };
    let to: Vec<VertexId> = local.iter().copied().filter(|&c| c != from).collect();
    let on_a: std::collections::HashSet<VertexId> = a.iter().copied().collect();
    let on_new = |w: VertexId| s1_local(&s1, s, w).is_some_and(|x| on_a.contains(&x));
    let Some(b) = interior_path(&s1.mesh, &blocked_on(&s1, blocked), from, &to, &on_new) else { return Ok(None) };
    let s2 = compose(&s1, cut_along(&s1.mesh, &path_edges(&s1.mesh, std::slice::from_ref(&b))?)?);
    Ok(Some((a.to_vec(), b, s1.orig, s2)))
}

/// For any vertex: how many interior vertices its interior neighbours reach through interior
/// vertices (one labelling of the interior's components serves every corner).
fn interior_components<'a>(mesh: &'a Mesh, blocked: &[bool]) -> impl Fn(VertexId) -> usize + 'a {
    let wall = |v: VertexId| super::search::wall(mesh, blocked, v);
    let n = mesh.n_vertices();
    let mut comp = vec![u32::MAX; n];
    let mut size: Vec<usize> = Vec::new();
    for v0 in 0..n {
        let v0 = VertexId::from_idx(v0);
        if comp[v0.idx()] != u32::MAX || wall(v0) {
            continue;
        }
        let id = size.len() as u32;
        let mut stack = vec![v0];
        comp[v0.idx()] = id;
        let mut count = 0;
        while let Some(v) = stack.pop() {
            count += 1;
            for w in mesh.vertex_neighbors(v) {
                if comp[w.idx()] == u32::MAX && !wall(w) {
                    comp[w.idx()] = id;
                    stack.push(w);
                }
            }
        }
        size.push(count);
    }
    move |c: VertexId| {
        let mut seen: Vec<u32> = Vec::new();
        let mut total = 0;
        for w in mesh.vertex_neighbors(c) {
            let k = comp[w.idx()];
            if k != u32::MAX && !seen.contains(&k) {
                seen.push(k);
                total += size[k as usize];
            }
        }
        total
    }
}

/// `inner` cut from `outer.mesh`; returns it with `orig` pointing into the uncut mesh.
fn compose(outer: &CutMesh, inner: CutMesh) -> CutMesh {
    let orig = inner.orig.iter().map(|&v| outer.orig[v.idx()]).collect();
    CutMesh { mesh: inner.mesh, orig }
}

/// The copies in `s1` of `corner` (a vertex of `s`).
fn copies_of(s1: &CutMesh, s: &CutMesh, corner: VertexId) -> Vec<VertexId> {
    (0..s1.mesh.n_vertices()).map(VertexId::from_idx).filter(|&v| s1_local(s1, s, v) == Some(corner)).collect()
}

/// The vertex of `s` that vertex `v` of `s1` (cut from `s`) copies: found through a face, since
/// both meshes list faces in the same order.
fn s1_local(s1: &CutMesh, s: &CutMesh, v: VertexId) -> Option<VertexId> {
    let h = s1.mesh.outgoing(v).next()?;
    Some(s.mesh.tail(h))
}

/// The copy whose two boundary edges are both new (it lies between the cut loop's ends).
fn middle_copy(s1: &CutMesh, s: &CutMesh, copies: &[VertexId]) -> Option<VertexId> {
    copies.iter().copied().find(|&c| {
        let nb: Vec<VertexId> = s1.mesh.vertex_neighbors(c).collect();
        let (Some(&first), Some(&last)) = (nb.first(), nb.last()) else { return false };
        let old = |w: VertexId| {
            let (Some(sc), Some(sw)) = (s1_local(s1, s, c), s1_local(s1, s, w)) else { return true };
            crate::mesh::cut::edge_between(&s.mesh, sc, sw).is_some_and(|e| s.mesh.is_boundary_edge(e))
        };
        !old(first) && !old(last)
    })
}

/// Splits chords (edges off the loops with both ends on them), cuts the disk, certifies it.
fn finish(
    refined: Refined,
    base: VertexId,
    loops: Vec<Vec<VertexId>>,
    mut curves: Loops,
    subdivisions: usize,
    attempt: usize,
) -> Result<(CanonicalBasisResult, Loops)> {
    let on_cut = {
        let mut f = vec![false; refined.mesh.n_vertices()];
        for l in &loops {
            for v in l {
                f[v.idx()] = true;
            }
        }
        f
    };
    let cut = path_edges(&refined.mesh, &loops)?;
    let chords: Vec<[VertexId; 2]> = (0..refined.mesh.n_edges())
        .filter(|&e| !cut[e])
        .map(|e| refined.mesh.edge_vertices(crate::mesh::EdgeId::from_idx(e)))
        .filter(|[a, b]| on_cut[a.idx()] && on_cut[b.idx()])
        .collect();
    let mut refined = refined;
    refine_with(&mut refined, &mut curves, |r| r.split_edges(&chords))?;
    let disk = cut_along(&refined.mesh, &path_edges(&refined.mesh, &loops)?)?;
    let chi = topology::euler_characteristic(&disk.mesh);
    let w = read_word(&disk.mesh, &disk.orig, base, &loops)
        .ok_or_else(|| Error::Internal("basis: the cut surface does not have one boundary loop".into()))?;
    let r =
        canonical_rotation(&w.letters).ok_or_else(|| Error::Internal("basis: final word is not canonical".into()))?;
    if chi != 1 {
        return Err(Error::Internal(format!("basis: the cut surface has Euler characteristic {chi}, not 1")));
    }
    // Relabel: side 4j is a_{j+1}, side 4j+1 is b_{j+1}, oriented as read.
    let n = w.letters.len();
    let mut labeled = Vec::with_capacity(loops.len());
    for j in 0..n / 4 {
        for k in 0..2 {
            let l = w.letters[(r + 4 * j + k) % n];
            let mut lp = loops[l.loop_id].clone();
            if l.dir < 0 {
                lp.reverse();
            }
            labeled.push(lp);
        }
    }
    let start = w.corners[r];
    let m = w.walk.len();
    let walk: Vec<VertexId> = (0..m).map(|i| w.walk[(start + i) % m]).collect();
    let w2 = read_word(&disk.mesh, &disk.orig, base, &labeled)
        .ok_or_else(|| Error::Internal("basis: relabeled word unreadable".into()))?;
    let r2 = w2.corners.iter().position(|&c| w2.walk[c] == walk[0]).unwrap_or(0);
    let word: Vec<Letter> = (0..n).map(|i| w2.letters[(r2 + i) % n]).collect();
    let corners: Vec<usize> = (0..m).filter(|&i| disk.orig[walk[i].idx()] == base).collect();
    let intersection = intersection_matrix(&refined.mesh, base, &labeled);
    let basis = CanonicalBasisResult {
        refined,
        base,
        loops: labeled,
        intersection,
        disk,
        walk,
        corners,
        word,
        subdivisions,
        attempt,
    };
    Ok((basis, curves))
}

/// Prints what `msg` says under debug-level tracing (built only then).
fn debug(msg: impl FnOnce() -> String) {
    if tracing::enabled!(tracing::Level::DEBUG) {
        tracing::debug!("homology basis: {}", msg());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    #[test]
    fn torus_basis_is_canonical_and_certified() {
        let t = shapes::torus(24, 12, 1.0, 0.3);
        for base in [0u32, 37, 150] {
            let r = canonical_basis(&t, VertexId(base), &CanonicalBasisOptions::default()).unwrap();
            assert_eq!(r.word_text(), "a1 b1 a1^-1 b1^-1");
            assert_eq!(r.intersection, vec![vec![0, 1], vec![-1, 0]]);
            assert_eq!(topology::euler_characteristic(&r.disk.mesh), 1);
            assert_eq!(r.corners.len(), 4);
            // Loops are closed at the base and share no other vertex.
            let mut seen = std::collections::HashSet::new();
            for l in &r.loops {
                assert_eq!((l[0], l[l.len() - 1]), (VertexId(base), VertexId(base)));
                assert!(l[1..l.len() - 1].iter().all(|v| seen.insert(*v)));
            }
        }
    }

    /// A curve across the torus's outer equator: the loops keep off it (it is a wall), the basis
    /// stays canonical, and a base on the curve is refused.
    #[test]
    fn the_basis_keeps_off_curves() {
        let t = shapes::torus(24, 12, 1.0, 0.3);
        let free = canonical_basis(&t, VertexId(0), &CanonicalBasisOptions::default()).unwrap();
        // Vertices of the first loop away from the base: a wall the unconstrained basis crosses.
        let l = &free.loops[0];
        let curve: Vec<VertexId> = l[l.len() / 2 - 1..=l.len() / 2 + 1].to_vec();
        let o = CanonicalBasisOptions::default();
        let (r, moved) = canonical_basis_avoiding(&t, VertexId(0), &o, std::slice::from_ref(&curve)).unwrap();
        assert_eq!(r.word_text(), "a1 b1 a1^-1 b1^-1");
        assert_eq!(r.intersection, vec![vec![0, 1], vec![-1, 0]]);
        assert_eq!(topology::euler_characteristic(&r.disk.mesh), 1);
        assert_eq!(moved.len(), 1);
        assert!(r.loops.iter().flatten().all(|v| !moved[0].contains(v)), "a loop runs through the curve");
        let on = canonical_basis_avoiding(&t, curve[1], &o, std::slice::from_ref(&curve)).unwrap_err();
        assert!(on.is_input(), "{on}");
    }

    #[test]
    fn bases_are_enumerated_and_bad_input_refused() {
        let t = shapes::torus(24, 12, 1.0, 0.3);
        let o = |k| CanonicalBasisOptions { basis_index: k, ..Default::default() };
        let a = canonical_basis(&t, VertexId(0), &o(0)).unwrap();
        let b = canonical_basis(&t, VertexId(0), &o(1)).unwrap();
        assert_ne!(a.loops, b.loops, "the second basis starts from another class");
        let sphere = shapes::icosphere(2);
        assert!(canonical_basis(&sphere, VertexId(0), &o(0)).unwrap_err().is_input());
        assert!(canonical_basis(&t, VertexId(1_000_000), &o(0)).unwrap_err().is_input());
        let disk = shapes::grid(4);
        assert!(canonical_basis(&disk, VertexId(0), &o(0)).unwrap_err().is_input());
    }
}
