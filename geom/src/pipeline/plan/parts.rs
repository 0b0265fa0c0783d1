//! Meshes in several parts (eyes, teeth beside a head): the parts pair up through the anchors.
//! Each pair is then mapped by the job's method on its own and the maps joined
//! ([`crate::pipeline::run`]). A part with no anchor, or anchors that pair one part with two, is a
//! typed error naming the part.

use crate::error::{InputError, Result};
use crate::mesh::Mesh;
use crate::topology::{self, components};

/// One connected component as a mesh of its own.
struct Part {
    mesh: Mesh,
    /// Local vertex -> whole vertex.
    vertices: Vec<u32>,
    /// Local face -> whole face.
    faces: Vec<u32>,
}

/// A source part and its partner, with the job's anchors and boundary rows among them in the
/// parts' own numbering.
pub struct PartPair {
    /// The source part's mesh, then the target part's.
    pub meshes: [Mesh; 2],
    /// Local vertex -> whole vertex, per side.
    pub vertices: [Vec<u32>; 2],
    /// Local face -> whole face, per side.
    pub faces: [Vec<u32>; 2],
    pub anchors: Vec<[u64; 2]>,
    pub boundaries: Vec<[u64; 2]>,
}

/// The part pairs of a job on meshes in several parts, in source part order.
pub struct PartsPlan {
    pub pairs: Vec<PartPair>,
    /// `[source part, target part]` per pair.
    pub part_pairs: Vec<[usize; 2]>,
    /// The whole job's anchors.
    pub rows: Vec<[u64; 2]>,
}

fn split(m: &Mesh) -> Result<(Vec<Part>, Vec<u32>)> {
    let c = components(m);
    let mut vlabel = vec![0u32; m.n_vertices()];
    let mut parts: Vec<(Vec<u32>, Vec<u32>)> = vec![(Vec::new(), Vec::new()); c.count];
    for (f, tri) in m.faces().iter().enumerate() {
        parts[c.face_label[f] as usize].1.push(f as u32);
        for v in tri {
            vlabel[v.idx()] = c.face_label[f];
        }
    }
    for v in 0..m.n_vertices() {
        parts[vlabel[v] as usize].0.push(v as u32);
    }
    let mut local = vec![0u32; m.n_vertices()];
    let mut out = Vec::with_capacity(c.count);
    for (vs, fs) in parts {
        for (i, &v) in vs.iter().enumerate() {
            local[v as usize] = i as u32;
        }
        let pos = vs.iter().map(|&v| m.positions()[v as usize]).collect();
        let tris: Vec<[u32; 3]> = fs.iter().map(|&f| m.faces()[f as usize].map(|v| local[v.idx()])).collect();
        out.push(Part { mesh: Mesh::from_triangles(pos, &tris)?, vertices: vs, faces: fs });
    }
    Ok((out, vlabel))
}

fn describe(side: &str, k: usize, p: &Part) -> String {
    let s = topology::summary(&p.mesh);
    format!("{side} part {k} ({} vertices, genus {}, first vertex {})", s.vertices, s.genus, p.vertices[0])
}

/// Pairs the parts when either mesh has several; `None` when both are connected (or the job
/// is not a pair job). `rows` and `boundaries` are the job's anchor and boundary rows.
///
/// # Errors
/// `InputError::Anchors` naming a part without anchors or paired twice, or an anchor out of
/// range; `TopologyMismatch` for unequal part counts.
pub fn plan(meshes: &[Mesh], rows: &[[u64; 2]], boundaries: &[[u64; 2]]) -> Result<Option<PartsPlan>> {
    let [s, t] = meshes else { return Ok(None) };
    if topology::components(s).count == 1 && topology::components(t).count == 1 {
        return Ok(None);
    }
    let rows = rows.to_vec();
    if let Some((i, r)) =
        rows.iter().enumerate().find(|(_, r)| r[0] >= s.n_vertices() as u64 || r[1] >= t.n_vertices() as u64)
    {
        return Err(InputError::Anchors(format!(
            "anchor {i}: [{}, {}] is out of range (source {} vertices, target {})",
            r[0],
            r[1],
            s.n_vertices(),
            t.n_vertices()
        ))
        .into());
    }
    let ((sp, sl), (tp, tl)) = (split(s)?, split(t)?);
    if sp.len() != tp.len() {
        return Err(InputError::TopologyMismatch(format!(
            "the source has {} parts, the target {}: parts map one to one",
            sp.len(),
            tp.len()
        ))
        .into());
    }
    let mut partner = vec![usize::MAX; sp.len()];
    let mut back = vec![usize::MAX; tp.len()];
    for r in &rows {
        let (a, b) = (sl[r[0] as usize] as usize, tl[r[1] as usize] as usize);
        if (partner[a] != usize::MAX && partner[a] != b) || (back[b] != usize::MAX && back[b] != a) {
            return Err(InputError::Anchors(format!(
                "anchors pair {} with more than one target part (or a target part with two): each part's anchors must lie on one partner",
                describe("source", a, &sp[a])
            ))
            .into());
        }
        (partner[a], back[b]) = (b, a);
    }
    if let Some(a) = partner.iter().position(|&b| b == usize::MAX) {
        return Err(InputError::Anchors(format!(
            "{} has no anchor: give each part its own anchors",
            describe("source", a, &sp[a])
        ))
        .into());
    }
    let (mut sp, mut tp): (Vec<Option<Part>>, Vec<Option<Part>>) =
        (sp.into_iter().map(Some).collect(), tp.into_iter().map(Some).collect());
    let mut pairs = Vec::with_capacity(sp.len());
    for (a, &b) in partner.iter().enumerate() {
        let (Some(ps), Some(pt)) = (sp[a].take(), tp[b].take()) else {
            return Err(crate::Error::Internal("a part paired twice".into()));
        };
        let (mut ls, mut lt) = (vec![u64::MAX; s.n_vertices()], vec![u64::MAX; t.n_vertices()]);
        ps.vertices.iter().enumerate().for_each(|(i, &v)| ls[v as usize] = i as u64);
        pt.vertices.iter().enumerate().for_each(|(i, &v)| lt[v as usize] = i as u64);
        let anchors: Vec<[u64; 2]> = rows
            .iter()
            .filter(|r| sl[r[0] as usize] as usize == a)
            .map(|r| [ls[r[0] as usize], lt[r[1] as usize]])
            .collect();
        // `boundaries` rows (open parts) in the part's own numbering.
        let mut bounds = Vec::new();
        for (i, r) in boundaries.iter().enumerate() {
            let (Some(&ps_l), Some(&pt_l)) = (sl.get(r[0] as usize), lt.get(r[1] as usize)) else { continue };
            if ps_l as usize != a {
                continue;
            }
            if pt_l == u64::MAX {
                return Err(InputError::Anchors(format!(
                    "boundaries row {i} pairs a loop of source part {a} with a loop outside its partner part"
                ))
                .into());
            }
            bounds.push([ls[r[0] as usize], pt_l]);
        }
        pairs.push(PartPair {
            meshes: [ps.mesh, pt.mesh],
            vertices: [ps.vertices, pt.vertices],
            faces: [ps.faces, pt.faces],
            anchors,
            boundaries: bounds,
        });
    }
    let part_pairs = partner.iter().enumerate().map(|(a, &b)| [a, b]).collect();
    Ok(Some(PartsPlan { pairs, part_pairs, rows }))
}
