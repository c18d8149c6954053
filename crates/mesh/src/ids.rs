//! Typed indices, so a corner is never passed where a vertex is meant.

macro_rules! id_type {
    ($(#[$doc:meta])* $name:ident) => {
        $(#[$doc])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Default)]
        #[repr(transparent)]
        pub struct $name(pub u32);

        impl $name {
            /// The index as a `usize`, for indexing slices.
            #[inline]
            pub const fn index(self) -> usize {
                self.0 as usize
            }

            /// Builds the id from a `usize` index (which the caller keeps below `u32::MAX`).
            #[inline]
            pub const fn from_index(i: usize) -> Self {
                $name(i as u32)
            }
        }

        impl From<$name> for usize {
            #[inline]
            fn from(id: $name) -> usize {
                id.0 as usize
            }
        }

        impl std::fmt::Display for $name {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                self.0.fmt(f)
            }
        }
    };
}

id_type!(
    /// Index of a vertex in `Mesh::positions`.
    VertexId
);
id_type!(
    /// Index of a triangle in `Mesh::triangles`.
    FaceId
);
id_type!(
    /// Index of a corner: corner `c` is slot `c % 3` of triangle `c / 3`.
    CornerId
);

impl CornerId {
    /// The triangle this corner belongs to.
    #[inline]
    pub const fn face(self) -> FaceId {
        FaceId(self.0 / 3)
    }
}
