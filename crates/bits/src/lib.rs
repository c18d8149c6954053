//! whet-bits owns entropy coding for every whet stream: an adaptive binary range coder
//! ([`RangeEncoder`], [`RangeDecoder`]) with its probability models ([`BitModel`], [`BitTree`],
//! [`SymbolModel`], [`UnsignedIntModel`], [`SignedIntModel`]), a [`CostCounter`] that prices
//! symbols in fractions of a bit with the same models so encoders can compare choices before
//! making them, a static-table rANS residual code for streams that must decode fast
//! ([`StaticResidualEncoder`], [`StaticResidualDecoder`]), and fixed-width bit fields ([`RawBitWriter`], [`RawBitReader`]). All
//! arithmetic is integer, so streams are identical on every machine.
//!
//! ```
//! use whet_bits::{RangeDecoder, RangeEncoder, SymbolModel};
//!
//! // Five CLERS-like labels, mostly the first two.
//! let labels = [0usize, 1, 0, 1, 0, 0, 1, 4, 0, 1, 0, 1];
//! let mut model = SymbolModel::new(5);
//! let mut enc = RangeEncoder::new();
//! for &l in &labels {
//!     enc.encode_symbol(&mut model, l);
//! }
//! let bytes = enc.finish();
//!
//! let mut model = SymbolModel::new(5);
//! let mut dec = RangeDecoder::new(&bytes)?;
//! let back: Vec<usize> = labels.iter().map(|_| dec.decode_symbol(&mut model)).collect();
//! dec.finish()?;
//! assert_eq!(back, labels);
//! # Ok::<(), whet_bits::Error>(())
//! ```
#![forbid(unsafe_code)]

mod cost;
mod models;
mod range_coder;
mod rans;
mod raw;
mod residual;

pub use cost::{CostCounter, COST_FRAC_BITS, COST_ONE};
pub use models::{
    BitModel, BitSink, BitTree, CountingBitModel, SignedIntModel, SymbolModel, SymbolTables,
    UnsignedIntModel, ADAPT_SHIFT, COUNTING_PROB_BITS, PROB_BITS, PROB_ONE,
};
pub use range_coder::{RangeDecoder, RangeEncoder};
pub use rans::{
    StaticResidualDecoder, StaticResidualEncoder, MAX_STATIC_CONTEXTS, STATIC_LANES, STATIC_PREC,
    STATIC_SYMBOLS,
};
pub use raw::{RawBitReader, RawBitWriter};
pub use residual::{CdfModel, ResidualModel, CDF_SYMBOLS};

/// Why a stream could not be decoded.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// The stream ended before the data it announced.
    #[error("entropy-coded stream is truncated")]
    Truncated,
    /// The stream is not one this coder wrote.
    #[error("entropy-coded stream is corrupt: {0}")]
    Corrupt(&'static str),
}
