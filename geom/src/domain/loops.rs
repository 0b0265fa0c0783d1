//! Fixed layout paths for boundary loops closed by cones ([`crate::mesh::cap`]): every loop
//! is cut by its anchors into segments that run along the loop's own edges, and the cone's apex
//! is joined to each of them by its fan edge. Given to both meshes' tracers before any other
//! path ([`super::tracer::Tracer::fix`]), with the cone's faces closed to every later path,
//! they make the loop a union of layout paths and each cone sector a patch: every layout (and
//! so every map built from it) takes the loop onto the loop and the cone onto the cone.

use super::LayoutPath;
use crate::error::{Error, Result};
use crate::geodesic::{EdgeNodeGraph, NodeId};
use crate::mesh::VertexId;

/// The anchors of one closed loop: the apex and the loop's anchors in loop order (indices
/// into the tracer's anchor list), with the loop's vertices in order.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopAnchors {
    pub apex: u32,
    pub anchors: Vec<u32>,
    pub vertices: Vec<VertexId>,
}

/// Nodes from vertex `u` to its neighbour `w` along their edge, `u` included, `w` not.
fn along(g: &EdgeNodeGraph, u: VertexId, w: VertexId, out: &mut Vec<NodeId>) -> Result<()> {
    let m = g.mesh();
    let h = m
        .find_halfedge(u, w)
        .or_else(|| m.find_halfedge(w, u))
        .ok_or_else(|| Error::Internal(format!("loop vertices {} and {} share no edge", u.0, w.0)))?;
    let e = m.edge(h);
    let c = g.edge_node_count(e);
    out.push(g.vertex_node(u));
    let forward = m.tail(m.edge_halfedge(e)) == u;
    for i in 0..c {
        out.push(g.edge_node(e, if forward { i } else { c - 1 - i }));
    }
    Ok(())
}

fn path(g: &EdgeNodeGraph, a: u32, b: u32, nodes: Vec<NodeId>) -> LayoutPath {
    let m = g.mesh();
    let points: Vec<_> = nodes.iter().map(|&n| g.surface_point(n)).collect();
    let length = points.windows(2).map(|w| (w[1].position(m) - w[0].position(m)).norm()).sum();
    LayoutPath { a, b, nodes, points, length }
}

/// The fixed paths of every loop: its segments between consecutive anchors, then its spokes
/// (apex to each anchor).
///
/// # Errors
/// `Error::Internal` when an anchor is not on its loop or the loop is not a chain of edges.
pub fn loop_paths(g: &EdgeNodeGraph, anchors: &[VertexId], loops: &[LoopAnchors]) -> Result<Vec<LayoutPath>> {
    let mut out = Vec::new();
    for l in loops {
        let n = l.vertices.len();
        let pos: Vec<usize> = l
            .anchors
            .iter()
            .map(|&a| {
                l.vertices
                    .iter()
                    .position(|&v| v == anchors[a as usize])
                    .ok_or_else(|| Error::Internal(format!("anchor {a} is not on its boundary loop")))
            })
            .collect::<Result<_>>()?;
        let k = pos.len();
        for i in 0..k {
            let (from, to) = (pos[i], pos[(i + 1) % k]);
            let steps = (to + n - from) % n;
            let steps = if steps == 0 { n } else { steps };
            let mut nodes = Vec::new();
            for s in 0..steps {
                along(g, l.vertices[(from + s) % n], l.vertices[(from + s + 1) % n], &mut nodes)?;
            }
            nodes.push(g.vertex_node(l.vertices[to]));
            out.push(path(g, l.anchors[i], l.anchors[(i + 1) % k], nodes));
        }
        for &a in &l.anchors {
            let mut nodes = Vec::new();
            along(g, anchors[l.apex as usize], anchors[a as usize], &mut nodes)?;
            nodes.push(g.vertex_node(anchors[a as usize]));
            out.push(path(g, l.apex, a, nodes));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::domain::straighten::straighten;
    use crate::domain::tracer::{TraceRequest, Tracer};
    use crate::mesh::cap::cap_loops;
    use crate::mesh::shapes;
    use crate::progress::NoProgress;

    /// A holed icosphere closed by a cone, its loop cut by three anchors: the fixed paths run
    /// along the loop and the spokes, survive straightening and a fresh tracer, and no traced
    /// path enters the cone.
    #[test]
    fn fixed_loop_paths_stay_and_close_the_cone() {
        let open = shapes::icosphere_with_holes(3, &[0]);
        let c = cap_loops(&open).unwrap();
        let lp = &c.loops[0];
        let n = lp.vertices.len();
        let far = VertexId::from_idx(200);
        let anchors = vec![lp.vertices[0], lp.vertices[n / 3], lp.vertices[2 * n / 3], far, lp.apex];
        let la = LoopAnchors { apex: 4, anchors: vec![0, 1, 2], vertices: lp.vertices.clone() };
        let mut t = Tracer::new(&c.mesh, &anchors, &Default::default()).unwrap();
        let paths = loop_paths(t.graph(), t.anchors(), std::slice::from_ref(&la)).unwrap();
        assert_eq!(paths.len(), 6, "three segments and three spokes");
        t.fix(paths.clone(), &c.cap_faces()).unwrap();
        assert_eq!(t.n_fixed(), 6);
        assert!(t.is_enclosed(4) && !t.is_enclosed(3));
        assert!(t.linked_by_fixed(0, 1) && t.linked_by_fixed(4, 2) && !t.linked_by_fixed(0, 3));
        // The apex is out of reach of every traced path.
        assert!(t.trace(&TraceRequest { a: 3, b: 4, ..Default::default() }).unwrap().is_none());
        let p = t.trace_insert(&TraceRequest { a: 3, b: 0, ..Default::default() }).unwrap().unwrap();
        for w in t.paths()[p as usize].nodes.windows(2) {
            if let Some((f, _, _)) = t.arc_face(w[0], w[1]) {
                assert!(!c.is_cap_face(f), "a traced path crossed the cone");
            }
        }
        straighten(&mut t, 3, &mut NoProgress).unwrap();
        assert_eq!(&t.paths()[..6], &paths[..], "straightening leaves fixed paths alone");
        let fresh = t.fresh().unwrap();
        assert_eq!(fresh.paths(), &paths[..], "a fresh tracer holds the fixed paths only");
    }
}
