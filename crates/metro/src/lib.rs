//! whet-metro owns whet's error measure: the Metro distance between two triangle surfaces
//! (Cignoni, Rocchini & Scopigno 1998) as max (Hausdorff), mean and RMS, one-sided and
//! symmetric, absolute and in percent of the reference bounding-box diagonal, computed from
//! deterministic vertex, edge and area-uniform face samples ([`metro`], [`one_sided`]); the
//! [`Bvh`] with exact point-triangle distance ([`closest_point_on_triangle`]) that answers its
//! closest-point queries and that other crates reuse; and per-vertex errors with a colour ramp
//! for export ([`vertex_distances`], [`error_ramp`]). It depends only on whet-mesh.
//!
//! ```
//! use whet_metro::{metro, MetroOptions};
//! use whet_mesh::{DVec3, Mesh};
//!
//! // A unit square (two triangles) and the same square lifted by 0.01.
//! let square = |z: f64| {
//!     Mesh::new(
//!         vec![
//!             DVec3::new(0.0, 0.0, z),
//!             DVec3::new(1.0, 0.0, z),
//!             DVec3::new(1.0, 1.0, z),
//!             DVec3::new(0.0, 1.0, z),
//!         ],
//!         vec![[0, 1, 2], [0, 2, 3]],
//!     )
//! };
//! let (reference, test) = (square(0.0), square(0.01));
//! let report = metro(&reference, &test, &MetroOptions::DEFAULT.with_samples(10_000)).unwrap();
//! assert!((report.symmetric.max - 0.01).abs() < 1e-12);
//! assert!((report.symmetric.rms - 0.01).abs() < 1e-12);
//! // In percent of the reference diagonal (sqrt 2).
//! assert!((report.symmetric.max_pct - 1.0 / 2f64.sqrt()).abs() < 1e-9);
//! assert!(report.to_json().starts_with("{\"max\":"));
//! ```
#![forbid(unsafe_code)]

mod bvh;
mod metro;
pub mod sampling;
mod triangle_distance;

pub use bvh::{Bvh, ClosestPoint, CoherentQuery};
pub use metro::{
    error_ramp, metro, one_sided, vertex_distances, Directional, Figures, MetroOptions,
    MetroReport, MAX_FACE_SAMPLES,
};
pub use triangle_distance::{
    closest_point_on_segment, closest_point_on_triangle, point_triangle_distance_squared,
};

/// Why a Metro measurement could not be made.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// A mesh without triangles has no surface to sample or measure against.
    #[error("the {which} mesh has no triangles: the Metro distance needs a surface on both sides")]
    NoTriangles {
        /// Which mesh: "reference", "test", "sampled" or "target".
        which: &'static str,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error(
        "the {which} mesh is invalid: triangle {triangle} refers to vertex {index}, \
         but the mesh has only {vertex_count} vertices"
    )]
    IndexOutOfRange {
        /// Which mesh.
        which: &'static str,
        /// The triangle.
        triangle: usize,
        /// The out-of-range vertex index.
        index: u32,
        /// Number of vertices of the mesh.
        vertex_count: usize,
    },
    /// A vertex position is NaN or infinite.
    #[error("the {which} mesh is invalid: vertex {vertex} has a non-finite position")]
    NonFinitePosition {
        /// Which mesh.
        which: &'static str,
        /// The vertex.
        vertex: usize,
    },
    /// The percentages are relative to the reference diagonal, which must be positive.
    #[error(
        "the reference mesh's bounding-box diagonal is {diagonal}: percentages of it are \
         undefined (all vertices coincide, or the coordinates overflow)"
    )]
    DegenerateDiagonal {
        /// The offending diagonal.
        diagonal: f64,
    },
    /// [`one_sided`] was given a [`Bvh`] without triangles.
    #[error("the target BVH holds no triangles: there is no surface to measure against")]
    EmptyTarget,
    /// More face samples were asked for than [`MAX_FACE_SAMPLES`].
    #[error("{samples} face samples per direction are more than the limit of {limit}")]
    TooManySamples {
        /// The samples asked for.
        samples: usize,
        /// [`MAX_FACE_SAMPLES`].
        limit: usize,
    },
    /// Distances overflowed `f64` (coordinates near the limits of the type).
    #[error("distances overflow f64: the coordinates are too large to measure")]
    Overflow,
}
