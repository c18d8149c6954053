//! whet-edgebreaker owns connectivity coding: the Edgebreaker traversal ([`traverse`]) that
//! fixes the order in which every whet coder meets triangles and vertices, the CLERS encoder
//! ([`encode_connectivity`]) with holes closed by dummy vertices and handles recorded as split
//! events, and a linear-time Spirale Reversi decoder ([`decode_connectivity`]) whose backwards
//! reconstruction gives each label the context of the valence its vertex still has to gain.
//! Geometry coders plug in by walking the [`Connectivity`] both sides share.
//!
//! ```
//! use whet_edgebreaker::{decode_connectivity, encode_connectivity, ConnectivityLimits};
//!
//! // An octahedron.
//! let tris = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]];
//! let enc = encode_connectivity(&tris, 6)?;
//! let (dec, _) = decode_connectivity(&enc.bytes, &ConnectivityLimits::DEFAULT)?;
//! assert_eq!(dec.output_triangles().len(), 8);
//! assert_eq!(dec.summary.labels, enc.connectivity.summary.labels);
//! # Ok::<(), whet_edgebreaker::Error>(())
//! ```
#![forbid(unsafe_code)]

mod coding;
mod holes;
mod reverse_decoder;
mod traversal;

pub use coding::{
    decode_connectivity, decode_connectivity_coded, decode_connectivity_reusing,
    encode_connectivity, encode_connectivity_coded_in, encode_connectivity_with_table,
    encode_connectivity_with_table_in, label_bits, Connectivity, ConnectivityBuffers,
    ConnectivityLimits, EncodedConnectivity, LabelCode,
};
pub use holes::close_holes;
pub use traversal::{
    traverse, traverse_in, Clers, SplitEvent, Step, TraversalError, TraversalSummary,
};

/// Why connectivity could not be coded or decoded.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The input mesh is not an oriented manifold.
    #[error("cannot encode this mesh: {0}")]
    Mesh(#[from] whet_mesh::MeshError),
    /// The traversal failed.
    #[error(transparent)]
    Traversal(#[from] TraversalError),
    /// The payload ended early.
    #[error("connectivity stream is truncated")]
    Truncated,
    /// The payload is not a valid connectivity stream.
    #[error("connectivity stream is corrupt: {0}")]
    Corrupt(&'static str),
    /// A count exceeds the decoder's limits.
    #[error("connectivity stream announces {value} {what}, more than the limit of {limit}")]
    LimitExceeded {
        /// What was counted.
        what: &'static str,
        /// The limit.
        limit: u64,
        /// The announced value.
        value: u64,
    },
}

impl From<whet_bits::Error> for Error {
    fn from(e: whet_bits::Error) -> Self {
        match e {
            whet_bits::Error::Truncated => Error::Truncated,
            _ => Error::Corrupt("entropy-coded labels are corrupt"),
        }
    }
}
