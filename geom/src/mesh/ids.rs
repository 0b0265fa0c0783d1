//! Typed element ids. Each wraps a `u32` index; `INVALID` marks "none" in compact tables.

macro_rules! id_type {
    ($(#[$m:meta])* $name:ident) => {
        $(#[$m])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Default, serde::Serialize, serde::Deserialize)]
        #[serde(transparent)]
        pub struct $name(pub u32);

        impl $name {
            /// The "no element" marker.
            pub const INVALID: $name = $name(u32::MAX);
            /// Index into per-element arrays.
            #[inline]
            pub fn idx(self) -> usize {
                self.0 as usize
            }
            /// Id from an array index.
            #[inline]
            pub fn from_idx(i: usize) -> Self {
                $name(i as u32)
            }
            /// False for `INVALID`.
            #[inline]
            pub fn is_valid(self) -> bool {
                self.0 != u32::MAX
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}", self.0)
            }
        }
    };
}

id_type!(
    /// A vertex of a [`super::Mesh`].
    VertexId
);
id_type!(
    /// A face (triangle) of a [`super::Mesh`].
    FaceId
);
id_type!(
    /// A half-edge: `3 * face + corner`, running from corner `k` to corner `k + 1` of its face.
    HalfedgeId
);
id_type!(
    /// An undirected edge.
    EdgeId
);

impl HalfedgeId {
    /// The face this half-edge belongs to.
    #[inline]
    pub fn face(self) -> FaceId {
        FaceId(self.0 / 3)
    }
    /// The corner (0, 1, 2) of the face where this half-edge starts.
    #[inline]
    pub fn corner(self) -> usize {
        (self.0 % 3) as usize
    }
    /// Next half-edge around the same face.
    #[inline]
    pub fn next(self) -> HalfedgeId {
        let f = self.0 / 3;
        HalfedgeId(3 * f + (self.0 % 3 + 1) % 3)
    }
    /// Previous half-edge around the same face.
    #[inline]
    pub fn prev(self) -> HalfedgeId {
        let f = self.0 / 3;
        HalfedgeId(3 * f + (self.0 % 3 + 2) % 3)
    }
    /// The half-edge of face `f` that starts at corner `k`.
    #[inline]
    pub fn of(f: FaceId, k: usize) -> HalfedgeId {
        HalfedgeId(3 * f.0 + k as u32)
    }
}

/// Per-element data indexed by a typed id.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ElementData<I, T> {
    data: Vec<T>,
    _id: std::marker::PhantomData<I>,
}

/// Data per vertex.
pub type VertexData<T> = ElementData<VertexId, T>;
/// Data per face.
pub type FaceData<T> = ElementData<FaceId, T>;

impl<I, T> ElementData<I, T> {
    /// Wraps a vector (one entry per element).
    pub fn from_vec(data: Vec<T>) -> Self {
        Self { data, _id: std::marker::PhantomData }
    }
    /// `n` copies of `value`.
    pub fn filled(n: usize, value: T) -> Self
    where
        T: Clone,
    {
        Self::from_vec(vec![value; n])
    }
    /// The underlying slice, indexed by `id.idx()`.
    pub fn as_slice(&self) -> &[T] {
        &self.data
    }
    /// Mutable underlying slice.
    pub fn as_mut_slice(&mut self) -> &mut [T] {
        &mut self.data
    }
    /// Unwraps the vector.
    pub fn into_vec(self) -> Vec<T> {
        self.data
    }
    /// Number of entries.
    pub fn len(&self) -> usize {
        self.data.len()
    }
    /// True when there are no entries.
    pub fn is_empty(&self) -> bool {
        self.data.is_empty()
    }
}

macro_rules! index_impl {
    ($id:ty) => {
        impl<T> std::ops::Index<$id> for ElementData<$id, T> {
            type Output = T;
            #[inline]
            fn index(&self, i: $id) -> &T {
                &self.data[i.idx()]
            }
        }
        impl<T> std::ops::IndexMut<$id> for ElementData<$id, T> {
            #[inline]
            fn index_mut(&mut self, i: $id) -> &mut T {
                &mut self.data[i.idx()]
            }
        }
    };
}
index_impl!(VertexId);
index_impl!(FaceId);
