//! Z2 cohomology by tree–cotree (Eppstein 2003; Erickson & Whittlesey 2005): a spanning tree
//! `T` of the vertices, a spanning tree `C` of the dual graph avoiding `T`, and the `2g` edges in
//! neither. Each leftover edge gets a closed cocycle (zero on `T`, one on itself, fixed on `C`
//! by peeling the cotree from its leaves), so a closed edge path is non-separating exactly when
//! the XOR of its edges' masks is non-zero.
//!
//! A surface with one boundary loop is treated as closed by capping the loop with one face
//! (the cap is the cotree's root); a loop in the surface separates it exactly when it separates
//! the capped surface.

use crate::error::{Error, Result};
use crate::mesh::{EdgeId, Mesh, VertexId};
use crate::topology::boundary_loops;
use std::collections::VecDeque;

/// Cocycle masks per edge (bit `k`: the `k`-th leftover edge's cocycle).
#[derive(Debug, Clone)]
pub struct Cohomology {
    pub mask: Vec<u64>,
    /// Number of leftover edges (`2g` of the capped surface).
    pub rank: usize,
}

/// Builds the cohomology masks. `tree_parent[v]` is the parent edge of `v` in a tree that
/// must contain every edge given (others are added to span all vertices).
///
/// # Errors
/// `InvalidInput`-free: `Internal` when the surface has more than 64 generators or more than one
/// boundary loop.
pub fn z2_cohomology(mesh: &Mesh, tree_edges: &[EdgeId]) -> Result<Cohomology> {
    let tc = tree_cotree(mesh, tree_edges)?;
    let ne = mesh.n_edges();
    let mut mask = vec![0u64; ne];
    let mut rank = 0;
    for (e, m) in mask.iter_mut().enumerate() {
        if !tc.in_tree[e] && !tc.in_cotree[e] {
            if rank >= 64 {
                return Err(Error::Internal("cohomology: more than 64 generators".into()));
            }
            *m = 1 << rank;
            rank += 1;
        }
    }
    for &u in tc.order.iter().rev() {
        if u == tc.root {
            continue;
        }
        let pe = tc.parent_edge[u] as usize;
        let m = tc.node_edges(mesh, u).iter().filter(|e| e.idx() != pe).fold(0u64, |acc, e| acc ^ mask[e.idx()]);
        mask[pe] = m;
    }
    Ok(Cohomology { mask, rank })
}

/// Integer cocycles, one per leftover edge, on a closed surface: `value(e, k)` is cocycle `k` on
/// edge `e` oriented from its first vertex to its second ([`Mesh::edge_vertices`]). They sum to
/// zero around every face and form a basis of H¹(M; Z), so the class of a closed edge path in
/// H1(M; Z) has coordinates `Σ ω_k(step)` (exactly what [`IntCohomology::class_of`] sums).
#[derive(Debug, Clone)]
pub struct IntCohomology {
    pub rank: usize,
    values: Vec<i32>,
}

impl IntCohomology {
    pub fn value(&self, e: EdgeId, k: usize) -> i32 {
        self.values[e.idx() * self.rank + k]
    }

    /// Coordinates of the closed path `steps` (consecutive vertices joined by edges; repeated
    /// vertices are steps of length zero).
    pub fn class_of(&self, mesh: &Mesh, steps: &[VertexId]) -> Option<Vec<i64>> {
        let mut c = vec![0i64; self.rank];
        for w in steps.windows(2) {
            if w[0] == w[1] {
                continue;
            }
            let e = crate::mesh::cut::edge_between(mesh, w[0], w[1])?;
            let sign = if mesh.edge_vertices(e)[0] == w[0] { 1 } else { -1 };
            for (k, ck) in c.iter_mut().enumerate() {
                *ck += i64::from(sign * self.value(e, k));
            }
        }
        Some(c)
    }
}

/// The integer cocycles of a closed mesh (tree–cotree, as [`z2_cohomology`], with signs).
///
/// # Errors
/// `Internal` for a mesh with boundary.
pub fn integer_cohomology(mesh: &Mesh) -> Result<IntCohomology> {
    if !boundary_loops(mesh).is_empty() {
        return Err(Error::Internal("integer cohomology: the mesh has a boundary".into()));
    }
    let tc = tree_cotree(mesh, &[])?;
    let ne = mesh.n_edges();
    let gens: Vec<usize> = (0..ne).filter(|&e| !tc.in_tree[e] && !tc.in_cotree[e]).collect();
    let rank = gens.len();
    let mut values = vec![0i32; ne * rank];
    for (k, &e) in gens.iter().enumerate() {
        values[e * rank + k] = 1;
    }
    // Face u: the sum over its half-edges (signed against each edge's own direction) is zero;
    // peeling the cotree from its leaves fixes the parent edge's value.
    for &u in tc.order.iter().rev() {
        if u == tc.root {
            continue;
        }
        let pe = tc.parent_edge[u] as usize;
        let f = crate::mesh::FaceId::from_idx(u);
        let mut sum = vec![0i32; rank];
        let mut pe_sign = 0;
        for k in 0..3 {
            let h = crate::mesh::HalfedgeId::of(f, k);
            let e = mesh.edge(h);
            let sign = if mesh.edge_vertices(e)[0] == mesh.tail(h) { 1 } else { -1 };
            if e.idx() == pe {
                pe_sign = sign;
                continue;
            }
            for (j, s) in sum.iter_mut().enumerate() {
                *s += sign * values[e.idx() * rank + j];
            }
        }
        for (j, s) in sum.iter().enumerate() {
            values[pe * rank + j] = -pe_sign * s;
        }
    }
    Ok(IntCohomology { rank, values })
}

/// A spanning tree of the vertices and one of the dual graph that avoids it.
struct TreeCotree {
    in_tree: Vec<bool>,
    in_cotree: Vec<bool>,
    /// Dual nodes in BFS order from the root.
    order: Vec<usize>,
    parent_edge: Vec<u32>,
    root: usize,
    cap_edges: Vec<EdgeId>,
    nf: usize,
}

impl TreeCotree {
    /// The edges around dual node `u` (a face, or the cap).
    fn node_edges(&self, mesh: &Mesh, u: usize) -> Vec<EdgeId> {
        dual_node_edges(mesh, self.nf, &self.cap_edges, u)
    }
}

/// The edges around dual node `u`: face `u`, or the cap (node `nf`, bounded by `cap_edges`).
fn dual_node_edges(mesh: &Mesh, nf: usize, cap_edges: &[EdgeId], u: usize) -> Vec<EdgeId> {
    if u == nf {
        cap_edges.to_vec()
    } else {
        (0..3).map(|k| mesh.edge(crate::mesh::HalfedgeId::of(crate::mesh::FaceId::from_idx(u), k))).collect()
    }
}

/// Builds the tree (containing every edge given, then spanning all vertices) and the cotree.
///
/// # Errors
/// `Internal` when the surface has more than one boundary loop.
fn tree_cotree(mesh: &Mesh, tree_edges: &[EdgeId]) -> Result<TreeCotree> {
    let (nv, ne, nf) = (mesh.n_vertices(), mesh.n_edges(), mesh.n_faces());
    let loops = boundary_loops(mesh);
    if loops.len() > 1 {
        return Err(Error::Internal("cohomology: more than one boundary loop".into()));
    }
    // Spanning tree: the given edges, then a BFS over all edges from every covered vertex.
    let mut in_tree = vec![false; ne];
    let mut covered = vec![false; nv];
    let mut uf = UnionFind::new(nv);
    for &e in tree_edges {
        let [a, b] = mesh.edge_vertices(e);
        if uf.union(a.idx(), b.idx()) {
            in_tree[e.idx()] = true;
        }
        covered[a.idx()] = true;
        covered[b.idx()] = true;
    }
    let mut queue: VecDeque<VertexId> = (0..nv).filter(|&v| covered[v]).map(VertexId::from_idx).collect();
    if queue.is_empty() && nv > 0 {
        covered[0] = true;
        queue.push_back(VertexId(0));
    }
    while let Some(v) = queue.pop_front() {
        for h in mesh.outgoing(v).collect::<Vec<_>>() {
            for (x, e) in [(mesh.head(h), mesh.edge(h)), (mesh.tail(h.prev()), mesh.edge(h.prev()))] {
                if !covered[x.idx()] && uf.union(v.idx(), x.idx()) {
                    covered[x.idx()] = true;
                    in_tree[e.idx()] = true;
                    queue.push_back(x);
                }
            }
        }
    }
    // Dual graph: faces plus the cap (index nf) when there is a boundary.
    let cap = if loops.is_empty() { None } else { Some(nf) };
    let root = cap.unwrap_or(0);
    let n_dual = nf + usize::from(cap.is_some());
    let dual_ends = |e: EdgeId| -> (usize, usize) {
        let (f0, f1) = mesh.edge_faces(e);
        (f0.idx(), f1.map_or(nf, |f| f.idx()))
    };
    let mut parent_edge = vec![u32::MAX; n_dual];
    let mut seen = vec![false; n_dual];
    let mut order = Vec::with_capacity(n_dual);
    let mut in_cotree = vec![false; ne];
    seen[root] = true;
    let mut dq = VecDeque::from([root]);
    let cap_edges: Vec<EdgeId> = loops.first().map(|l| l.iter().map(|&h| mesh.edge(h)).collect()).unwrap_or_default();
    while let Some(u) = dq.pop_front() {
        order.push(u);
        for e in dual_node_edges(mesh, nf, &cap_edges, u) {
            if in_tree[e.idx()] {
                continue;
            }
            let (a, b) = dual_ends(e);
            let w = if a == u { b } else { a };
            if !seen[w] {
                seen[w] = true;
                parent_edge[w] = e.0;
                in_cotree[e.idx()] = true;
                dq.push_back(w);
            }
        }
    }
    Ok(TreeCotree { in_tree, in_cotree, order, parent_edge, root, cap_edges, nf })
}

struct UnionFind(Vec<u32>);
impl UnionFind {
    fn new(n: usize) -> Self {
        UnionFind((0..n as u32).collect())
    }
    fn find(&mut self, mut x: usize) -> usize {
        while self.0[x] as usize != x {
            let p = self.0[x] as usize;
            self.0[x] = self.0[p];
            x = p;
        }
        x
    }
    fn union(&mut self, a: usize, b: usize) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.0[ra] = rb as u32;
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::shapes;

    fn mask_of(m: &Mesh, c: &Cohomology, path: &[u32]) -> u64 {
        path.windows(2)
            .map(|w| crate::mesh::cut::edge_between(m, VertexId(w[0]), VertexId(w[1])).unwrap())
            .fold(0, |acc, e| acc ^ c.mask[e.idx()])
    }

    #[test]
    fn torus_has_two_generators_and_separates_correctly() {
        // torus(n, m): vertex i*m + j, i around the big circle, j around the tube.
        let (n, m) = (12usize, 6usize);
        let t = shapes::torus(n, m, 1.0, 0.3);
        let c = z2_cohomology(&t, &[]).unwrap();
        assert_eq!(c.rank, 2);
        let tube: Vec<u32> = (0..=m).map(|j| (j % m) as u32).collect();
        let ring: Vec<u32> = (0..=n).map(|i| ((i % n) * m) as u32).collect();
        assert_ne!(mask_of(&t, &c, &tube), 0, "a meridian does not separate");
        assert_ne!(mask_of(&t, &c, &ring), 0, "a longitude does not separate");
        assert_ne!(mask_of(&t, &c, &tube), mask_of(&t, &c, &ring), "different classes");
        // The boundary of one face separates (bounds that face).
        let f = t.face(crate::mesh::FaceId(0)).map(|v| v.0);
        assert_eq!(mask_of(&t, &c, &[f[0], f[1], f[2], f[0]]), 0);
    }

    #[test]
    fn integer_classes_of_a_torus() {
        let (n, m) = (12usize, 6usize);
        let t = shapes::torus(n, m, 1.0, 0.3);
        let c = integer_cohomology(&t).unwrap();
        assert_eq!(c.rank, 2);
        let path = |p: &[u32]| p.iter().map(|&v| VertexId(v)).collect::<Vec<_>>();
        let tube: Vec<u32> = (0..=m).map(|j| (j % m) as u32).collect();
        let ring: Vec<u32> = (0..=n).map(|i| ((i % n) * m) as u32).collect();
        let (a, b) = (c.class_of(&t, &path(&tube)).unwrap(), c.class_of(&t, &path(&ring)).unwrap());
        // Independent over Z (a unimodular pair), reversal negates, twice is twice.
        assert_eq!((a[0] * b[1] - a[1] * b[0]).abs(), 1, "{a:?} {b:?}");
        let back: Vec<u32> = tube.iter().rev().copied().collect();
        assert_eq!(c.class_of(&t, &path(&back)).unwrap(), a.iter().map(|x| -x).collect::<Vec<_>>());
        let twice: Vec<u32> = tube.iter().chain(&tube[1..]).copied().collect();
        assert_eq!(c.class_of(&t, &path(&twice)).unwrap(), a.iter().map(|x| 2 * x).collect::<Vec<_>>());
        // Every face boundary is null-homologous.
        for f in t.faces() {
            let f = f.map(|v| v.0);
            assert_eq!(c.class_of(&t, &path(&[f[0], f[1], f[2], f[0]])).unwrap(), vec![0, 0]);
        }
    }

    #[test]
    fn more_than_one_boundary_loop_is_refused() {
        let t = shapes::torus(12, 6, 1.0, 0.3);
        let tube: Vec<VertexId> = (0..=6).map(|j| VertexId((j % 6) as u32)).collect();
        let cut = crate::mesh::cut::cut_along(&t, &crate::mesh::cut::path_edges(&t, &[tube]).unwrap()).unwrap();
        // An annulus: two boundary loops (the capped version is refused: more than one loop).
        assert_eq!(boundary_loops(&cut.mesh).len(), 2);
        assert!(z2_cohomology(&cut.mesh, &[]).is_err());
    }
}
