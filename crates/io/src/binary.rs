//! Helpers of the binary formats: a chunked reader that hands out records as byte slices, and
//! the little/big-endian scalar decoders.

use std::io::{self, ErrorKind, Read};

use crate::Error;

/// Size of one refill of [`BinReader`]'s buffer.
const CHUNK: usize = 1 << 16;

/// Reads fixed-size records from a `Read` through its own buffer, so that decoding a record is
/// a bounds check and a slice instead of a `read_exact` call.
pub(crate) struct BinReader<R> {
    inner: R,
    buf: Vec<u8>,
    pos: usize,
    end: usize,
}

impl<R: Read> BinReader<R> {
    /// A reader that first hands out `prefix` (bytes already taken from `inner`), then `inner`.
    pub(crate) fn with_prefix(inner: R, prefix: &[u8]) -> Self {
        let mut buf = vec![0; CHUNK.max(prefix.len())];
        buf[..prefix.len()].copy_from_slice(prefix);
        BinReader {
            inner,
            buf,
            pos: 0,
            end: prefix.len(),
        }
    }

    /// A reader of `inner` from its current position.
    pub(crate) fn new(inner: R) -> Self {
        Self::with_prefix(inner, &[])
    }

    /// The next `n` bytes, or an `UnexpectedEof` error when the input has fewer. Callers keep
    /// `n` small (a record, at most a few hundred KiB): the buffer grows to hold it.
    #[inline]
    pub(crate) fn get(&mut self, n: usize) -> io::Result<&[u8]> {
        if self.end - self.pos < n {
            self.refill(n)?;
        }
        let start = self.pos;
        self.pos += n;
        Ok(&self.buf[start..start + n])
    }

    /// Skips `n` bytes, reading them in chunks (never allocating for `n`).
    pub(crate) fn skip(&mut self, mut n: u64) -> io::Result<()> {
        while n > 0 {
            let step = usize::try_from(n).map_or(CHUNK, |n| n.min(CHUNK));
            self.get(step)?;
            n -= step as u64;
        }
        Ok(())
    }

    /// Makes at least `n` bytes available from `pos`.
    #[cold]
    fn refill(&mut self, n: usize) -> io::Result<()> {
        self.buf.copy_within(self.pos..self.end, 0);
        self.end -= self.pos;
        self.pos = 0;
        if self.buf.len() < n {
            self.buf.resize(n.max(CHUNK), 0);
        }
        while self.end < n {
            match self.inner.read(&mut self.buf[self.end..]) {
                Ok(0) => return Err(ErrorKind::UnexpectedEof.into()),
                Ok(k) => self.end += k,
                Err(e) if e.kind() == ErrorKind::Interrupted => {}
                Err(e) => return Err(e),
            }
        }
        Ok(())
    }
}

/// Turns a read error into [`Error::Truncated`] when the input ended: "expected {expected}
/// {what}, file ended after {got}".
pub(crate) fn ended(e: io::Error, expected: u64, what: &str, got: u64) -> Error {
    if e.kind() == ErrorKind::UnexpectedEof {
        Error::truncated(format!(
            "expected {expected} {what}, file ended after {got}"
        ))
    } else {
        Error::Io(e)
    }
}

/// The first `N` bytes of `b` as an array. Callers slice records of a size computed from the
/// same types, so `b` always holds `N` bytes.
#[inline]
pub(crate) fn array<const N: usize>(b: &[u8]) -> [u8; N] {
    let mut a = [0; N];
    a.copy_from_slice(&b[..N]);
    a
}

/// A scalar type that binary PLY and STL store, decodable from either byte order.
pub(crate) trait Decode {
    /// The value at the start of `b` (at least `SIZE` bytes), as f64 (exact for every type).
    fn f64_from(b: &[u8], big_endian: bool) -> f64;
}

macro_rules! impl_decode {
    ($($t:ty),*) => {$(
        impl Decode for $t {
            #[inline(always)]
            fn f64_from(b: &[u8], big_endian: bool) -> f64 {
                let a = array::<{ std::mem::size_of::<$t>() }>(b);
                let v = if big_endian { <$t>::from_be_bytes(a) } else { <$t>::from_le_bytes(a) };
                f64::from(v)
            }
        }
    )*};
}

impl_decode!(i8, u8, i16, u16, i32, u32, f32, f64);

#[cfg(test)]
mod tests {
    use super::*;

    /// A reader that returns at most 3 bytes per call, to exercise refills.
    struct Trickle<'a>(&'a [u8]);

    impl Read for Trickle<'_> {
        fn read(&mut self, out: &mut [u8]) -> io::Result<usize> {
            let n = self.0.len().min(out.len()).min(3);
            out[..n].copy_from_slice(&self.0[..n]);
            self.0 = &self.0[n..];
            Ok(n)
        }
    }

    #[test]
    fn records_across_refills() {
        let data: Vec<u8> = (0..=255).collect();
        let mut r = BinReader::with_prefix(Trickle(&data[2..]), &data[..2]);
        assert_eq!(r.get(5).unwrap(), &data[..5]);
        r.skip(100).unwrap();
        assert_eq!(r.get(7).unwrap(), &data[105..112]);
        r.skip(140).unwrap();
        assert_eq!(r.get(4).unwrap(), &data[252..]);
        assert_eq!(r.get(1).unwrap_err().kind(), ErrorKind::UnexpectedEof);
    }

    #[test]
    fn large_records_grow_the_buffer() {
        let data = vec![7u8; 3 * CHUNK];
        let mut r = BinReader::new(&data[..]);
        assert_eq!(r.get(2 * CHUNK + 1).unwrap().len(), 2 * CHUNK + 1);
        assert!(r.skip(u64::MAX).is_err());
    }

    #[test]
    fn decode_both_orders() {
        assert_eq!(u16::f64_from(&[1, 2], false), 513.0);
        assert_eq!(u16::f64_from(&[1, 2], true), 258.0);
        assert_eq!(i8::f64_from(&[0xff], true), -1.0);
        assert_eq!(f32::f64_from(&1.5f32.to_be_bytes(), true), 1.5);
        assert_eq!(f64::f64_from(&(-2.25f64).to_le_bytes(), false), -2.25);
        assert_eq!(u32::f64_from(&[0xff; 4], false), 4294967295.0);
    }
}
