//! whet-codec: work in progress.
#![forbid(unsafe_code)]

mod exact;
mod parallelogram;
mod quantize;

pub use exact::ExactPayloads;
pub use parallelogram::{average, candidates, gate_fallback, MAX_CANDIDATES};
pub use quantize::Quantizer;

/// Codec errors.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// Connectivity coding failed.
    #[error(transparent)]
    Connectivity(#[from] whet_edgebreaker::Error),
    /// A section ended early.
    #[error("the {0} section is truncated")]
    Truncated(&'static str),
    /// Decoded data is inconsistent.
    #[error("corrupt stream: {0}")]
    Corrupt(String),
}

#[doc(hidden)]
pub fn encode_exact_payloads(mesh: &whet_mesh::Mesh, bits: u32) -> Result<ExactPayloads, Error> {
    exact::encode_exact(mesh, bits)
}

#[doc(hidden)]
pub fn decode_exact_payloads(p: &ExactPayloads) -> Result<whet_mesh::Mesh, Error> {
    exact::decode_exact(
        &p.connectivity,
        &p.geometry,
        &p.quantizer,
        &whet_edgebreaker::ConnectivityLimits::DEFAULT,
    )
}
