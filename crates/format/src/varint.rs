//! Canonical unsigned LEB128 varints and zigzag signed varints (docs/format.md §2).
//!
//! Invariants: at most [`MAX_VARINT_LEN`] bytes, no redundant trailing zero group, value
//! ≤ 2^64 − 1, so every value has exactly one encoding and re-encoding a decoded varint gives
//! back the bytes it came from (the CRCs rely on this). The codec uses the same functions for
//! counts inside section payloads.

use crate::error::{Error, FormatError};

/// Longest varint: ⌈64 / 7⌉ bytes.
pub const MAX_VARINT_LEN: usize = 10;

/// Appends the canonical varint of `value` to `out`.
pub fn write_varint(out: &mut Vec<u8>, mut value: u64) {
    while value >= 0x80 {
        // Truncation to the low 7 bits plus the continuation bit is the encoding.
        out.push((value as u8 & 0x7f) | 0x80);
        value >>= 7;
    }
    out.push(value as u8);
}

/// Number of bytes [`write_varint`] writes for `value` (1 to 10).
pub const fn varint_len(value: u64) -> usize {
    let bits = 64 - (value | 1).leading_zeros() as usize;
    bits.div_ceil(7)
}

/// Reads a varint at `data[*pos..]` and advances `*pos` past it.
///
/// On error `*pos` is unchanged. Errors: [`Error::Truncated`] when `data` ends inside the
/// varint, [`FormatError::OverlongVarint`] and [`FormatError::VarintOverflow`] for encodings
/// docs/format.md §2 forbids.
pub fn read_varint(data: &[u8], pos: &mut usize) -> Result<u64, Error> {
    decode(data, pos).map_err(|e| match e {
        VarintError::Truncated => Error::Truncated {
            offset: data.len() as u64,
            what: "inside a varint".to_string(),
        },
        VarintError::Format(f) => Error::Format(f),
    })
}

/// Zigzag-maps a signed value so small magnitudes get small codes: 0, −1, 1, −2 → 0, 1, 2, 3.
pub const fn zigzag_encode(value: i64) -> u64 {
    ((value << 1) ^ (value >> 63)) as u64
}

/// Inverse of [`zigzag_encode`].
pub const fn zigzag_decode(code: u64) -> i64 {
    ((code >> 1) as i64) ^ -((code & 1) as i64)
}

/// Appends the zigzag varint of `value`.
pub fn write_varint_i64(out: &mut Vec<u8>, value: i64) {
    write_varint(out, zigzag_encode(value));
}

/// Reads a zigzag varint; errors as [`read_varint`].
pub fn read_varint_i64(data: &[u8], pos: &mut usize) -> Result<i64, Error> {
    read_varint(data, pos).map(zigzag_decode)
}

/// Why a varint could not be decoded; `Truncated` means "the slice ended inside it", which
/// callers map to their own notion of truncation.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum VarintError {
    Truncated,
    Format(FormatError),
}

/// Decodes one varint; the slice form of [`VarintAcc`].
pub(crate) fn decode(data: &[u8], pos: &mut usize) -> Result<u64, VarintError> {
    let mut acc = VarintAcc::default();
    let mut at = *pos;
    loop {
        let byte = *data.get(at).ok_or(VarintError::Truncated)?;
        at += 1;
        if let Some(value) = acc.push(byte).map_err(VarintError::Format)? {
            *pos = at;
            return Ok(value);
        }
    }
}

/// Incremental varint decoder for the streaming reader: fed one byte at a time.
#[derive(Debug, Clone, Copy, Default)]
pub(crate) struct VarintAcc {
    value: u64,
    count: u32,
}

impl VarintAcc {
    /// Feeds the next byte; returns the value once its last byte has arrived.
    pub(crate) fn push(&mut self, byte: u8) -> Result<Option<u64>, FormatError> {
        // The 10th byte carries only bit 63: it must be exactly 1 (0 would be overlong, more
        // would overflow, and a continuation bit would promise an 11th byte).
        if self.count == 9 && byte > 1 {
            return Err(FormatError::VarintOverflow);
        }
        self.value |= u64::from(byte & 0x7f) << (7 * self.count);
        self.count += 1;
        if byte & 0x80 != 0 {
            return Ok(None);
        }
        if byte == 0 && self.count > 1 {
            return Err(FormatError::OverlongVarint);
        }
        Ok(Some(self.value))
    }

    /// True when no byte has been fed yet.
    pub(crate) fn is_empty(&self) -> bool {
        self.count == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn enc(v: u64) -> Vec<u8> {
        let mut out = Vec::new();
        write_varint(&mut out, v);
        out
    }

    #[test]
    fn spec_examples() {
        assert_eq!(enc(0), [0x00]);
        assert_eq!(enc(127), [0x7f]);
        assert_eq!(enc(128), [0x80, 0x01]);
        assert_eq!(enc(300), [0xac, 0x02]);
        let mut max = vec![0xff; 9];
        max.push(0x01);
        assert_eq!(enc(u64::MAX), max);
        assert_eq!(
            [0, -1, 1, -2].map(zigzag_encode),
            [0, 1, 2, 3],
            "docs/format.md §2"
        );
    }

    #[test]
    fn lengths() {
        for (v, n) in [
            (0, 1),
            (127, 1),
            (128, 2),
            (16383, 2),
            (16384, 3),
            (u64::MAX, 10),
        ] {
            assert_eq!(varint_len(v), n, "{v}");
            assert_eq!(enc(v).len(), n, "{v}");
        }
    }

    #[test]
    fn rejects_overlong() {
        for bad in [&[0x80, 0x00][..], &[0xff, 0x00], &[0x81, 0x80, 0x00]] {
            let mut pos = 0;
            let err = read_varint(bad, &mut pos).unwrap_err();
            assert!(
                matches!(err, Error::Format(FormatError::OverlongVarint)),
                "{bad:02x?}: {err}"
            );
            assert_eq!(pos, 0);
        }
    }

    #[test]
    fn rejects_overflow() {
        let mut ten = vec![0xff; 9];
        ten.push(0x02);
        let mut eleven = vec![0xff; 10];
        eleven.push(0x01);
        for bad in [ten, eleven] {
            let err = read_varint(&bad, &mut 0).unwrap_err();
            assert!(
                matches!(err, Error::Format(FormatError::VarintOverflow)),
                "{err}"
            );
        }
        let mut zero_tenth = vec![0x80; 9];
        zero_tenth.push(0x00);
        let err = read_varint(&zero_tenth, &mut 0).unwrap_err();
        assert!(
            matches!(err, Error::Format(FormatError::OverlongVarint)),
            "{err}"
        );
    }

    #[test]
    fn truncated() {
        let err = read_varint(&[0x80, 0x80], &mut 0).unwrap_err();
        assert!(matches!(err, Error::Truncated { offset: 2, .. }), "{err}");
        assert!(matches!(
            read_varint(&[], &mut 0),
            Err(Error::Truncated { .. })
        ));
    }

    proptest! {
        #[test]
        fn round_trip(v: u64, prefix in proptest::collection::vec(any::<u8>(), 0..4)) {
            let mut bytes = prefix.clone();
            write_varint(&mut bytes, v);
            let mut pos = prefix.len();
            prop_assert_eq!(read_varint(&bytes, &mut pos).unwrap(), v);
            prop_assert_eq!(pos, bytes.len());
            prop_assert_eq!(bytes.len() - prefix.len(), varint_len(v));
        }

        #[test]
        fn round_trip_signed(v: i64) {
            prop_assert_eq!(zigzag_decode(zigzag_encode(v)), v);
            let mut bytes = Vec::new();
            write_varint_i64(&mut bytes, v);
            prop_assert_eq!(read_varint_i64(&bytes, &mut 0).unwrap(), v);
        }

        /// Canonical: whatever bytes decode, they re-encode to themselves.
        #[test]
        fn decoding_is_canonical(bytes in proptest::collection::vec(any::<u8>(), 0..12)) {
            let mut pos = 0;
            if let Ok(v) = read_varint(&bytes, &mut pos) {
                prop_assert_eq!(enc(v), bytes[..pos].to_vec());
            }
        }
    }
}
