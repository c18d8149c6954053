//! Static-table residual code for streams that must decode fast: per context, one frequency
//! table for the whole stream (sent ahead of the data), coded with four interleaved rANS
//! states (Duda's asymmetric numeral systems, range variant) and a table lookup per symbol.
//! The adaptive [`crate::ResidualModel`] searches and updates a 32-entry cumulative table per
//! symbol; here decoding a symbol is one slot lookup, one multiply and at most one 16-bit
//! read, and the chains of residuals on different states (lanes) overlap.
//!
//! A residual `r` (`|r| < 2^32`) is split into a symbol and raw bits: with `z = |r|` of bit
//! length `L`, the symbol is `z` itself for `z < 8`, else `8 + 4 (L - 4) + h`, `h` the two
//! bits below the leading one (128 symbols); the `L - 3` bits below `h` and then (for
//! `z != 0`) the sign go to a separate raw-bit stream, least significant bit first, as one
//! field (sign in its lowest bit). Symbols are entropy coded in the caller's context (below
//! [`MAX_STATIC_CONTEXTS`]). A caller with an alphabet of its own (up to 128 symbols, no raw
//! bits) codes its symbols directly ([`StaticResidualEncoder::encode_symbol`]).
//!
//! Layout of [`StaticResidualEncoder::finish`]'s bytes (docs/format.md, "Exact geometry
//! payload"): the context mask (varint: bit `k` set when context `k` has a table); the
//! tables as bit fields, least significant bit first, padded to a byte: per present
//! context, in order, its symbol count less one (7 bits) and, for every symbol but the last,
//! the Elias gamma code of its frequency plus one (the last is what the others leave of
//! `2^12`, at least 1); the [`STATIC_LANES`] final rANS states (u32 little
//! endian each, state 0 first); the count of 16-bit words (varint) and the words (little
//! endian), in the order the decoder reads them; then the raw-bit stream to the end.

use crate::Error;

/// Bits of the frequency total: every table sums to `2^12`.
pub const STATIC_PREC: u32 = 12;
const TOTAL: u32 = 1 << STATIC_PREC;
const SLOT_MASK: u32 = TOTAL - 1;
/// Symbols of the residual alphabet: magnitudes below [`DIRECT`] whole, then four per bit
/// length up to 32 (the two bits below the leading one).
pub const STATIC_SYMBOLS: usize = 128;
/// Bits below a magnitude's leading one that its symbol holds.
const SUB_BITS: u32 = 2;
/// Magnitudes below this are symbols of their own.
const DIRECT: u32 = 1 << (SUB_BITS + 1);
/// Most contexts a static residual code distinguishes (one bit each in the context mask).
pub const MAX_STATIC_CONTEXTS: usize = 64;
/// Interleaved rANS states (lanes) of a static residual code.
pub const STATIC_LANES: usize = 4;
/// Lower bound of a normalised rANS state; states live in `[LOWER, 2^32)`.
const LOWER: u32 = 1 << 16;

/// The symbol of magnitude `z` and the number of raw mantissa bits below it.
#[inline(always)]
fn symbol_of(z: u32) -> (u32, u32) {
    if z < DIRECT {
        return (z, 0);
    }
    let len = 32 - z.leading_zeros();
    let extra = len - 1 - SUB_BITS;
    let top = (z >> extra) & ((1 << SUB_BITS) - 1);
    (DIRECT + ((len - SUB_BITS - 2) << SUB_BITS) + top, extra)
}

/// Per symbol: the magnitude with the raw mantissa bits zero, and the number of those bits.
const SYMBOL_BASE: [(u32, u32); STATIC_SYMBOLS] = {
    let mut t = [(0u32, 0u32); STATIC_SYMBOLS];
    let mut s = 0;
    while s < STATIC_SYMBOLS {
        let k = s as u32;
        t[s] = if k < DIRECT {
            (k, 0)
        } else {
            let len = ((k - DIRECT) >> SUB_BITS) + SUB_BITS + 2;
            let top = (k - DIRECT) & ((1 << SUB_BITS) - 1);
            let extra = len - 1 - SUB_BITS;
            // Lengths past 32 (symbols no magnitude has) keep the top bit in range.
            if len > 32 {
                (0, 0)
            } else {
                (((1 << SUB_BITS) | top) << extra, extra)
            }
        };
        s += 1;
    }
    t
};

/// Per symbol, the bit length of its magnitudes.
const SYMBOL_LENGTH: [u32; STATIC_SYMBOLS] = {
    let mut t = [0u32; STATIC_SYMBOLS];
    let mut s = 0;
    while s < STATIC_SYMBOLS {
        let k = s as u32;
        t[s] = if k < DIRECT {
            32 - k.leading_zeros()
        } else {
            ((k - DIRECT) >> SUB_BITS) + SUB_BITS + 2
        };
        s += 1;
    }
    t
};

/// Appends the Elias gamma code of `v >= 1` (its bit length less one as zeros, a one, then
/// the bits below its leading one), least significant bit first.
fn push_gamma(out: &mut RawFields, v: u32) {
    let len = 32 - v.leading_zeros();
    out.push(len - 1, 0);
    out.push(1, 1);
    out.push(len - 1, u64::from(v) & ((1u64 << (len - 1)) - 1));
}

/// Reads the bit fields of the tables (see [`StaticResidualEncoder::finish`]).
struct TableBits<'a> {
    bytes: &'a [u8],
    bit: usize,
}

impl TableBits<'_> {
    fn read(&mut self, bits: u32) -> Result<u32, Error> {
        let mut v = 0u32;
        for i in 0..bits {
            let byte = *self.bytes.get(self.bit / 8).ok_or(Error::Truncated)?;
            v |= u32::from(byte >> (self.bit % 8) & 1) << i;
            self.bit += 1;
        }
        Ok(v)
    }

    /// An Elias gamma code of a value up to `2^13 - 1`.
    fn gamma(&mut self) -> Result<u32, Error> {
        let mut zeros = 0;
        while self.read(1)? == 0 {
            zeros += 1;
            if zeros > 12 {
                return Err(Error::Corrupt("static residual code: frequency too large"));
            }
        }
        Ok(1 << zeros | self.read(zeros)?)
    }

    /// Bytes read, the last one's padding included.
    fn bytes_read(&self) -> usize {
        self.bit.div_ceil(8)
    }
}

/// Appends `v` as a LEB128 varint.
fn put_varint(out: &mut Vec<u8>, mut v: u64) {
    while v >= 0x80 {
        out.push((v as u8) | 0x80);
        v >>= 7;
    }
    out.push(v as u8);
}

/// Reads a LEB128 varint at `*pos`.
fn get_varint(bytes: &[u8], pos: &mut usize) -> Result<u64, Error> {
    let mut v = 0u64;
    for shift in (0..64).step_by(7) {
        let b = *bytes.get(*pos).ok_or(Error::Truncated)?;
        *pos += 1;
        v |= u64::from(b & 0x7F) << shift;
        if b & 0x80 == 0 {
            return Ok(v);
        }
    }
    Err(Error::Corrupt("static residual code: varint too long"))
}

/// Frequencies summing to [`TOTAL`] for `counts` (not all zero): proportional, every symbol
/// seen at least 1, the rounding's remainder on the most frequent symbol (ties: the lowest).
fn normalise(counts: &[u64; STATIC_SYMBOLS]) -> [u32; STATIC_SYMBOLS] {
    let total: u64 = counts.iter().sum();
    let mut f = [0u32; STATIC_SYMBOLS];
    for (f, &c) in f.iter_mut().zip(counts) {
        if c > 0 {
            *f = ((c * u64::from(TOTAL)) / total).max(1) as u32;
        }
    }
    let sum: u32 = f.iter().sum();
    if sum < TOTAL {
        let top = (0..STATIC_SYMBOLS)
            .max_by_key(|&s| (counts[s], std::cmp::Reverse(s)))
            .unwrap_or(0);
        f[top] += TOTAL - sum;
    } else {
        // The floors of 1 pushed the sum over: take it back from the largest frequencies
        // (at most 63 too many, from symbols that each hold far more than one).
        let mut excess = sum - TOTAL;
        while excess > 0 {
            let top = (0..STATIC_SYMBOLS)
                .max_by_key(|&s| (f[s], std::cmp::Reverse(s)))
                .unwrap_or(0);
            let take = excess.min(f[top] / 2);
            f[top] -= take;
            excess -= take;
        }
    }
    f
}

/// Packs raw fields least significant bit first.
#[derive(Debug, Default)]
struct RawFields {
    bytes: Vec<u8>,
    acc: u64,
    fill: u32,
}

impl RawFields {
    /// Appends the low `bits` bits of `v` (`bits <= 32`, the bits above zero).
    #[inline(always)]
    fn push(&mut self, bits: u32, v: u64) {
        self.acc |= v << self.fill;
        self.fill += bits;
        if self.fill >= 32 {
            self.bytes
                .extend_from_slice(&(self.acc as u32).to_le_bytes());
            self.acc >>= 32;
            self.fill -= 32;
        }
    }

    fn finish(mut self) -> Vec<u8> {
        while self.fill > 0 {
            self.bytes.push(self.acc as u8);
            self.acc >>= 8;
            self.fill = self.fill.saturating_sub(8);
        }
        self.bytes
    }
}

/// Collects residuals by context, then codes them with per-context static tables
/// ([`StaticResidualEncoder::finish`]).
#[derive(Debug)]
pub struct StaticResidualEncoder {
    contexts: usize,
    /// Per coded residual: its context, lane and symbol (`context << 16 | lane << 8 |
    /// symbol`).
    items: Vec<u32>,
    counts: Vec<[u64; STATIC_SYMBOLS]>,
    raw: RawFields,
}

impl StaticResidualEncoder {
    /// An encoder for contexts `0..contexts` (`contexts <= MAX_STATIC_CONTEXTS`; more are
    /// clamped).
    pub fn new(contexts: usize) -> Self {
        let contexts = contexts.min(MAX_STATIC_CONTEXTS);
        StaticResidualEncoder {
            contexts,
            items: Vec::new(),
            counts: vec![[0; STATIC_SYMBOLS]; contexts],
            raw: RawFields::default(),
        }
    }

    /// Codes `r` in `context` (below the encoder's context count; a larger one is clamped
    /// to the last) on rANS state `lane` (below [`STATIC_LANES`]; taken modulo it): the
    /// decoder must read it on the same lane. Residuals on different lanes decode as
    /// independent chains (a caller puts the three axes of a vertex on three lanes).
    #[inline]
    pub fn encode(&mut self, context: usize, lane: usize, r: i32) {
        let z = r.unsigned_abs();
        let (s, extra) = symbol_of(z);
        self.encode_symbol(context, lane, s as usize);
        if z != 0 {
            let mantissa = u64::from(z) & ((1u64 << extra) - 1);
            self.raw.push(extra + 1, mantissa << 1 | u64::from(r < 0));
        }
    }

    /// Codes a symbol (below [`STATIC_SYMBOLS`]; taken modulo it) in `context` on `lane`,
    /// with no raw bits: for alphabets of their own (the decoder reads it with
    /// [`StaticResidualDecoder::decode_symbol`]).
    #[inline]
    pub fn encode_symbol(&mut self, context: usize, lane: usize, symbol: usize) {
        let context = context.min(self.contexts - 1);
        let s = symbol % STATIC_SYMBOLS;
        self.items
            .push((context as u32) << 16 | ((lane % STATIC_LANES) as u32) << 8 | s as u32);
        self.counts[context][s] += 1;
    }

    /// Appends a raw field of `bits` bits (at most 32) to the raw-bit stream.
    pub fn encode_raw(&mut self, bits: u32, value: u32) {
        let bits = bits.min(32);
        let v = if bits == 32 {
            u64::from(value)
        } else {
            u64::from(value) & ((1u64 << bits) - 1)
        };
        self.raw.push(bits, v);
    }

    /// Residuals coded so far.
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// Whether nothing was coded.
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The stream's bytes (layout in the module docs).
    pub fn finish(self) -> Vec<u8> {
        let mut out = Vec::new();
        let mut mask = 0u64;
        // (frequency, cumulative frequency) per context and symbol.
        let mut fc = vec![[(0u32, 0u32); STATIC_SYMBOLS]; self.contexts];
        for (k, counts) in self.counts.iter().enumerate() {
            if counts.iter().any(|&c| c > 0) {
                mask |= 1 << k;
            }
        }
        put_varint(&mut out, mask);
        // The tables as bit fields (most frequencies are small): per context its symbol
        // count less one in 7 bits, then every frequency but the last (the total fixes it)
        // as the Elias gamma code of the frequency plus one.
        let mut tables = RawFields::default();
        for (k, counts) in self.counts.iter().enumerate() {
            if mask >> k & 1 == 0 {
                continue;
            }
            let f = normalise(counts);
            let n = STATIC_SYMBOLS - f.iter().rev().take_while(|&&x| x == 0).count();
            tables.push(7, (n - 1) as u64);
            let mut cum = 0u32;
            for s in 0..n {
                if s + 1 < n {
                    push_gamma(&mut tables, f[s] + 1);
                }
                fc[k][s] = (f[s], cum);
                cum += f[s];
            }
        }
        out.extend_from_slice(&tables.finish());
        // rANS runs backwards: the last residual first, each on its lane's state.
        let mut states = [LOWER; STATIC_LANES];
        let mut words: Vec<u16> = Vec::with_capacity(self.items.len() / 2 + 4);
        for &item in self.items.iter().rev() {
            let (f, c) = fc[(item >> 16) as usize][(item & 0xFF) as usize];
            let x = &mut states[(item >> 8 & 0xFF) as usize];
            // Renormalise so that the coded state stays below 2^32: it is when x < f 2^20,
            // which one word off any state below 2^32 makes true.
            if u64::from(*x) >= u64::from(f) << (32 - STATIC_PREC) {
                words.push(*x as u16);
                *x >>= 16;
            }
            *x = ((*x / f) << STATIC_PREC) + (*x % f) + c;
        }
        for x in states {
            out.extend_from_slice(&x.to_le_bytes());
        }
        put_varint(&mut out, words.len() as u64);
        for w in words.iter().rev() {
            out.extend_from_slice(&w.to_le_bytes());
        }
        out.extend_from_slice(&self.raw.finish());
        out
    }
}

/// Decodes what [`StaticResidualEncoder`] wrote, in the same order and contexts.
#[derive(Debug)]
pub struct StaticResidualDecoder<'a> {
    /// Symbol per slot, `TOTAL` per context; absent contexts map every slot to symbol 0 with
    /// the whole total (decoding there reads nothing and leaves the state as it is; a
    /// stream that goes there was not written for this context sequence, which the end
    /// checks of [`StaticResidualDecoder::finish`] then catch).
    /// Fixed sizes (every context up to [`MAX_STATIC_CONTEXTS`], absent ones as above), so
    /// that a masked index needs no bounds check.
    slots: Box<[[u8; TOTAL as usize]; MAX_STATIC_CONTEXTS]>,
    /// `frequency << 16 | cumulative` per context and symbol.
    fc: Box<[[u32; STATIC_SYMBOLS]; MAX_STATIC_CONTEXTS]>,
    states: [u32; STATIC_LANES],
    words: &'a [u8],
    word_pos: usize,
    raw: &'a [u8],
    raw_pos: usize,
    acc: u64,
    fill: u32,
    overran: bool,
}

impl<'a> StaticResidualDecoder<'a> {
    /// Reads the tables and the states of `bytes`, for contexts `0..contexts`. Fails with
    /// [`Error::Truncated`] or [`Error::Corrupt`] (a table that does not sum to `2^12`, a
    /// context beyond `contexts`, a state out of range, more words than bytes).
    pub fn new(bytes: &'a [u8], contexts: usize) -> Result<Self, Error> {
        let contexts = contexts.min(MAX_STATIC_CONTEXTS);
        let mut pos = 0usize;
        let mask = get_varint(bytes, &mut pos)?;
        if contexts < 64 && mask >> contexts != 0 {
            return Err(Error::Corrupt(
                "static residual code: table for an unknown context",
            ));
        }
        let mut slots: Box<[[u8; TOTAL as usize]; MAX_STATIC_CONTEXTS]> =
            vec![[0u8; TOTAL as usize]; MAX_STATIC_CONTEXTS]
                .into_boxed_slice()
                .try_into()
                .map_err(|_| Error::Corrupt("static residual code: table allocation"))?;
        let mut fc: Box<[[u32; STATIC_SYMBOLS]; MAX_STATIC_CONTEXTS]> =
            vec![[0u32; STATIC_SYMBOLS]; MAX_STATIC_CONTEXTS]
                .into_boxed_slice()
                .try_into()
                .map_err(|_| Error::Corrupt("static residual code: table allocation"))?;
        let mut table_bits = TableBits {
            bytes: bytes.get(pos..).unwrap_or(&[]),
            bit: 0,
        };
        for k in 0..MAX_STATIC_CONTEXTS {
            if k >= contexts || mask >> k & 1 == 0 {
                // Symbol 0 with the whole total: the identity on the state.
                fc[k][0] = TOTAL << 16;
                continue;
            }
            let n = table_bits.read(7)? as usize + 1;
            let mut cum = 0u32;
            for s in 0..n {
                let f = if s + 1 < n {
                    table_bits.gamma()? - 1
                } else {
                    // The last frequency is what the others leave of the total: at least 1.
                    TOTAL.saturating_sub(cum)
                };
                if f > TOTAL - cum || (s + 1 == n && f == 0) {
                    return Err(Error::Corrupt(
                        "static residual code: frequencies do not sum to the total",
                    ));
                }
                fc[k][s] = f << 16 | cum;
                slots[k][cum as usize..(cum + f) as usize].fill(s as u8);
                cum += f;
            }
        }
        pos += table_bits.bytes_read();
        let mut state = [0u32; STATIC_LANES];
        for s in &mut state {
            let b = bytes.get(pos..pos + 4).ok_or(Error::Truncated)?;
            *s = u32::from_le_bytes([b[0], b[1], b[2], b[3]]);
            pos += 4;
            if *s < LOWER {
                return Err(Error::Corrupt("static residual code: state out of range"));
            }
        }
        let words = get_varint(bytes, &mut pos)?;
        let word_bytes = words
            .checked_mul(2)
            .filter(|&w| w <= (bytes.len() - pos) as u64)
            .ok_or(Error::Truncated)? as usize;
        let (words, raw) = bytes[pos..].split_at(word_bytes);
        Ok(StaticResidualDecoder {
            slots,
            fc,
            states: state,
            words,
            word_pos: 0,
            raw,
            raw_pos: 0,
            acc: 0,
            fill: 0,
            overran: false,
        })
    }

    /// Whether a read went past the end of the words or of the raw bits (the values read
    /// there are zeros; [`StaticResidualDecoder::finish`] fails).
    #[inline]
    pub fn overran(&self) -> bool {
        self.overran
    }

    /// The next `bits` raw bits (at most 32), least significant first.
    #[inline(always)]
    fn raw_bits(&mut self, bits: u32) -> u64 {
        if self.fill < bits {
            let chunk = match self.raw.get(self.raw_pos..self.raw_pos + 4) {
                Some(b) => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
                None => self.raw_tail(),
            };
            self.raw_pos += 4;
            self.acc |= u64::from(chunk) << self.fill;
            self.fill += 32;
        }
        let v = self.acc & ((1u64 << bits) - 1);
        self.acc >>= bits;
        self.fill -= bits;
        v
    }

    /// The last, partial chunk of raw bits (zeros past the end).
    #[cold]
    fn raw_tail(&mut self) -> u32 {
        let mut b = [0u8; 4];
        let rest = self.raw.get(self.raw_pos..).unwrap_or(&[]);
        if rest.is_empty() {
            // Bits the stream does not hold: stop the caller early.
            self.overran = true;
        }
        b[..rest.len()].copy_from_slice(rest);
        u32::from_le_bytes(b)
    }

    /// A raw field of `bits` bits (at most 32), as [`StaticResidualEncoder::encode_raw`]
    /// wrote it.
    pub fn decode_raw(&mut self, bits: u32) -> u32 {
        self.raw_bits(bits.min(32)) as u32
    }

    /// The next residual, in `context` on `lane`, as the encoder coded it (a context at
    /// or past the decoder's count reads nothing and gives 0: no valid stream goes there).
    #[inline(always)]
    pub fn decode(&mut self, context: usize, lane: usize) -> i32 {
        self.decode_with_length(context, lane).0
    }

    /// The next symbol coded by [`StaticResidualEncoder::encode_symbol`] in `context` on
    /// `lane` (as [`StaticResidualDecoder::decode`] for a context past the decoder's count).
    #[inline(always)]
    pub fn decode_symbol(&mut self, context: usize, lane: usize) -> usize {
        let context = context % MAX_STATIC_CONTEXTS;
        let lane = lane % STATIC_LANES;
        let x = self.states[lane];
        let slot = x & SLOT_MASK;
        let s = usize::from(self.slots[context][slot as usize]) % STATIC_SYMBOLS;
        self.states[lane] = self.advance(x, self.fc[context][s], slot);
        s
    }

    /// The state after decoding the symbol of `fc` (`frequency << 16 | cumulative`) at
    /// `slot` of state `x`, renormalised.
    #[inline(always)]
    fn advance(&mut self, x: u32, fc: u32, slot: u32) -> u32 {
        let mut x = (fc >> 16) * (x >> STATIC_PREC) + slot - (fc & 0xFFFF);
        if x < LOWER {
            let w = match self.words.get(self.word_pos..self.word_pos + 2) {
                Some(b) => u32::from(u16::from_le_bytes([b[0], b[1]])),
                None => {
                    self.overran = true;
                    0
                }
            };
            self.word_pos += 2;
            x = x << 16 | w;
        }
        x
    }

    /// [`StaticResidualDecoder::decode`], with the bit length of the residual's magnitude
    /// (0 for 0), known from the symbol before its raw bits are read: a caller whose next
    /// context depends on it need not wait for them.
    #[inline(always)]
    pub fn decode_with_length(&mut self, context: usize, lane: usize) -> (i32, u32) {
        let context = context % MAX_STATIC_CONTEXTS;
        let lane = lane % STATIC_LANES;
        let x = self.states[lane];
        let slot = x & SLOT_MASK;
        let s = usize::from(self.slots[context][slot as usize]) % STATIC_SYMBOLS;
        let x = self.advance(x, self.fc[context][s], slot);
        self.states[lane] = x;
        let length = SYMBOL_LENGTH[s];
        if s == 0 {
            return (0, 0);
        }
        let (base, extra) = SYMBOL_BASE[s];
        let v = self.raw_bits(extra + 1);
        let z = base | (v >> 1) as u32;
        // Two's complement negation by the sign bit, without a branch.
        let sign = (v & 1) as i32;
        ((z as i32 ^ -sign).wrapping_add(sign), length)
    }

    /// Checks that the stream was read exactly: both states back at their start, every word
    /// read, and no more raw bits read than the stream holds (its last byte's padding
    /// aside).
    pub fn finish(&self) -> Result<(), Error> {
        let raw_read = (self.raw_pos as u64) * 8 - u64::from(self.fill);
        if self.overran || raw_read > self.raw.len() as u64 * 8 {
            return Err(Error::Truncated);
        }
        if self.states != [LOWER; STATIC_LANES] || self.word_pos != self.words.len() {
            return Err(Error::Corrupt(
                "static residual code: stream not read to its end",
            ));
        }
        if self.raw.len() as u64 * 8 - raw_read >= 8 {
            return Err(Error::Corrupt("static residual code: raw bits left unread"));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn round_trip(items: &[(usize, i32)], contexts: usize) -> Vec<u8> {
        let mut enc = StaticResidualEncoder::new(contexts);
        for (i, &(k, r)) in items.iter().enumerate() {
            enc.encode(k, i % 3, r);
        }
        enc.encode_raw(13, 0x1ABC);
        let bytes = enc.finish();
        let mut dec = StaticResidualDecoder::new(&bytes, contexts).unwrap();
        for (i, &(k, r)) in items.iter().enumerate() {
            let (back, length) = dec.decode_with_length(k, i % 3);
            assert_eq!(back, r, "context {k}");
            assert_eq!(length, 32 - r.unsigned_abs().leading_zeros());
        }
        assert_eq!(dec.decode_raw(13), 0x1ABC);
        dec.finish().unwrap();
        bytes
    }

    #[test]
    fn symbols_split_magnitudes_into_four_buckets_per_length() {
        for z in 0..8 {
            assert_eq!(symbol_of(z), (z, 0));
        }
        // 8..16: length 4, the two bits below the leading one in the symbol, one raw.
        assert_eq!(symbol_of(8), (8, 1));
        assert_eq!(symbol_of(9), (8, 1));
        assert_eq!(symbol_of(10), (9, 1));
        assert_eq!(symbol_of(15), (11, 1));
        assert_eq!(symbol_of(16), (12, 2));
        assert_eq!(symbol_of(u32::MAX), (123, 29));
        for z in (0..5000u32).chain([1 << 30, (1 << 31) - 1, 1 << 31, u32::MAX]) {
            let (s, extra) = symbol_of(z);
            let (base, e) = SYMBOL_BASE[s as usize];
            assert_eq!(e, extra, "{z}");
            assert_eq!(SYMBOL_LENGTH[s as usize], 32 - z.leading_zeros(), "{z}");
            assert_eq!(base | (z & ((1u64 << extra) - 1) as u32), z, "{z}");
        }
    }

    #[test]
    fn tables_sum_to_the_total_and_keep_every_seen_symbol() {
        let mut counts = [0u64; STATIC_SYMBOLS];
        // Every symbol seen once and one seen a million times: the floors push the sum
        // over and the excess comes off the big one.
        counts.iter_mut().for_each(|c| *c = 1);
        counts[5] = 1_000_000;
        let f = normalise(&counts);
        assert_eq!(f.iter().sum::<u32>(), TOTAL);
        assert!(f.iter().all(|&x| x >= 1));
        let mut one = [0u64; STATIC_SYMBOLS];
        one[7] = 3;
        let f = normalise(&one);
        assert_eq!(f[7], TOTAL);
        assert_eq!(f.iter().sum::<u32>(), TOTAL);
    }

    #[test]
    fn residuals_round_trip_across_contexts_and_extremes() {
        let mut items = Vec::new();
        for i in 0..10_000i32 {
            let r = (i * 7919 % 61) - 30;
            items.push(((i % 5) as usize, r));
        }
        for r in [i32::MIN, i32::MAX, -1, 1, 0, 1 << 30, -(1 << 30)] {
            items.push((2, r));
        }
        round_trip(&items, 5);
        // Nothing coded, one context with a single symbol (zero bits per residual).
        round_trip(&[], 3);
        let zeros: Vec<(usize, i32)> = (0..1000).map(|_| (1, 0)).collect();
        let bytes = round_trip(&zeros, 3);
        // Mask, a table of one symbol (its count in 7 bits, its frequency implied), four
        // states, no words, the 13 raw bits.
        assert_eq!(bytes.len(), 1 + 1 + 16 + 1 + 2, "{bytes:?}");
    }

    #[test]
    fn skewed_residuals_cost_about_their_entropy() {
        // Mostly small residuals: well under the 8 bits a byte each would take.
        let items: Vec<(usize, i32)> = (0..100_000)
            .map(|i: i32| (0, ((i.wrapping_mul(2_654_435_761u32 as i32) >> 28) % 3)))
            .collect();
        let bytes = round_trip(&items, 1);
        // Three near-equally likely magnitudes 0, 1, 2 with signs: about 2.3 bits each.
        let bits = bytes.len() as f64 * 8.0 / items.len() as f64;
        assert!(bits > 1.5 && bits < 3.0, "{bits} bits per residual");
    }

    #[test]
    fn corrupt_and_truncated_streams_are_refused_or_caught_at_the_end() {
        let items: Vec<(usize, i32)> = (0..2000).map(|i| (i % 3, (i as i32 % 17) - 8)).collect();
        let bytes = round_trip(&items, 3);
        // Every truncation either fails up front or fails the end check.
        for cut in 0..bytes.len() {
            let b = &bytes[..cut];
            if let Ok(mut dec) = StaticResidualDecoder::new(b, 3) {
                for (i, &(k, _)) in items.iter().enumerate() {
                    dec.decode(k, i % 3);
                }
                dec.decode_raw(13);
                assert!(dec.finish().is_err(), "cut at {cut}");
            }
        }
        // A table for a context the reader does not have.
        assert!(StaticResidualDecoder::new(&bytes, 2).is_err());
        // Bit flips never panic.
        for i in 0..bytes.len() {
            let mut b = bytes.clone();
            b[i] ^= 0x5A;
            if let Ok(mut dec) = StaticResidualDecoder::new(&b, 3) {
                for (i, &(k, _)) in items.iter().enumerate() {
                    dec.decode(k, i % 3);
                }
                let _ = dec.finish();
            }
        }
    }

    #[test]
    fn symbols_of_their_own_alphabet_round_trip_between_residuals() {
        let mut enc = StaticResidualEncoder::new(4);
        for i in 0..5000usize {
            enc.encode_symbol(i % 3, 0, (i * i) % 5);
            if i % 7 == 0 {
                enc.encode(3, 1, i as i32 - 2500);
            }
        }
        let bytes = enc.finish();
        let mut dec = StaticResidualDecoder::new(&bytes, 4).unwrap();
        for i in 0..5000usize {
            assert_eq!(dec.decode_symbol(i % 3, 0), (i * i) % 5);
            if i % 7 == 0 {
                assert_eq!(dec.decode(3, 1), i as i32 - 2500);
            }
        }
        dec.finish().unwrap();
    }

    proptest! {
        #[test]
        fn any_residuals_round_trip(items in proptest::collection::vec((0usize..4, any::<i32>()), 0..300),
                                    small in proptest::collection::vec((0usize..4, -40i32..40), 0..300)) {
            round_trip(&items, 4);
            round_trip(&small, 4);
        }
    }
}
