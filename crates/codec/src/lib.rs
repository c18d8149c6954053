//! whet-codec owns whet's codec modes and their public entry points: the [`Encoder`] with its
//! [`EncodeOptions`], and three decoders — [`decode`] from a slice, [`Decoder`] over any
//! `Read`, and the sans-IO [`StreamingDecoder`] — all over the `.whet` container of
//! whet-format. It carries the `exact` mode (Edgebreaker connectivity, positions
//! quantized on one cubic grid and predicted by parallelograms in the prediction-degree
//! order) and the decoder and stream writer of the `swing` mode (SwingWrapper: the retiler
//! that builds the retiled mesh lives in whet-swing, so a decode-only server does not carry
//! it; [`swing`] holds the tip reconstruction both sides share). The prediction code each
//! mode shares between its encoder and decoder lives here so the two cannot drift.
//!
//! ```
//! use whet_codec::{decode, encode, DecodeOptions, EncodeOptions};
//! use whet_mesh::{DVec3, Mesh};
//!
//! let mesh = Mesh::new(
//!     vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
//!     vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! );
//! let encoded = encode(&mesh, &EncodeOptions::DEFAULT.with_quant_bits(12))?;
//! let decoded = decode(&encoded.bytes, &DecodeOptions::DEFAULT)?;
//! assert_eq!(decoded.triangles.len(), 4);
//! for (i, &src) in encoded.report.vertex_order.iter().enumerate() {
//!     assert!((decoded.positions[i] - mesh.positions[src as usize]).length() < 1e-3);
//! }
//! # Ok::<(), whet_codec::Error>(())
//! ```
#![forbid(unsafe_code)]

mod decoder;
mod encoder;
mod exact;
mod fuzz;
mod parallelogram;
mod quantize;
mod sharpen_hint;
mod snap_vetoes;
pub mod surface_filter;
pub mod swing;

pub use decoder::{
    decode, decode_container, decode_container_reusing, decode_reusing, peek_header, DecodeBuffers,
    DecodeOptions, Decoder, StreamingDecoder, DECODE_BYTES_PER_TRIANGLE, DECODE_BYTES_PER_VERTEX,
    DECODE_PEAK_LIMIT,
};
pub use encoder::{
    encode, prepare_mesh, EncodeBuffers, EncodeOptions, EncodeReport, Encoded, Encoder,
    PreparedMesh,
};
pub use exact::{ExactPayloads, ExactPrediction};
#[doc(hidden)]
pub use fuzz::{
    fuzz_decode, fuzz_exact_payloads, fuzz_swing_payloads, fuzz_swing_payloads_extended,
    swing_payload_seed, swing_payload_seed_extended,
};
pub use parallelogram::{average, candidates, gate_fallback, MAX_CANDIDATES};
pub use quantize::Quantizer;
pub use sharpen_hint::SharpenHint;
pub use snap_vetoes::{SnapVetoes, MAX_VETO_PASSES};
pub use surface_filter::{untouched_by_sharpening, FilterFields, SurfaceFilter};
pub use swing::{
    encode_retiled, AngleTable, RetiledMesh, SwingEncoded, SwingFrame, SwingGeometry, SwingParams,
    SwingStreamInfo, VertexSource,
};
pub use whet_format::{HeaderInfo, Limits, Mode, Progress, Version};

/// Everything that can go wrong encoding or decoding.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The container is malformed, truncated, corrupt, of an unknown version, or over limits.
    #[error(transparent)]
    Format(#[from] whet_format::Error),
    /// The connectivity section is corrupt (or the encoder's input could not be traversed).
    #[error(transparent)]
    Connectivity(#[from] whet_edgebreaker::Error),
    /// A section ended early.
    #[error("the {0} section is truncated")]
    Truncated(&'static str),
    /// Decoded data is inconsistent.
    #[error("corrupt stream: {0}")]
    Corrupt(String),
    /// A header field the mode needs is missing.
    #[error("the stream lacks the {0} header field")]
    MissingField(&'static str),
    /// A section the mode needs is missing.
    #[error("the stream lacks the {0} section")]
    MissingSection(&'static str),
    /// The encoder's input mesh cannot be coded (non-finite coordinates, or non-manifold with
    /// repair off).
    #[error("cannot encode this mesh: {0}")]
    InvalidInput(whet_mesh::MeshError),
    /// API misuse (an option out of range, a mode this build lacks).
    #[error("{0}")]
    Parameter(String),
}

impl Error {
    /// True when the fault is in the bytes handed to a decoder (exit code 2 in the CLI).
    pub fn is_input_error(&self) -> bool {
        match self {
            Error::Format(e) => !matches!(e, whet_format::Error::Io(_)),
            Error::Parameter(_) => false,
            _ => true,
        }
    }
}

#[doc(hidden)]
pub fn encode_exact_payloads(
    mesh: &whet_mesh::Mesh,
    bits: u32,
    prediction: ExactPrediction,
) -> Result<ExactPayloads, Error> {
    let table = whet_mesh::CornerTable::new(mesh).map_err(Error::InvalidInput)?;
    exact::encode_exact(
        mesh,
        &mesh.bounding_box(),
        table,
        bits,
        false,
        prediction,
        &mut whet_mesh::Scratch::new(),
    )
}

#[doc(hidden)]
pub fn decode_exact_payloads(
    p: &ExactPayloads,
    prediction: ExactPrediction,
) -> Result<whet_mesh::Mesh, Error> {
    exact::decode_exact(
        &p.connectivity,
        &p.geometry,
        &p.quantizer,
        &whet_edgebreaker::ConnectivityLimits::DEFAULT,
        prediction,
        &mut Default::default(),
    )
}
