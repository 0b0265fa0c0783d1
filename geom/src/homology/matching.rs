//! An explicit curve matching (Carner et al. section 5: "choosing and matching basis curves"):
//! the user says where each source loop should go, e.g. `a1 -> b1`, `b1 -> -a1` (the quarter
//! turn) or `a1 -> a1+b1`, `b1 -> b1` (a Dehn twist). That is an integer matrix on H1, which an
//! orientation-preserving map can only induce if it is symplectic (`MᵀJM = J`). We realize it
//! by searching the homotopy classes the method can build — basis `k` on each mesh (the k-th
//! shortest first loop class) and every rotation τ — for one whose induced map on H1, read in
//! the reference bases (basis 0 on each mesh, see [`super::classes`]), equals the request; the
//! H1 matrix of each candidate comes from the bases' intersection numbers and integer classes
//! alone, so only the chosen class is mapped.

use super::basis::{CanonicalBasisOptions, CanonicalBasisResult, canonical_basis};
use super::classes::{change_of_basis, in_reference, loop_classes};
use super::cocycle::{IntCohomology, integer_cohomology};
use super::map::{induced_h1_for, rotation_count};
use crate::error::{InputError, Result};
use crate::mesh::{Mesh, VertexId};
use nalgebra::DMatrix;

/// Options for [`find_matching`].
#[derive(Debug, Clone, PartialEq)]
pub struct MatchingOptions {
    /// Bases tried on each mesh (0..count).
    pub bases: usize,
}

impl Default for MatchingOptions {
    fn default() -> Self {
        Self { bases: 4 }
    }
}

/// The class found: basis index on each mesh and rotation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MatchingResult {
    pub basis: [usize; 2],
    pub rotation: usize,
    /// Distinct H1 matrices met on the way (what the request could have been).
    pub reachable: Vec<Vec<Vec<i32>>>,
}

/// Parses `["a1 -> b1", "b1 -> -a1", …]` for genus `g` into the matrix whose column `j` is the
/// image of source loop `j` (`a1, b1, a2, …`) in the target basis.
///
/// # Errors
/// `InputError::Spec` naming the entry at fault; a missing or repeated loop; a matrix that is
/// not symplectic.
pub fn parse_matching(g: usize, entries: &[String]) -> Result<Vec<Vec<i32>>> {
    let n = 2 * g;
    let bad = |m: String| -> crate::Error { InputError::Spec(format!("options.matching: {m}")).into() };
    let mut m = vec![vec![0i32; n]; n];
    let mut seen = vec![false; n];
    for e in entries {
        let (lhs, rhs) = e.split_once("->").ok_or_else(|| bad(format!("'{e}' is not of the form 'a1 -> b1'")))?;
        let j = loop_index(lhs.trim(), g).ok_or_else(|| bad(format!("'{}' is not a loop of genus {g}", lhs.trim())))?;
        if std::mem::replace(&mut seen[j], true) {
            return Err(bad(format!("loop '{}' is matched twice", lhs.trim())));
        }
        for (i, c) in parse_sum(rhs, g).map_err(|x| bad(format!("'{e}': {x}")))? {
            m[i][j] += c;
        }
    }
    if let Some(j) = seen.iter().position(|s| !s) {
        return Err(bad(format!("loop {} is not matched (give all {n})", loop_name(j))));
    }
    if !is_symplectic(&m) {
        return Err(bad(
            "the matching does not preserve intersection numbers (not symplectic): no orientation-preserving map induces it"
                .into(),
        ));
    }
    Ok(m)
}

fn loop_name(j: usize) -> String {
    format!("{}{}", if j.is_multiple_of(2) { 'a' } else { 'b' }, j / 2 + 1)
}

fn loop_index(s: &str, g: usize) -> Option<usize> {
    let (c, k) = s.split_at(s.char_indices().nth(1)?.0);
    let k: usize = k.parse().ok()?;
    let off = match c {
        "a" => 0,
        "b" => 1,
        _ => return None,
    };
    (1..=g).contains(&k).then_some(2 * (k - 1) + off)
}

/// `-a1 + 2b1 - b2` → `[(0, -1), (1, 2), (3, -1)]`.
fn parse_sum(s: &str, g: usize) -> std::result::Result<Vec<(usize, i32)>, String> {
    let mut out = Vec::new();
    let t: String = s.chars().filter(|c| !c.is_whitespace()).collect();
    if t.is_empty() {
        return Err("empty image".into());
    }
    let mut rest = t.as_str();
    while !rest.is_empty() {
        let (sign, r) = match rest.as_bytes()[0] {
            b'-' => (-1, &rest[1..]),
            b'+' => (1, &rest[1..]),
            _ => (1, rest),
        };
        let end = r[1..].find(['+', '-']).map_or(r.len(), |k| k + 1);
        let term = &r[..end];
        let digits = term.chars().take_while(|c| c.is_ascii_digit()).count();
        let coef: i32 =
            if digits == 0 { 1 } else { term[..digits].parse().map_err(|_| format!("bad coefficient in '{term}'"))? };
        let i = loop_index(&term[digits..], g)
            .ok_or_else(|| format!("'{}' is not a loop of genus {g}", &term[digits..]))?;
        out.push((i, sign * coef));
        rest = &r[end..];
    }
    Ok(out)
}

/// `MᵀJM = J` with `J` the standard form (`a_i·b_i = 1`).
pub fn is_symplectic(m: &[Vec<i32>]) -> bool {
    let n = m.len();
    let j = |r: usize, c: usize| -> i64 {
        if r / 2 != c / 2 || r == c {
            0
        } else if r.is_multiple_of(2) {
            1
        } else {
            -1
        }
    };
    (0..n).all(|r| {
        (0..n).all(|c| {
            let mut s = 0i64;
            for p in 0..n {
                for q in 0..n {
                    s += i64::from(m[p][r]) * j(p, q) * i64::from(m[q][c]);
                }
            }
            s == j(r, c)
        })
    })
}

/// Reference frame of one mesh: its integer cocycles and the classes of basis 0's loops.
pub struct Frame {
    coh: IntCohomology,
    a0: DMatrix<f64>,
}

impl Frame {
    /// # Errors
    /// As [`integer_cohomology`] and [`loop_classes`].
    pub fn new(mesh: &Mesh, basis0: &CanonicalBasisResult) -> Result<Frame> {
        let coh = integer_cohomology(mesh)?;
        let a0 = loop_classes(basis0, mesh, &coh)?;
        Ok(Frame { coh, a0 })
    }

    /// How `b`'s loops read in basis 0.
    ///
    /// # Errors
    /// As [`change_of_basis`].
    pub fn change(&self, mesh: &Mesh, b: &CanonicalBasisResult) -> Result<DMatrix<f64>> {
        change_of_basis(&self.a0, &loop_classes(b, mesh, &self.coh)?)
    }
}

/// The induced map `h` between bases `s` and `t` (any indices), read in the reference bases.
///
/// # Errors
/// As [`Frame::change`] and [`in_reference`].
pub fn reference_h1(
    meshes: (&Mesh, &Mesh),
    frames: (&Frame, &Frame),
    bases: (&CanonicalBasisResult, &CanonicalBasisResult),
    h: &[Vec<i32>],
) -> Result<Vec<Vec<i32>>> {
    let ps = frames.0.change(meshes.0, bases.0)?;
    let pt = frames.1.change(meshes.1, bases.1)?;
    in_reference(h, &ps, &pt)
}

/// Basis 0 of a mesh through `base` and its frame.
///
/// # Errors
/// As [`canonical_basis`] and [`Frame::new`].
pub fn reference_frame(mesh: &Mesh, base: VertexId) -> Result<(CanonicalBasisResult, Frame)> {
    let b = canonical_basis(mesh, base, &CanonicalBasisOptions::default())?;
    let f = Frame::new(mesh, &b)?;
    Ok((b, f))
}

/// Finds basis indices and a rotation whose induced map on H1, read in the reference bases
/// (basis 0 on each mesh), is `want`.
///
/// # Errors
/// `InputError::Spec` when none of the classes tried induces it (the message lists what they
/// do induce); as [`canonical_basis`].
pub fn find_matching(
    source: &Mesh,
    target: &Mesh,
    bases: (VertexId, VertexId),
    want: &[Vec<i32>],
    opts: &MatchingOptions,
) -> Result<MatchingResult> {
    let side = |m: &Mesh, b: VertexId| -> Result<(Vec<CanonicalBasisResult>, Vec<DMatrix<f64>>)> {
        let bs: Vec<CanonicalBasisResult> = (0..opts.bases)
            .map_while(|k| canonical_basis(m, b, &CanonicalBasisOptions { basis_index: k, ..Default::default() }).ok())
            .collect();
        let Some(b0) = bs.first() else {
            return Err(InputError::Invalid("matching: no canonical basis on a mesh".into()).into());
        };
        let frame = Frame::new(m, b0)?;
        let ps = bs.iter().map(|b| frame.change(m, b)).collect::<Result<Vec<_>>>()?;
        Ok((bs, ps))
    };
    let (s, t) = std::thread::scope(|sc| {
        let h = sc.spawn(|| side(target, bases.1));
        (side(source, bases.0), h.join())
    });
    let (s, ps) = s?;
    let (t, pt) = t.map_err(|_| crate::Error::Internal("matching thread panicked".into()))??;
    let mut reachable: Vec<Vec<Vec<i32>>> = Vec::new();
    let g = want.len() / 2;
    for sum in 0..2 * opts.bases {
        for (ks, sb) in s.iter().enumerate().take(sum + 1) {
            let kt = sum - ks;
            let Some(tb) = t.get(kt) else { continue };
            for r in 0..rotation_count(g) {
                let h = in_reference(&induced_h1_for(sb, tb, r), &ps[ks], &pt[kt])?;
                if h == want {
                    return Ok(MatchingResult { basis: [ks, kt], rotation: r, reachable });
                }
                if !reachable.contains(&h) {
                    reachable.push(h);
                }
            }
        }
    }
    Err(InputError::Spec(format!(
        "options.matching: no class among {} bases per mesh and {} rotations induces {want:?}; they induce {reachable:?}",
        opts.bases,
        rotation_count(g)
    ))
    .into())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matchings_parse_and_must_be_symplectic() {
        let q = parse_matching(1, &["a1 -> b1".into(), "b1 -> -a1".into()]).unwrap();
        assert_eq!(q, vec![vec![0, -1], vec![1, 0]]);
        let twist = parse_matching(1, &["a1 -> a1 + b1".into(), "b1 -> b1".into()]).unwrap();
        assert_eq!(twist, vec![vec![1, 0], vec![1, 1]]);
        let err = |e: &[&str], g| {
            parse_matching(g, &e.iter().map(|s| s.to_string()).collect::<Vec<_>>()).unwrap_err().to_string()
        };
        assert!(err(&["a1 -> b1", "b1 -> a1"], 1).contains("not symplectic"));
        assert!(err(&["a1 -> a1"], 1).contains("b1 is not matched"));
        assert!(err(&["a1 -> a1", "a1 -> b1"], 1).contains("twice"));
        assert!(err(&["a1 -> c1", "b1 -> b1"], 1).contains("not a loop"));
        assert!(err(&["a1 = b1", "b1 -> b1"], 1).contains("form"));
        let swap = parse_matching(2, &["a1 -> a2", "b1 -> b2", "a2 -> a1", "b2 -> b1"].map(String::from)).unwrap();
        assert!(is_symplectic(&swap));
    }
}
