//! The position-residual code of the exact mode, built for decoding speed: the bit length of
//! a residual is one multi-symbol decision (an adaptive cumulative-frequency model with a
//! power-of-two total, so no division, as AV1's adaptive CDFs), where a binary tree takes
//! five; the raw mantissa bits are one range-coder step, not one per bit.
//!
//! * [`CdfModel`]: 32 symbols, 15-bit cumulative frequencies, every symbol at least 1/2^15;
//!   after each symbol every cumulative count moves a `1 / 2^rate` part of the way to the
//!   step at that symbol, the rate growing from 3 to 6 over the first 24 symbols (fast
//!   learning, then a stable estimate).
//! * [`ResidualModel`]: a signed integer below `2^31` in magnitude: bit length through a
//!   [`CdfModel`], the two bits below the leading one with adaptive binary models per length,
//!   the rest raw in one step, then an adaptive sign bit.

use crate::models::{BitModel, PROB_BITS};
use crate::range_coder::{RangeDecoder, RangeEncoder};

/// Alphabet size of a [`CdfModel`].
pub const CDF_SYMBOLS: usize = 32;
/// Bits of the cumulative frequencies.
pub(crate) const CDF_BITS: u32 = 15;
/// Adaptive part of the total: each symbol also holds a fixed count of one.
const CDF_SPAN: u16 = (1 << CDF_BITS) - CDF_SYMBOLS as u16;
/// Adaptation rate: `RATE_MIN` for the first `RATE_STEP` symbols, one slower after each
/// further `RATE_STEP`, `RATE_STEPS` times (3, 4, 5, then 6 from the 25th symbol on).
const RATE_MIN: u32 = 3;
const RATE_STEPS: u32 = 3;
const RATE_STEP: u8 = 8;

/// Adaptive model of a 32-symbol alphabet.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CdfModel {
    /// Adaptive cumulative counts below each symbol (`c[0] = 0`, `c[32] = CDF_SPAN`,
    /// non-decreasing); the coded cumulative frequency below `s` is `c[s] + s`.
    c: [u16; CDF_SYMBOLS + 1],
    /// Symbols seen, saturating (sets the adaptation rate).
    count: u8,
    /// Whether some count above the first [`CDF_LANES`] may still rise: while none can, an
    /// update below [`CDF_LANES`] touches only those (see [`CdfModel::update`]).
    wide: bool,
}

/// Per symbol `s` (0..=32), the mask of the counts that rise: all ones in the lanes above `s`.
/// A load, where a compare of the lane index with `s` came out as 32-bit compares packed back
/// to 16 bits, and, once the compiler knew `s` small, as a mix of scalar and vector code.
static RISE_MASKS: [[u16; CDF_SYMBOLS]; CDF_SYMBOLS + 1] = {
    let mut m = [[0u16; CDF_SYMBOLS]; CDF_SYMBOLS + 1];
    let mut s = 0;
    while s <= CDF_SYMBOLS {
        let mut lane = s + 1;
        while lane < CDF_SYMBOLS {
            m[s][lane] = u16::MAX;
            lane += 1;
        }
        s += 1;
    }
    m
};

/// Moves the counts `x` towards the symbol whose [`RISE_MASKS`] row is `rise`: those the mask
/// selects rise, the rest fall, each by `1 / 2^rate` of its distance. Branch-free over whole
/// vectors, so that it vectorises.
#[inline(always)]
fn update_lanes<const N: usize>(x: &mut [u16; N], rise: &[u16; N], rate: u32) {
    for (x, &rise) in x.iter_mut().zip(rise) {
        let up = (CDF_SPAN - *x) >> rate;
        let down = *x >> rate;
        *x = x.wrapping_add(up & rise).wrapping_sub(down & !rise);
    }
}

/// The counts an update touches while the others cannot move (eight 16-bit lanes: one SSE2
/// register).
const CDF_LANES: usize = 8;

impl Default for CdfModel {
    fn default() -> Self {
        Self::new()
    }
}

impl CdfModel {
    /// All symbols equally likely.
    pub fn new() -> Self {
        let mut c = [0u16; CDF_SYMBOLS + 1];
        for (i, x) in c.iter_mut().enumerate() {
            *x = (CDF_SPAN as u32 * i as u32 / CDF_SYMBOLS as u32) as u16;
        }
        CdfModel {
            c,
            count: 0,
            wide: true,
        }
    }

    /// Cumulative frequency below symbol `s` (`s <= 32`), out of `2^15`.
    #[inline(always)]
    fn cum(&self, s: usize) -> u32 {
        self.c[s] as u32 + s as u32
    }

    /// Moves the estimate towards `s`.
    ///
    /// Never inlined: one compiled copy, vectorised. Inlined at every call site, some
    /// copies came out as scalar loops (about eight times the instructions).
    #[inline(never)]
    pub fn update(&mut self, s: usize) {
        self.update_in_line(s)
    }

    /// [`CdfModel::update`] inlined, for the coder's hot call sites (`encode_cdf`,
    /// `decode_cdf`).
    #[inline(always)]
    fn update_in_line(&mut self, s: usize) {
        let rate = RATE_MIN + (self.count / RATE_STEP) as u32;
        if (self.count as u32) < RATE_STEP as u32 * RATE_STEPS {
            self.count += 1;
        }
        // Entries above s rise, the rest fall ([`update_lanes`]). c[0] = 0 stays 0 (it falls
        // by 0 >> rate); c[32] = CDF_SPAN is left alone (it would rise by 0).
        //
        // A count above `s` rises by `(CDF_SPAN - x) >> rate`, which is 0 once it is within
        // `2^rate` of the top; the rate never falls, so such a count stays put until a symbol
        // at or above it makes it fall. While every count above the first vector stays put,
        // a symbol below [`CDF_LANES`] updates the first vector alone (a skewed source, as
        // residual lengths are, lives there): the counts come out the same as if all moved.
        let s = s.min(CDF_SYMBOLS);
        // Each mask row is copied out first: a local the counts cannot alias (read in place,
        // the vectorised loop came with a runtime overlap check and a scalar fallback).
        let (head, _) = self
            .c
            .split_first_chunk_mut::<CDF_SYMBOLS>()
            .expect("33 counts");
        if !self.wide && s < CDF_LANES {
            let (low, _) = head
                .split_first_chunk_mut::<CDF_LANES>()
                .expect("32 counts");
            let rise: [u16; CDF_LANES] = *RISE_MASKS[s].first_chunk().expect("32 masks");
            update_lanes(low, &rise, rate);
        } else {
            let rise: [u16; CDF_SYMBOLS] = RISE_MASKS[s];
            update_lanes(head, &rise, rate);
            // Whether a count above the first vector can still rise at this rate (an OR, no
            // early exit: it vectorises).
            let room = head[CDF_LANES..]
                .iter()
                .fold(0u16, |m, &x| m | ((CDF_SPAN - x) >> rate));
            self.wide = room != 0;
        }
    }

    /// Cost of coding `s` now, in 1/[`crate::COST_ONE`] bits.
    #[inline]
    pub fn cost(&self, s: usize) -> u32 {
        let s = s.min(CDF_SYMBOLS - 1);
        let f = self.cum(s + 1) - self.cum(s);
        // A 15-bit probability priced through the 12-bit table.
        let shift = (32 - f.leading_zeros()).saturating_sub(PROB_BITS);
        crate::cost::price(f >> shift) + (CDF_BITS - PROB_BITS - shift) * crate::COST_ONE
    }
}

impl RangeEncoder {
    /// Codes symbol `s` (below 32) with an adaptive [`CdfModel`], updating it.
    #[inline]
    pub fn encode_cdf(&mut self, model: &mut CdfModel, s: usize) {
        let s = s.min(CDF_SYMBOLS - 1);
        let r = self.range >> CDF_BITS;
        let lo = r * model.cum(s);
        // The last symbol takes what the power-of-two total leaves over.
        let range = if s == CDF_SYMBOLS - 1 {
            self.range - lo
        } else {
            r * (model.cum(s + 1) - model.cum(s))
        };
        self.add_low(lo);
        self.range = range;
        model.update_in_line(s);
        self.normalize_pub();
    }

    /// Codes the low `bits` bits of `value` (`bits` at most 32) as equiprobable, 12 at a
    /// time in one step each.
    #[inline]
    pub fn encode_bits(&mut self, value: u32, bits: u32) {
        let mut left = bits.min(32);
        while left > 0 {
            let n = left.min(12);
            left -= n;
            let chunk = (value >> left) & ((1u32 << n) - 1);
            self.range >>= n;
            self.add_low(self.range * chunk);
            self.normalize_pub();
        }
    }
}

impl RangeDecoder<'_> {
    /// Decodes a symbol coded with [`RangeEncoder::encode_cdf`].
    #[inline]
    pub fn decode_cdf(&mut self, model: &mut CdfModel) -> usize {
        let r = self.range >> CDF_BITS;
        let code = self.code;
        // r * cum < 2^17 * 2^15: no overflow. Lengths are mostly small: search upwards.
        let mut s = 0usize;
        while s + 1 < CDF_SYMBOLS && r * model.cum(s + 1) <= code {
            s += 1;
        }
        let lo = r * model.cum(s);
        let range = if s == CDF_SYMBOLS - 1 {
            self.range.wrapping_sub(lo)
        } else {
            r * (model.cum(s + 1) - model.cum(s))
        };
        // A corrupt stream may break `code < range`; wrapping keeps it garbage, not a panic.
        self.code = code.wrapping_sub(lo);
        self.range = range.max(1);
        model.update_in_line(s);
        self.normalize_pub();
        s
    }

    /// Decodes `bits` equiprobable bits coded with [`RangeEncoder::encode_bits`].
    #[inline]
    pub fn decode_bits(&mut self, bits: u32) -> u32 {
        let mut left = bits.min(32);
        let mut v = 0u32;
        while left > 0 {
            let n = left.min(12);
            left -= n;
            self.range >>= n;
            // range >= 2^12 here; a corrupt stream may give a quotient past the chunk.
            let chunk = (self.code / self.range.max(1)).min((1u32 << n) - 1);
            self.code = self.code.wrapping_sub(chunk * self.range);
            v = v.checked_shl(n).unwrap_or(0) | chunk;
            self.normalize_pub();
        }
        v
    }
}

/// Adaptive code of a signed residual below `2^31` in magnitude (larger magnitudes are coded
/// as `2^31 - 1`; callers guarantee they never occur).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ResidualModel {
    length: CdfModel,
    mantissa: [[BitModel; 3]; CDF_SYMBOLS],
    sign: BitModel,
}

impl Default for ResidualModel {
    fn default() -> Self {
        Self::new()
    }
}

impl ResidualModel {
    /// Modelled mantissa bits below the leading one.
    const MODELLED: u32 = 2;

    /// A fresh model.
    pub fn new() -> Self {
        ResidualModel {
            length: CdfModel::new(),
            mantissa: [[BitModel::new(); 3]; CDF_SYMBOLS],
            sign: BitModel::new(),
        }
    }

    /// Codes `v`.
    #[inline]
    pub fn encode(&mut self, e: &mut RangeEncoder, v: i32) {
        let m = v.unsigned_abs().min((1 << 31) - 1);
        let len = 32 - m.leading_zeros();
        e.encode_cdf(&mut self.length, len as usize);
        if len > 1 {
            let rest = len - 1;
            let modelled = rest.min(Self::MODELLED);
            let models = &mut self.mantissa[len as usize];
            let mut ctx = 0usize;
            for i in 0..modelled {
                let bit = (m >> (rest - 1 - i)) & 1 == 1;
                e.encode_bit(&mut models[ctx], bit);
                ctx = 1 + bit as usize;
            }
            let raw = rest - modelled;
            if raw > 0 {
                e.encode_bits(m & ((1u32 << raw) - 1), raw);
            }
        }
        if m != 0 {
            e.encode_bit(&mut self.sign, v < 0);
        }
    }

    /// Decodes a value coded by [`ResidualModel::encode`]; garbage input gives some value,
    /// never a panic.
    #[inline]
    pub fn decode(&mut self, d: &mut RangeDecoder<'_>) -> i32 {
        let len = d.decode_cdf(&mut self.length) as u32;
        if len == 0 {
            return 0;
        }
        let rest = len - 1;
        let mut m: u32 = 1;
        let modelled = rest.min(Self::MODELLED);
        let models = &mut self.mantissa[len as usize];
        let mut ctx = 0usize;
        for _ in 0..modelled {
            let bit = d.decode_bit(&mut models[ctx]);
            m = (m << 1) | bit as u32;
            ctx = 1 + bit as usize;
        }
        let raw = rest - modelled;
        if raw > 0 {
            m = (m << raw) | d.decode_bits(raw);
        }
        let m = m as i32; // len <= 31, so m < 2^31
        if d.decode_bit(&mut self.sign) {
            m.wrapping_neg()
        } else {
            m
        }
    }

    /// Cost of coding `v` now, in 1/[`crate::COST_ONE`] bits.
    #[inline]
    pub fn cost(&self, v: i32) -> u32 {
        let m = v.unsigned_abs().min((1 << 31) - 1);
        let len = 32 - m.leading_zeros();
        let mut c = self.length.cost(len as usize);
        if len > 1 {
            let rest = len - 1;
            let modelled = rest.min(Self::MODELLED);
            let models = &self.mantissa[len as usize];
            let mut ctx = 0usize;
            for i in 0..modelled {
                let bit = (m >> (rest - 1 - i)) & 1 == 1;
                c += models[ctx].cost(bit);
                ctx = 1 + bit as usize;
            }
            c += (rest - modelled) * crate::COST_ONE;
        }
        if m != 0 {
            c += self.sign.cost(v < 0);
        }
        c
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #[test]
        fn residuals_round_trip(vals in proptest::collection::vec(
            prop_oneof![-40i32..40, any::<i32>().prop_map(|v| v / 2)], 0..600)) {
            let mut e = RangeEncoder::new();
            let mut m = ResidualModel::new();
            let mut raw = Vec::new();
            for (i, &v) in vals.iter().enumerate() {
                m.encode(&mut e, v);
                let bits = (i % 33) as u32;
                let r = (v as u32) & if bits == 32 { u32::MAX } else { (1u32 << bits) - 1 };
                e.encode_bits(r, bits);
                raw.push((r, bits));
            }
            let bytes = e.finish();
            let mut d = RangeDecoder::new(&bytes).unwrap();
            let mut m = ResidualModel::new();
            for (&v, &(r, bits)) in vals.iter().zip(&raw) {
                prop_assert_eq!(m.decode(&mut d), v);
                prop_assert_eq!(d.decode_bits(bits), r);
            }
            prop_assert!(d.finish().is_ok());
        }

        #[test]
        fn garbage_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..64)) {
            let mut input = bytes.clone();
            if let Some(b) = input.first_mut() { *b = 0; }
            if let Ok(mut d) = RangeDecoder::new(&input) {
                let mut m = ResidualModel::new();
                for _ in 0..300 {
                    m.decode(&mut d);
                    d.decode_bits(23);
                }
                let _ = d.finish();
            }
        }
    }

    /// The update as docs/codec.md ("Exact mode geometry") states it: every count moves.
    fn reference_update(c: &mut [u16; CDF_SYMBOLS + 1], count: &mut u8, s: usize) {
        let rate = RATE_MIN + (*count / RATE_STEP) as u32;
        if (*count as u32) < RATE_STEP as u32 * RATE_STEPS {
            *count += 1;
        }
        for (i, x) in c.iter_mut().enumerate().take(CDF_SYMBOLS) {
            if i > s {
                *x += (CDF_SPAN - *x) >> rate;
            } else {
                *x -= *x >> rate;
            }
        }
    }

    proptest! {
        #[test]
        fn skipping_settled_counts_changes_no_count(
            symbols in proptest::collection::vec(
                prop_oneof![8 => 0usize..6, 1 => 0usize..40], 0..2000)
        ) {
            let mut model = CdfModel::new();
            let (mut c, mut count) = (model.c, 0u8);
            for s in symbols {
                model.update(s);
                reference_update(&mut c, &mut count, s.min(CDF_SYMBOLS));
                prop_assert_eq!(model.c, c);
            }
        }
    }

    #[test]
    fn a_skewed_source_settles_the_upper_counts() {
        // Small symbols only: the counts above the first vector stop moving, and updates
        // then touch the first vector alone; a large symbol wakes them up again.
        let mut model = CdfModel::new();
        for i in 0..2000usize {
            model.update(i % 4);
        }
        assert!(!model.wide);
        model.update(20);
        assert!(model.wide);
    }

    #[test]
    fn model_stays_a_distribution() {
        let mut m = CdfModel::new();
        for i in 0..5000usize {
            m.update(if i % 7 == 0 { 31 } else { i % 5 });
            for s in 0..CDF_SYMBOLS {
                assert!(m.cum(s + 1) > m.cum(s));
            }
            assert_eq!(m.cum(CDF_SYMBOLS), 1 << CDF_BITS);
        }
        // A skewed source is learnt: its common symbol costs well under a bit.
        assert!(m.cost(0) < crate::COST_ONE * 3);
    }
}
