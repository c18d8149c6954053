//! whet is a mesh codec that gets far more shape per bit than vertex-quantizing codecs: it
//! re-tiles a dense triangle mesh into a nearly regular one whose vertices each cost a few
//! bits (SwingWrapper), codes the connectivity with Edgebreaker, and after decoding restores
//! the sharp edges and corners that uniform re-tiling chamfers away (EdgeSharpener, then the
//! Bender subdivision).
//!
//! This crate is the facade that applications depend on: it re-exports the public API of the
//! internal crates (which may change freely) under stable paths. The `whet` binary is the
//! command-line front end.
//!
//! ```
//! use whet::{io, Mesh};
//! let text = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 1 2 3\n3 2 0 3\n";
//! let mesh: Mesh = io::read(text.as_bytes(), io::Format::Off)?;
//! let report = mesh.topology_report();
//! assert_eq!((report.vertices, report.triangles, report.genus), (4, 4, Some(0)));
//! # Ok::<(), whet::io::Error>(())
//! ```
#![forbid(unsafe_code)]

pub use whet_mesh::{
    angle_between, edge_key, Aabb, CornerId, CornerTable, DVec3, EdgeLengthStats, FaceId,
    ManifoldRepair, Mesh, MeshError, TopologyReport, VertexId,
};

/// Mesh files: OFF, OBJ, PLY and STL readers and writers.
pub mod io {
    pub use whet_io::*;
}

/// The codec: encoders, decoders, options and reports.
pub mod codec {
    pub use whet_codec::*;
}

pub use whet_codec::{
    decode, encode, DecodeOptions, Decoder, EncodeOptions, Encoder, StreamingDecoder,
};
