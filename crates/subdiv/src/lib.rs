//! whet-subdiv owns whet's `subdiv` mode (seed 004: Wu, Zheng, Cai & Li, "Variational
//! reconstruction using subdivision surfaces with continuous sharpness control", CVM 2017): Loop
//! subdivision whose control edges carry a continuous sharpness `h` in [0, 1] blending the
//! smooth rules with Hoppe et al.'s crease, dart and corner rules ([`subdivide`],
//! [`EdgeSharpness`]); feature-preserving quadric-error simplification of a dense mesh to a
//! control mesh of a requested size ([`simplify`]); the variational L1 fit of the control
//! points and the sharpness to the dense mesh ([`fit`]); and the stream payloads of the mode
//! ([`encode_subdiv`], [`decode_subdiv`]): the control mesh through the exact mode's coders,
//! one quantized sharpness per edge, and the number of levels the decoder subdivides. See
//! `docs/subdiv.md`.
//!
//! ```
//! use whet_subdiv::{subdivide, EdgeSharpness, SubdivOptions};
//! use whet_synth::{Shape, ShapeKind, ShapeParams};
//!
//! // The exact cube (corners and edges sharp), subdivided twice with its edges as creases.
//! let cube = Shape::new(ShapeKind::Cube, &ShapeParams::default()).unwrap().truth_mesh();
//! let creases = EdgeSharpness::from_dihedral_angle(&cube, 40.0);
//! let out = subdivide(&cube, &creases, &SubdivOptions::DEFAULT.with_levels(2))?;
//! assert_eq!(out.triangles.len(), cube.triangles.len() * 16);
//! // Fully sharp corners do not move.
//! for v in 0..cube.positions.len() {
//!     assert!((out.positions[v] - cube.positions[v]).length() < 1e-12);
//! }
//! # Ok::<(), whet_subdiv::Error>(())
//! ```
#![forbid(unsafe_code)]

mod denoise;
mod fit;
mod loop_subdivision;
mod qem;
mod sharpness;
mod sharpness_fit;
mod sparse;
mod stream;
mod surface;
mod topology;

pub use denoise::bilateral_denoise;
pub use fit::{
    fit, fit_control, initial_sharpness, FitFallback, FitOptions, FitReport, Fitted, SharpnessMode,
    SharpnessSolver, MAX_FITTED_TRIANGLES,
};
pub use qem::{simplify, Simplified, SimplifyOptions};
pub use sharpness::EdgeSharpness;
pub use stream::{
    decode_control, decode_subdiv, encode_control, encode_subdiv, DecodedControl,
    SubdivEncodeOptions, SubdivPayloads, SubdivReport, SHARPNESS_FORMAT,
    SUBDIVISION_BYTES_PER_TRIANGLE, SUBDIVISION_PEAK_LIMIT,
};
pub use surface::{subdivide, subdivided_counts, SubdivOptions, MAX_LEVELS, MAX_OUTPUT_TRIANGLES};

/// Everything that can go wrong subdividing, fitting, encoding or decoding.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The mesh cannot be used: non-manifold, inconsistently oriented, non-finite or empty.
    #[error("unusable mesh: {0}")]
    InvalidInput(whet_mesh::MeshError),
    /// API misuse: an option out of range, sharpness made for another mesh.
    #[error("invalid parameter: {0}")]
    Parameter(String),
    /// A requested or declared size is above a limit.
    #[error("{what} {value} exceeds the limit {limit}")]
    LimitExceeded {
        /// What was too large.
        what: &'static str,
        /// The limit.
        limit: u64,
        /// The requested or declared value.
        value: u64,
    },
    /// The control-mesh stream could not be written or read by the exact mode.
    #[error("control mesh stream: {0}")]
    Codec(#[from] whet_codec::Error),
    /// The sharpness payload ended early.
    #[error("the sharpness payload is truncated")]
    Truncated,
    /// The sharpness payload is inconsistent with itself or with the control mesh.
    #[error("corrupt sharpness payload: {0}")]
    Corrupt(String),
}
