//! Fixed-width bit fields (quantized seed positions, small header fields) packed MSB first
//! with bitstream-io, for values that have no statistics worth modelling.

use crate::Error;
use bitstream_io::{BigEndian, BitRead, BitReader, BitWrite, BitWriter};

/// Packs fixed-width fields into bytes.
pub struct RawBitWriter {
    inner: BitWriter<Vec<u8>, BigEndian>,
}

impl Default for RawBitWriter {
    fn default() -> Self {
        Self::new()
    }
}

impl RawBitWriter {
    /// An empty writer.
    pub fn new() -> Self {
        RawBitWriter {
            inner: BitWriter::endian(Vec::new(), BigEndian),
        }
    }

    /// Appends the low `bits` bits of `value` (`bits` at most 32; higher bits of `value` are
    /// ignored).
    pub fn write(&mut self, bits: u32, value: u32) {
        let bits = bits.min(32);
        if bits == 0 {
            return;
        }
        let masked = if bits == 32 {
            value
        } else {
            value & ((1u32 << bits) - 1)
        };
        // Writing into a Vec cannot fail and `masked` fits in `bits`.
        let _ = self.inner.write(bits, masked);
    }

    /// Pads to a byte boundary with zeros and returns the bytes.
    pub fn finish(mut self) -> Vec<u8> {
        let _ = self.inner.byte_align();
        self.inner.into_writer()
    }
}

/// Reads fields written by [`RawBitWriter`].
pub struct RawBitReader<'a> {
    inner: BitReader<std::io::Cursor<&'a [u8]>, BigEndian>,
}

impl<'a> RawBitReader<'a> {
    /// Reads from `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        RawBitReader {
            inner: BitReader::endian(std::io::Cursor::new(bytes), BigEndian),
        }
    }

    /// Reads a `bits`-bit field (at most 32); [`Error::Truncated`] past the end.
    pub fn read(&mut self, bits: u32) -> Result<u32, Error> {
        let bits = bits.min(32);
        if bits == 0 {
            return Ok(0);
        }
        self.inner.read::<u32>(bits).map_err(|_| Error::Truncated)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_round_trip() {
        let mut w = RawBitWriter::new();
        let fields = [(3, 5u32), (14, 12345), (1, 1), (32, 0xDEADBEEF), (7, 0x7F)];
        for &(b, v) in &fields {
            w.write(b, v);
        }
        let bytes = w.finish();
        assert_eq!(bytes.len(), (3 + 14 + 1 + 32 + 7usize).div_ceil(8));
        let mut r = RawBitReader::new(&bytes);
        for &(b, v) in &fields {
            assert_eq!(r.read(b).unwrap(), v);
        }
        assert!(r.read(16).is_err());
    }
}
