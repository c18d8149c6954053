//! The error type of every reader and writer of the container, grouped by who is at fault
//! (docs/format.md §7).

use std::io;

use crate::header::ValueType;

/// Everything that can go wrong while reading or writing a `.whet` container.
///
/// Grouped by fault: [`Error::Io`] is the machine's (possibly retryable); `Truncated`,
/// `BadMagic`, `Unsupported`, `ChecksumMismatch` and `Format` are the input's;
/// `LimitExceeded` is a policy decision of the caller's [`Limits`](crate::Limits); `Parameter`
/// is API misuse.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum Error {
    /// An error from the underlying reader or writer.
    #[error("I/O error: {0}")]
    Io(#[from] io::Error),

    /// The input ended before the end marker.
    #[error("stream is truncated: it ends at byte {offset}, {what}")]
    Truncated {
        /// Number of bytes the input had.
        offset: u64,
        /// What was being read, e.g. "inside the payload of connectivity".
        what: String,
    },

    /// The input does not start with `WHET`.
    #[error("not a .whet stream: it starts with {found:02x?}, not \"WHET\" (57 48 45 54)")]
    BadMagic {
        /// The first bytes of the input, at most 4 (fewer when the first wrong byte came early).
        found: Vec<u8>,
    },

    /// The stream's major format version is not one this crate reads.
    #[error("{}", unsupported_message(*major, *minor))]
    Unsupported {
        /// Major version found in the stream.
        major: u8,
        /// Minor version found in the stream.
        minor: u8,
    },

    /// A CRC-32 stored in the stream does not match its data.
    #[error("checksum mismatch in {section}: stored {stored:#010x}, computed {computed:#010x}")]
    ChecksumMismatch {
        /// `header`, a section name such as `connectivity`, or `section 9` for an unknown tag.
        section: String,
        /// The CRC stored in the stream.
        stored: u32,
        /// The CRC of the bytes actually read.
        computed: u32,
    },

    /// A declared count or size is above the caller's [`Limits`](crate::Limits).
    #[error(
        "{what} {value} exceeds the limit of {limit} (raise the Limits if the input is trusted)"
    )]
    LimitExceeded {
        /// What was limited, e.g. "vertex count" or "section length (bytes)".
        what: &'static str,
        /// The limit in force.
        limit: u64,
        /// The declared value.
        value: u64,
    },

    /// The bytes do not follow docs/format.md.
    #[error("malformed .whet stream: {0}")]
    Format(#[from] FormatError),

    /// The caller asked for something the API cannot do, e.g. writing an unknown major version
    /// or sections out of tag order.
    #[error("invalid argument: {0}")]
    Parameter(String),
}

fn unsupported_message(major: u8, minor: u8) -> String {
    let reads = crate::Version::CURRENT.major;
    if major > reads {
        format!(
            "stream format version {major}.{minor} is newer than this whet (reads {reads}.x); \
             upgrade whet"
        )
    } else {
        format!(
            "stream format version {major}.{minor} is older than any this whet reads \
             (reads {reads}.x)"
        )
    }
}

/// How the bytes break docs/format.md; carried by [`Error::Format`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum FormatError {
    /// A varint has a redundant trailing zero group (docs/format.md §2).
    #[error("overlong (non-canonical) varint")]
    OverlongVarint,
    /// A varint does not fit 64 bits.
    #[error("varint exceeds 64 bits")]
    VarintOverflow,
    /// The header names a codec mode this crate does not know.
    #[error("codec mode {0} is unknown to this whet (known: 0 exact, 1 swing, 2 subdiv)")]
    UnknownMode(u64),
    /// `header_len` is above the 65 535 bytes the format allows.
    #[error("header length {0} exceeds the 65535 bytes the format allows")]
    HeaderTooLong(u64),
    /// A varint or value runs past the end of the header body.
    #[error("a header value runs past the end of the header body")]
    HeaderOverrun,
    /// The header declares a stream longer than 2^64 bytes.
    #[error("declared stream length overflows 64 bits")]
    LengthOverflow,
    /// An even (required) header field tag this crate does not know.
    #[error("unknown required header field {tag}")]
    UnknownRequiredField {
        /// The field tag.
        tag: u64,
    },
    /// Header field tags are not strictly increasing (equal tags are duplicates).
    #[error("header field {found} follows field {previous}; tags must be strictly increasing")]
    FieldOrder {
        /// The previous tag.
        previous: u64,
        /// The tag found after it.
        found: u64,
    },
    /// A known header field has the wrong value type.
    #[error("header field {tag} has type {found}, expected {expected}")]
    FieldType {
        /// The field tag.
        tag: u64,
        /// Type the format assigns to the tag.
        expected: ValueType,
        /// Type found in the stream.
        found: ValueType,
    },
    /// A known header field has a value the format forbids.
    #[error("header field {tag}: {reason}")]
    FieldValue {
        /// The field tag.
        tag: u64,
        /// What is wrong.
        reason: &'static str,
    },
    /// An even (required) section tag this crate does not know.
    #[error("unknown required section {tag}")]
    UnknownRequiredSection {
        /// The section tag.
        tag: u64,
    },
    /// Two sections have the same tag.
    #[error("duplicate section {tag}")]
    DuplicateSection {
        /// The repeated tag.
        tag: u64,
    },
    /// Section tags are not increasing.
    #[error("section {found} follows section {previous}; tags must be strictly increasing")]
    SectionOrder {
        /// The previous tag.
        previous: u64,
        /// The tag found after it.
        found: u64,
    },
    /// A section does not end before the end marker the header declares.
    #[error("section {tag} of {len} bytes runs past the declared end of the stream")]
    SectionOverrun {
        /// The section tag.
        tag: u64,
        /// Its declared payload length.
        len: u64,
    },
    /// The declared stream length is used up without an end marker.
    #[error("no end marker at byte {offset}, where the header says the stream ends")]
    MissingEndMarker {
        /// Offset of the byte where the end marker belongs (one past its position).
        offset: u64,
    },
    /// The end marker is not where the header says the stream ends.
    #[error("end marker ends at byte {offset}, but the header declares {declared} bytes")]
    MisplacedEndMarker {
        /// Offset just after the end marker found.
        offset: u64,
        /// Declared stream length.
        declared: u64,
    },
    /// Bytes follow the end marker.
    #[error("data continues after the end marker, at byte {offset}")]
    TrailingBytes {
        /// Offset of the first trailing byte.
        offset: u64,
    },
}

impl Error {
    /// True when the error means "these bytes are not a valid stream this crate reads"
    /// (truncated, corrupt, unsupported or malformed input), false for I/O failures, limits and
    /// API misuse.
    pub fn is_input_error(&self) -> bool {
        matches!(
            self,
            Error::Truncated { .. }
                | Error::BadMagic { .. }
                | Error::Unsupported { .. }
                | Error::ChecksumMismatch { .. }
                | Error::Format(_)
        )
    }
}
