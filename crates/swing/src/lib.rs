//! whet-swing owns the encoder side of whet's main codec, SwingWrapper (Attene, Falcidieno,
//! Spagnuolo, Rossignac, ACM TOG 2003): the [`retile`]r that grows a nearly regular mesh `M'`
//! with edges of about one length `L` over the original `M`, in exactly the Edgebreaker
//! order, so that each new vertex costs one quantized swing angle; and the [`SwingEncoder`]
//! that picks `L` from a rate or error target ([`Rate`]) and writes the stream through
//! whet-codec, which also holds the decoder and the tip reconstruction both sides share.
//!
//! ```
//! use whet_swing::{encode, Rate, SwingOptions};
//!
//! let mesh = whet_io::read_path(&whet_testkit::shared_fixture("spot.off"), None)?;
//! let out = encode(&mesh, &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(0.03)))?;
//! let decoded = whet_codec::decode(&out.bytes, &whet_codec::DecodeOptions::DEFAULT)?;
//! // The decoder rebuilds the encoder's retiled mesh bit for bit.
//! assert_eq!(decoded, out.retiled);
//! assert!(out.bytes.len() < 2000);
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![forbid(unsafe_code)]

mod encoder;
mod filter_fit;
mod fuzz;
mod grid;
mod holes;
mod retiler;
pub mod snap_judge;
mod stated;
mod surface;

pub use encoder::{
    encode, valence6_fraction, AngleTrial, ErrorOf, Rate, SharpenTrial, SwingEncoder, SwingOptions,
    SwingOutput, APEX_MOVE, BESIDE_FACTOR, CREASE_MOVE, CURVED_WALL_FACTOR, MAX_COVERAGE_GAP,
    MAX_ERROR_WEIGHT, PLANAR_FACTOR, QUADRIC_FACTOR, TWO_PASSES,
};
pub use filter_fit::{fit_displacements, fit_filters, fit_surface_filter, FilterFit};
pub use fuzz::{fuzz_decode_sharpen, fuzz_encode};
pub use retiler::{retile, RetileStats, RetileTuning, Retiled};
pub use stated::{StatedOutput, StatedProjection, StatedSharpening};

/// Why a mesh could not be encoded in the swing mode.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The stream could not be written, or the input failed whet-codec's checks.
    #[error(transparent)]
    Codec(#[from] whet_codec::Error),
    /// The retiler found no valid way to continue (bounded work: it stops rather than
    /// loop).
    #[error("the retiler is stuck: {0}")]
    Stuck(String),
    /// A retiler invariant broke (a bug; please report it with the mesh).
    #[error("internal retiler error: {0}")]
    Internal(String),
    /// An error target that no edge length reached.
    #[error("{0}")]
    Unreachable(String),
    /// The input has nothing to retile.
    #[error("cannot encode this mesh: {0}")]
    InvalidInput(String),
    /// An option out of range.
    #[error("{0}")]
    Parameter(String),
    /// The error measurement failed.
    #[error(transparent)]
    Metro(#[from] whet_metro::Error),
}

impl Error {
    /// True when the fault lies in the input mesh rather than in the options.
    pub fn is_input_error(&self) -> bool {
        match self {
            Error::Codec(e) => !matches!(e, whet_codec::Error::Parameter(_)),
            Error::InvalidInput(_) | Error::Stuck(_) => true,
            _ => false,
        }
    }
}
