//! The triangle mesh: positions, faces, compact half-edge connectivity with typed ids,
//! per-vertex attributes, and the validated construction from raw reader output.
//!
//! Half-edges are implicit (`3 * face + corner`), so only twins, edge ids and one outgoing
//! half-edge per vertex are stored. Every `Mesh` is a manifold, consistently oriented triangle
//! mesh without unreferenced vertices, degenerate or duplicate faces, or non-finite coordinates:
//! [`Mesh::from_raw`] refuses or repairs (with a warning) anything else.

mod build;
pub mod cap;
pub mod cut;
mod cut_copy;
mod ids;
pub mod insert;
pub mod layout;
mod loops;
pub mod refine;
pub mod shapes;
mod triangulate;

pub use build::{MeshLimits, RawMesh, Warning};
pub use ids::{EdgeId, ElementData, FaceData, FaceId, HalfedgeId, VertexData, VertexId};
pub use layout::{Attributes, InputLayout, SplitMesh};
pub use loops::boundary_loops;
pub use triangulate::triangulate_polygon;

use nalgebra::{Point3, Vector3};

/// A 3D point.
pub type P3 = Point3<f64>;
/// A 3D vector.
pub type V3 = Vector3<f64>;

/// Per-vertex attributes carried by the formats. Each is present for all vertices or absent.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct VertexAttributes {
    /// Unit normals.
    pub normals: Option<Vec<V3>>,
    /// RGBA colours.
    pub colors: Option<Vec<[u8; 4]>>,
    /// Texture coordinates.
    pub uvs: Option<Vec<[f64; 2]>>,
}

impl VertexAttributes {
    /// Keeps the entries of the vertices listed in `keep`, in that order.
    pub(crate) fn select(&self, keep: &[u32]) -> Self {
        fn pick<T: Clone>(v: &Option<Vec<T>>, keep: &[u32]) -> Option<Vec<T>> {
            v.as_ref().map(|v| keep.iter().map(|&i| v[i as usize].clone()).collect())
        }
        Self { normals: pick(&self.normals, keep), colors: pick(&self.colors, keep), uvs: pick(&self.uvs, keep) }
    }
}

/// A validated manifold triangle mesh with half-edge connectivity.
#[derive(Debug, Clone)]
pub struct Mesh {
    pub(crate) positions: Vec<P3>,
    pub(crate) faces: Vec<[VertexId; 3]>,
    /// Per half-edge: the opposite half-edge, `INVALID` on the boundary.
    pub(crate) twin: Vec<HalfedgeId>,
    /// Per half-edge: its undirected edge.
    pub(crate) edge_of: Vec<EdgeId>,
    /// Per edge: one half-edge (the boundary one for boundary edges).
    pub(crate) edge_he: Vec<HalfedgeId>,
    /// Per vertex: an outgoing half-edge; for boundary vertices the one without a twin.
    pub(crate) vertex_he: Vec<HalfedgeId>,
    pub(crate) attributes: VertexAttributes,
}

impl Mesh {
    /// Number of vertices.
    pub fn n_vertices(&self) -> usize {
        self.positions.len()
    }
    /// Number of faces.
    pub fn n_faces(&self) -> usize {
        self.faces.len()
    }
    /// Number of undirected edges.
    pub fn n_edges(&self) -> usize {
        self.edge_he.len()
    }
    /// Number of half-edges (`3 * faces`).
    pub fn n_halfedges(&self) -> usize {
        self.twin.len()
    }
    /// All positions, indexed by vertex.
    pub fn positions(&self) -> &[P3] {
        &self.positions
    }
    /// All faces, indexed by face.
    pub fn faces(&self) -> &[[VertexId; 3]] {
        &self.faces
    }
    /// Faces as plain `u32` triples.
    pub fn face_indices(&self) -> Vec<[u32; 3]> {
        self.faces.iter().map(|f| [f[0].0, f[1].0, f[2].0]).collect()
    }
    /// Position of a vertex.
    #[inline]
    pub fn position(&self, v: VertexId) -> P3 {
        self.positions[v.idx()]
    }
    /// The three vertices of a face.
    #[inline]
    pub fn face(&self, f: FaceId) -> [VertexId; 3] {
        self.faces[f.idx()]
    }
    /// The three corner positions of a face.
    #[inline]
    pub fn face_points(&self, f: FaceId) -> [P3; 3] {
        let [a, b, c] = self.faces[f.idx()];
        [self.positions[a.idx()], self.positions[b.idx()], self.positions[c.idx()]]
    }
    /// Per-vertex attributes.
    pub fn attributes(&self) -> &VertexAttributes {
        &self.attributes
    }
    /// Replaces the positions (same count), keeping connectivity. Attributes are kept.
    ///
    /// # Errors
    /// `InputError::Invalid` on a count mismatch, `NonFiniteCoordinate` on NaN/inf.
    pub fn with_positions(&self, positions: Vec<P3>) -> crate::Result<Mesh> {
        if positions.len() != self.positions.len() {
            return Err(crate::InputError::Invalid(format!(
                "expected {} positions, got {}",
                self.positions.len(),
                positions.len()
            ))
            .into());
        }
        check_finite(&positions)?;
        let mut m = self.clone();
        m.positions = positions;
        Ok(m)
    }

    /// Tail vertex of a half-edge.
    #[inline]
    pub fn tail(&self, h: HalfedgeId) -> VertexId {
        self.faces[h.face().idx()][h.corner()]
    }
    /// Head vertex of a half-edge.
    #[inline]
    pub fn head(&self, h: HalfedgeId) -> VertexId {
        self.faces[h.face().idx()][(h.corner() + 1) % 3]
    }
    /// Opposite half-edge, `None` on the boundary.
    #[inline]
    pub fn twin(&self, h: HalfedgeId) -> Option<HalfedgeId> {
        let t = self.twin[h.idx()];
        t.is_valid().then_some(t)
    }
    /// Undirected edge of a half-edge.
    #[inline]
    pub fn edge(&self, h: HalfedgeId) -> EdgeId {
        self.edge_of[h.idx()]
    }
    /// A half-edge of an edge (the boundary one if the edge is on the boundary).
    #[inline]
    pub fn edge_halfedge(&self, e: EdgeId) -> HalfedgeId {
        self.edge_he[e.idx()]
    }
    /// The two endpoints of an edge.
    #[inline]
    pub fn edge_vertices(&self, e: EdgeId) -> [VertexId; 2] {
        let h = self.edge_he[e.idx()];
        [self.tail(h), self.head(h)]
    }
    /// Length of an edge.
    pub fn edge_length(&self, e: EdgeId) -> f64 {
        let [a, b] = self.edge_vertices(e);
        (self.position(a) - self.position(b)).norm()
    }
    /// True when the half-edge has no twin.
    #[inline]
    pub fn is_boundary_halfedge(&self, h: HalfedgeId) -> bool {
        !self.twin[h.idx()].is_valid()
    }
    /// True when the edge has one face.
    #[inline]
    pub fn is_boundary_edge(&self, e: EdgeId) -> bool {
        self.is_boundary_halfedge(self.edge_he[e.idx()])
    }
    /// True when the vertex lies on the boundary.
    #[inline]
    pub fn is_boundary_vertex(&self, v: VertexId) -> bool {
        self.is_boundary_halfedge(self.vertex_he[v.idx()])
    }
    /// Faces on either side of an edge (second is `None` on the boundary).
    pub fn edge_faces(&self, e: EdgeId) -> (FaceId, Option<FaceId>) {
        let h = self.edge_he[e.idx()];
        (h.face(), self.twin(h).map(|t| t.face()))
    }

    /// Outgoing half-edges of `v`, counter-clockwise; for a boundary vertex the first one is on
    /// the boundary and the walk covers the whole fan.
    pub fn outgoing(&self, v: VertexId) -> Outgoing<'_> {
        let start = self.vertex_he[v.idx()];
        Outgoing { mesh: self, start, cur: Some(start) }
    }
    /// Neighbouring vertices of `v`, counter-clockwise. A boundary vertex also yields the
    /// tail of its incoming boundary half-edge, last.
    pub fn vertex_neighbors(&self, v: VertexId) -> impl Iterator<Item = VertexId> + '_ {
        let last = {
            // For a boundary vertex the last outgoing half-edge's face has one more neighbour:
            // the tail of prev(last outgoing).
            let mut last = None;
            if self.is_boundary_vertex(v) {
                let mut h = self.vertex_he[v.idx()];
                while let Some(t) = self.twin(h.prev()) {
                    h = t;
                }
                last = Some(self.tail(h.prev()));
            }
            last
        };
        self.outgoing(v).map(|h| self.head(h)).chain(last)
    }
    /// Faces around `v`.
    pub fn vertex_faces(&self, v: VertexId) -> impl Iterator<Item = FaceId> + '_ {
        self.outgoing(v).map(|h| h.face())
    }
    /// The (up to three) faces adjacent to `f` across its edges.
    pub fn face_neighbors(&self, f: FaceId) -> impl Iterator<Item = FaceId> + '_ {
        (0..3).filter_map(move |k| self.twin(HalfedgeId::of(f, k)).map(|t| t.face()))
    }

    /// Unnormalised face normal (twice the area, along the normal).
    #[inline]
    pub fn face_normal_raw(&self, f: FaceId) -> V3 {
        let [a, b, c] = self.face_points(f);
        (b - a).cross(&(c - a))
    }
    /// Face area.
    #[inline]
    pub fn face_area(&self, f: FaceId) -> f64 {
        0.5 * self.face_normal_raw(f).norm()
    }
    /// Total surface area.
    pub fn area(&self) -> f64 {
        (0..self.n_faces()).map(|f| self.face_area(FaceId::from_idx(f))).sum()
    }
    /// Axis-aligned bounding box (min, max).
    pub fn bbox(&self) -> (P3, P3) {
        let mut lo = P3::new(f64::INFINITY, f64::INFINITY, f64::INFINITY);
        let mut hi = P3::new(f64::NEG_INFINITY, f64::NEG_INFINITY, f64::NEG_INFINITY);
        for p in &self.positions {
            lo = lo.inf(p);
            hi = hi.sup(p);
        }
        (lo, hi)
    }
    /// Length of the bounding-box diagonal.
    pub fn bbox_diagonal(&self) -> f64 {
        let (lo, hi) = self.bbox();
        (hi - lo).norm()
    }
    /// Mean edge length.
    pub fn mean_edge_length(&self) -> f64 {
        if self.n_edges() == 0 {
            return 0.0;
        }
        (0..self.n_edges()).map(|e| self.edge_length(EdgeId::from_idx(e))).sum::<f64>() / self.n_edges() as f64
    }
    /// The half-edge from `a` to `b`, if any.
    pub fn find_halfedge(&self, a: VertexId, b: VertexId) -> Option<HalfedgeId> {
        self.outgoing(a).find(|&h| self.head(h) == b)
    }
}

/// Iterator over the outgoing half-edges of a vertex.
pub struct Outgoing<'a> {
    mesh: &'a Mesh,
    start: HalfedgeId,
    cur: Option<HalfedgeId>,
}

impl Iterator for Outgoing<'_> {
    type Item = HalfedgeId;
    fn next(&mut self) -> Option<HalfedgeId> {
        let h = self.cur?;
        self.cur = self.mesh.twin(h.prev()).filter(|&n| n != self.start);
        Some(h)
    }
}

fn check_finite(positions: &[P3]) -> crate::Result<()> {
    for (i, p) in positions.iter().enumerate() {
        for &c in p.coords.iter() {
            if !c.is_finite() {
                return Err(crate::InputError::NonFiniteCoordinate { vertex: i, value: c }.into());
            }
        }
    }
    Ok(())
}
