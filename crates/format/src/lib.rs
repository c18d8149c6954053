//! whet-format owns the `.whet` container specified in `docs/format.md`: a magic and a
//! major/minor version, a header (codec [`Mode`], vertex and triangle counts, and typed
//! key/value [`HeaderField`]s the codec modes define), then sections tagged by
//! [`SectionKind`], each with a varint length and a CRC-32, and an end marker. It frames bytes
//! and knows nothing about meshes beyond those counts. Readers work on a slice ([`parse`]), on
//! any `Read` ([`read_from`]) and sans-IO chunk by chunk ([`StreamingDecoder`]), with the same
//! results; they check every declared count and length against [`Limits`] and against the
//! bytes that remain before allocating, refuse unknown major versions, trailing bytes and bad
//! CRCs with a precise [`Error`], skip unknown optional sections, and never panic.
//! [`peek_header`] reads version, mode, counts and size from the first bytes alone.
//!
//! ```
//! use whet_format::{parse, peek_header, tag, Container, Header, Limits, Mode, SectionKind};
//!
//! let mut header = Header::new(Mode::Exact, 4, 4).with(tag::QUANT_BITS, 12u64);
//! header.set_bbox([0.0, 0.0, 0.0], [1.0, 1.0, 1.0]);
//! let container = Container::new(header)
//!     .with_section(SectionKind::CONNECTIVITY, vec![0xAA, 0xBB])
//!     .with_section(SectionKind::GEOMETRY, vec![1, 2, 3]);
//! let bytes = container.to_bytes()?;
//!
//! let info = peek_header(&bytes)?;
//! assert_eq!((info.mode, info.vertex_count, info.total_len), (Mode::Exact, 4, bytes.len() as u64));
//!
//! let back = parse(&bytes, &Limits::DEFAULT)?;
//! assert_eq!(back, container);
//! assert_eq!(back.header.get_u64(tag::QUANT_BITS), Some(12));
//! assert_eq!(back.section(SectionKind::GEOMETRY), Some(&[1, 2, 3][..]));
//! # Ok::<(), whet_format::Error>(())
//! ```
#![forbid(unsafe_code)]

mod container;
mod decoder;
mod error;
mod fuzz;
mod header;
mod limits;
mod varint;

pub use container::{Container, Section, SectionKind};
pub use decoder::{parse, read_from, Progress, StreamingDecoder};
pub use error::{Error, FormatError};
pub use fuzz::fuzz_parse;
pub use header::{
    box_f32_outward, peek_header, tag, Header, HeaderField, HeaderInfo, HeaderValue, Mode,
    ValueType, Version, BBOX_F32_LEN, BBOX_LEN, MAGIC, MAX_HEADER_LEN,
};
pub use limits::{Limits, ALLOCATION_LIMIT};
pub use varint::{
    read_varint, read_varint_i64, varint_len, write_varint, write_varint_i64, zigzag_decode,
    zigzag_encode, MAX_VARINT_LEN,
};
