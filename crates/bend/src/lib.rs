//! whet-bend owns Bender, the last stage of whet's decoder-side restoration: a
//! feature-preserving interpolatory subdivision that refines the sharpened mesh 1-to-4,
//! smoothing it with Zorin's modified butterfly while the sharp edges tagged by EdgeSharpener
//! (and mesh boundaries) are refined by the four-point rule, so they stay sharp and bend into
//! smooth curves ([`bend`], [`bend_levels`]). Tags are plain edge lists, so any tagger works.
//!
//! ```
//! use whet_bend::bend_levels;
//! use whet_mesh::{DVec3, Mesh};
//!
//! // An octahedron with its equator tagged sharp.
//! let p = vec![DVec3::X, DVec3::Y, -DVec3::X, -DVec3::Y, DVec3::Z, -DVec3::Z];
//! let t = vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4], [1, 0, 5], [2, 1, 5], [3, 2, 5], [0, 3, 5]];
//! let equator = [[0, 1], [1, 2], [2, 3], [0, 3]];
//! let out = bend_levels(&Mesh::new(p.clone(), t), &equator, 2)?;
//! assert_eq!(out.mesh.triangles.len(), 8 * 16);
//! assert_eq!(out.sharp_edges.len(), 4 * 4);
//! assert_eq!(&out.mesh.positions[..6], &p[..]); // interpolating: old vertices stay
//! # Ok::<(), whet_bend::Error>(())
//! ```
#![forbid(unsafe_code)]

mod bender;
mod fuzz;

pub use bender::{bend, bend_levels, zorin_weights, Bent};
pub use fuzz::fuzz_bend;

/// Most triangles [`bend_levels`] produces: the codec's default triangle limit, 2^28
/// (Bender needs about 46 bytes per output triangle at peak, measured on three levels of
/// bunny_dense: 12 GiB at the limit, where 32-bit indices alone would allow 2^30).
pub const MAX_OUTPUT_TRIANGLES: usize = 1 << 28;

/// Peak bytes [`bend_levels`] holds per output triangle (measured on three levels of
/// bunny_dense, 1.8M output triangles): what a caller multiplies by the output count to
/// hold a run against a memory budget before starting it (`whet bend --max-memory`).
pub const PEAK_BYTES_PER_OUTPUT_TRIANGLE: u64 = 46;

/// Why a mesh could not be bent.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The mesh is not an oriented manifold.
    #[error("cannot bend this mesh: {0}")]
    Mesh(#[from] whet_mesh::MeshError),
    /// A coordinate is NaN or infinite.
    #[error("vertex {vertex} has a non-finite coordinate")]
    NonFinite {
        /// The vertex.
        vertex: usize,
    },
    /// Another level would pass [`MAX_OUTPUT_TRIANGLES`].
    #[error(
        "another level of {triangles} triangles would pass the limit of {} output triangles",
        MAX_OUTPUT_TRIANGLES
    )]
    TooLarge {
        /// Triangles before the level.
        triangles: usize,
    },
}
