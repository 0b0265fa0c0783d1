//! Links read off the refined mesh instead of chosen by distance. Inside one original face
//! the layout's paths are chords between the face's refined pieces, and the pieces' patches
//! change exactly where a chord is crossed. Walking from piece to piece and composing the
//! transition of each path crossed gives every corner of the face a map into one chart (the
//! face's *developing map*), and the link of an edge is the quotient of its two ends' maps.
//! The links of a face then compose to the identity around it by construction; links chosen
//! by distance do not where a face lies next to a cone point (cow, 24 anchors: about sixty
//! faces with a turn around them, which fold in the global map).

use super::charts::{Affine, Charts};
use super::solve::{Rows, State};
use crate::domain::Patch;
use crate::domain::refine::Refined;
use crate::mesh::{FaceId, HalfedgeId, Mesh, VertexId};
use std::collections::HashMap;

/// Per slot of `rows`: the link of that ordered pair from the faces of `r` (the refinement of
/// `mesh` along the layout), or `None` where the refinement cannot say (the caller chooses
/// those by distance, [`State::fill_links`]).
pub fn from_refinement(
    mesh: &Mesh,
    r: &Refined,
    patches: &[Patch],
    charts: &Charts,
    st: &State,
    rows: &Rows,
) -> Vec<Option<Affine>> {
    let dbg = tracing::enabled!(tracing::Level::DEBUG);
    // Which path each refined edge runs on.
    let mut on_path: HashMap<(u32, u32), u32> = HashMap::new();
    for (p, vs) in r.path_vertices.iter().enumerate() {
        for w in vs.windows(2) {
            on_path.insert((w[0].0.min(w[1].0), w[0].0.max(w[1].0)), p as u32);
        }
    }
    // The path each non-anchor refined path vertex lies on.
    let mut on_vertex: HashMap<u32, u32> = HashMap::new();
    for (p, vs) in r.path_vertices.iter().enumerate() {
        for v in vs.iter().skip(1).take(vs.len().saturating_sub(2)) {
            on_vertex.insert(v.0, p as u32);
        }
    }
    let mut children: Vec<Vec<u32>> = vec![Vec::new(); mesh.n_faces()];
    for (rf, parent) in r.parent.iter().enumerate() {
        if let Some(c) = children.get_mut(parent.idx()) {
            c.push(rf as u32);
        }
    }
    // Per original face and corner: the map of that corner's chart into the face's chart.
    let develop = |f: usize| -> Option<[Affine; 3]> {
        let kids = &children[f];
        let root = *kids.first()?;
        let mut map: HashMap<u32, Affine> = HashMap::with_capacity(kids.len());
        map.insert(root, Affine::IDENTITY);
        let mut stack = vec![root];
        while let Some(c) = stack.pop() {
            let a = map[&c];
            let pc = r.patch[c as usize];
            for k in 0..3 {
                let h = HalfedgeId::of(FaceId(c), k);
                let Some(t) = r.mesh.twin(h) else { continue };
                let d = t.face().0;
                if r.parent[d as usize].idx() != f || map.contains_key(&d) {
                    continue;
                }
                let pd = r.patch[d as usize];
                let step = if pd == pc {
                    Affine::IDENTITY
                } else {
                    let (u, w) = (r.mesh.tail(h).0, r.mesh.head(h).0);
                    let Some(&path) = on_path.get(&(u.min(w), u.max(w))) else {
                        if dbg {
                            tracing::debug!("links: face {f}: edge {u}-{w} between patches {pc} {pd} on no path");
                        }
                        return None;
                    };
                    let Some(side) = (0..3)
                        .find(|&s| patches[pc as usize].sides[s] / 2 == path && charts.across[pc as usize][s].0 == pd)
                    else {
                        if dbg {
                            tracing::debug!(
                                "links: face {f}: path {path} is no side of {pc} towards {pd}: {:?}",
                                patches[pc as usize]
                            );
                        }
                        return None;
                    };
                    charts.across[pc as usize][side].1
                };
                map.insert(d, a.after(&step));
                stack.push(d);
            }
        }
        let tri = mesh.face(FaceId::from_idx(f));
        let mut out = [Affine::IDENTITY; 3];
        for (k, v) in tri.iter().enumerate() {
            // A piece with this corner: its patch is the vertex's own (or, at an anchor, one
            // of the patches around it).
            let mut touching = kids.iter().filter(|&&c| r.mesh.face(FaceId(c)).contains(v));
            let c = *touching.clone().find(|&&c| r.patch[c as usize] == st.patch[v.idx()]).or(touching.next())?;
            let pc = r.patch[c as usize];
            out[k] = match st.anchor[v.idx()] {
                u32::MAX if st.patch[v.idx()] == pc => map[&c],
                u32::MAX => {
                    // The vertex lies on a path between its own patch and this piece's: the
                    // transition across that path holds it in place.
                    let path = on_vertex.get(&v.0);
                    let side = (0..3).find(|&s| {
                        charts.across[pc as usize][s].0 == st.patch[v.idx()]
                            && path.is_none_or(|&p| patches[pc as usize].sides[s] / 2 == p)
                    });
                    let Some(side) = side else {
                        if dbg {
                            tracing::debug!(
                                "links: face {f}: vertex {} in patch {} but its piece is in {pc}",
                                v.0,
                                st.patch[v.idx()]
                            );
                        }
                        return None;
                    };
                    map[&c].after(&charts.across[pc as usize][side].1)
                }
                a => map[&c].after(&charts.anchor_link(a, pc, [0.0, 0.0])?),
            };
        }
        Some(out)
    };
    let mut links = vec![None; rows.nbr.len()];
    let mut cache: HashMap<usize, Option<[Affine; 3]>> = HashMap::new();
    for i in 0..mesh.n_vertices() {
        let (a, b) = (rows.start[i], rows.start[i + 1]);
        for (link, &(j, _)) in links[a..b].iter_mut().zip(&rows.nbr[a..b]) {
            let Some(h) = mesh.find_halfedge(VertexId::from_idx(i), VertexId(j)) else { continue };
            let f = h.face().idx();
            let Some(dev) = *cache.entry(f).or_insert_with(|| develop(f)) else { continue };
            let tri = mesh.face(h.face());
            let (Some(ki), Some(kj)) = (tri.iter().position(|v| v.idx() == i), tri.iter().position(|v| v.0 == j))
            else {
                continue;
            };
            *link = Some(dev[ki].inverse().after(&dev[kj]));
        }
    }
    links
}
