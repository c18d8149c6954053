//! Adaptive probability models for the range coder, and what a symbol costs under them.
//!
//! * [`BitModel`]: one adaptive binary probability (12 bits, updated by a shift of 5: fast
//!   enough to follow the label statistics of a mesh region, precise enough for the 0.01-bit
//!   symbols of a regular retiled mesh).
//! * [`BitTree`]: `n`-bit values coded bit by bit, each bit in the context of the bits above
//!   it (a binary decomposition of a `2^n`-symbol alphabet; the swing-angle coder uses it).
//! * [`SymbolModel`]: an adaptive frequency table for small alphabets (the CLERS labels).
//! * [`SignedIntModel`] / [`UnsignedIntModel`]: integers by bit length (adaptive), then
//!   the top mantissa bits (adaptive per length) and the rest raw (position residuals).
//!
//! All of them implement their coding on any [`BitSink`], so an encoder can run the very same
//! code on a [`crate::CostCounter`] to price a choice before committing it.

use crate::range_coder::{RangeDecoder, RangeEncoder};

/// Bits of probability precision.
pub const PROB_BITS: u32 = 12;
/// Probability scale: a [`BitModel`] holds P(bit = 0) in units of `1 / PROB_ONE`.
pub const PROB_ONE: u32 = 1 << PROB_BITS;
/// Initial probability (one half).
pub const PROB_INIT: u16 = (PROB_ONE / 2) as u16;
/// Adaptation speed: the probability moves `1 / 2^ADAPT_SHIFT` of the way to the seen bit.
pub const ADAPT_SHIFT: u32 = 5;

/// Something symbols can be coded into: the range encoder, or a cost counter.
pub trait BitSink {
    /// Codes one bit with an adaptive model (and updates it).
    fn encode_bit(&mut self, model: &mut BitModel, bit: bool);
    /// Codes `bits` raw bits of `value`.
    fn encode_direct(&mut self, value: u32, bits: u32);
    /// Codes a symbol with an adaptive frequency model (and updates it).
    fn encode_symbol(&mut self, model: &mut SymbolModel, symbol: usize);
    /// Codes the interval `[cum, cum + freq)` of a frequency table summing to `total`
    /// (`0 < freq`, `cum + freq <= total <= 2^16`); the caller updates its table.
    fn encode_interval(&mut self, cum: u32, freq: u32, total: u32);
    /// Codes one bit with a [`CountingBitModel`] (and updates it).
    fn encode_counting_bit(&mut self, model: &mut CountingBitModel, bit: bool);
    /// Codes a value through a bit tree.
    fn encode_tree(&mut self, tree: &mut BitTree, value: u32) {
        let bits = tree.bits();
        let mut node = 1usize;
        for i in (0..bits).rev() {
            let bit = (value >> i) & 1 == 1;
            self.encode_bit(tree.node(node), bit);
            node = (node << 1) | bit as usize;
        }
    }
}

impl BitSink for RangeEncoder {
    #[inline]
    fn encode_bit(&mut self, model: &mut BitModel, bit: bool) {
        RangeEncoder::encode_bit(self, model, bit)
    }
    #[inline]
    fn encode_direct(&mut self, value: u32, bits: u32) {
        RangeEncoder::encode_direct(self, value, bits)
    }
    #[inline]
    fn encode_symbol(&mut self, model: &mut SymbolModel, symbol: usize) {
        RangeEncoder::encode_symbol(self, model, symbol)
    }
    #[inline]
    fn encode_interval(&mut self, cum: u32, freq: u32, total: u32) {
        RangeEncoder::encode_interval(self, cum, freq, total)
    }
    #[inline]
    fn encode_tree(&mut self, tree: &mut BitTree, value: u32) {
        RangeEncoder::encode_tree(self, tree, value)
    }
    #[inline]
    fn encode_counting_bit(&mut self, model: &mut CountingBitModel, bit: bool) {
        RangeEncoder::encode_counting_bit(self, model, bit)
    }
}

/// An adaptive probability of a binary event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BitModel(u16);

impl Default for BitModel {
    fn default() -> Self {
        Self::new()
    }
}

impl BitModel {
    /// Starts at probability one half.
    pub const fn new() -> Self {
        BitModel(PROB_INIT)
    }

    /// P(bit = 0) in units of `1 / PROB_ONE`; always in `[31, PROB_ONE - 31]`.
    #[inline]
    pub fn p0(&self) -> u16 {
        self.0
    }

    /// Moves the probability towards the bit just seen.
    #[inline]
    pub fn update(&mut self, bit: bool) {
        // Both moves computed and one masked away: decoded bits are often unpredictable,
        // and a branch on them costs more than the arithmetic.
        let one = 0u16.wrapping_sub(bit as u16);
        let down = self.0 >> ADAPT_SHIFT;
        let up = ((PROB_ONE as u16) - self.0) >> ADAPT_SHIFT;
        self.0 = self.0.wrapping_add(up & !one).wrapping_sub(down & one);
    }

    /// Cost of coding `bit` now, in 1/[`crate::COST_ONE`] bits (without updating).
    #[inline]
    pub fn cost(&self, bit: bool) -> u32 {
        let p = if bit {
            PROB_ONE - self.0 as u32
        } else {
            self.0 as u32
        };
        crate::cost::price(p)
    }
}

/// Probability precision of a [`CountingBitModel`].
pub const COUNTING_PROB_BITS: u32 = 15;
const COUNTING_ONE: u32 = 1 << COUNTING_PROB_BITS;
/// Nearest a [`CountingBitModel`] gets to certainty, in `1 / 2^15`.
const COUNTING_MARGIN: u32 = 32;

/// An adaptive probability of a binary event that learns fast while it has seen little and
/// then settles: after its `n`-th bit it moves `1 / 2^s` of the way to the bit seen, with
/// `s` = 1 for `n` < 2, 2 below 5, 3 below 10, 4 below 22, 5 below 44 and 6 from then on
/// (about `1 / (n + 1.5)`, the step of a count-based estimate, until the window reaches 64
/// bits). A [`BitModel`]'s fixed `1 / 32` pays dearly for its first bits when a coder
/// spreads its bits over hundreds of contexts; this one does not. P(bit = 0) is held in
/// `1 / 2^15`, within `[32, 2^15 − 32]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CountingBitModel {
    p0: u16,
    seen: u8,
}

impl Default for CountingBitModel {
    fn default() -> Self {
        Self::new()
    }
}

impl CountingBitModel {
    /// Bits seen after which the rate stays at its slowest.
    const SETTLED: u8 = 44;

    /// Starts at probability one half, having seen nothing.
    pub const fn new() -> Self {
        CountingBitModel {
            p0: (COUNTING_ONE / 2) as u16,
            seen: 0,
        }
    }

    /// P(bit = 0) in units of `1 / 2^15`.
    #[inline]
    pub fn p0(&self) -> u32 {
        self.p0 as u32
    }

    /// The rate shift after `n` bits: round(log2(n + 1.5)) clamped to 1..=6
    /// (docs/format.md), tabulated.
    const SHIFTS: [u8; Self::SETTLED as usize + 1] = {
        let mut t = [0u8; Self::SETTLED as usize + 1];
        let mut n = 0;
        while n < t.len() {
            t[n] = 1
                + (n >= 2) as u8
                + (n >= 5) as u8
                + (n >= 10) as u8
                + (n >= 22) as u8
                + (n >= Self::SETTLED as usize) as u8;
            n += 1;
        }
        t
    };

    /// The rate shift for the next update.
    #[inline]
    fn shift(&self) -> u32 {
        // `seen` never passes SETTLED: the index is in range.
        Self::SHIFTS[(self.seen as usize).min(Self::SETTLED as usize)] as u32
    }

    /// Moves the probability towards the bit just seen.
    #[inline]
    pub fn update(&mut self, bit: bool) {
        let s = self.shift();
        let p = self.p0 as u32;
        let p = if bit {
            p - (p >> s)
        } else {
            p + ((COUNTING_ONE - p) >> s)
        };
        self.p0 = p.clamp(COUNTING_MARGIN, COUNTING_ONE - COUNTING_MARGIN) as u16;
        self.seen = (self.seen + 1).min(Self::SETTLED);
    }

    /// Cost of coding `bit` now, in 1/[`crate::COST_ONE`] bits (without updating).
    #[inline]
    pub fn cost(&self, bit: bool) -> u32 {
        let p = if bit {
            COUNTING_ONE - self.p0 as u32
        } else {
            self.p0 as u32
        };
        crate::cost::ratio_cost(p, COUNTING_ONE)
    }
}

/// `n`-bit values coded MSB first, each bit with its own model chosen by the bits above it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct BitTree {
    bits: u32,
    nodes: Vec<BitModel>,
}

impl BitTree {
    /// A tree for values below `2^bits` (`bits` from 1 to 16).
    pub fn new(bits: u32) -> Self {
        let bits = bits.clamp(1, 16);
        BitTree {
            bits,
            nodes: vec![BitModel::new(); 1 << bits],
        }
    }

    /// Number of bits per value.
    #[inline]
    pub fn bits(&self) -> u32 {
        self.bits
    }

    /// The model of internal node `i` (1-based heap order).
    #[inline]
    pub fn node(&mut self, i: usize) -> &mut BitModel {
        // Callers walk from node 1 down `bits` levels, so i < 2^bits; the mask (the length
        // is a power of two) keeps a hypothetical misuse from panicking, and unlike a
        // modulo it adds no division to the chain from one decoded bit to the next.
        let mask = self.nodes.len() - 1;
        &mut self.nodes[i & mask]
    }

    /// Cost of coding `value` now, in 1/[`crate::COST_ONE`] bits.
    pub fn cost(&self, value: u32) -> u32 {
        let mut node = 1usize;
        let mut c = 0;
        for i in (0..self.bits).rev() {
            let bit = (value >> i) & 1 == 1;
            c += self.nodes[node & (self.nodes.len() - 1)].cost(bit);
            node = (node << 1) | bit as usize;
        }
        c
    }
}

/// Adaptive frequency model for a small alphabet (up to 64 symbols).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SymbolModel {
    freq: Vec<u32>,
    total: u32,
}

impl SymbolModel {
    /// Largest total before counts are halved; keeps `range / total >= 2^8`.
    const LIMIT: u32 = 1 << 16;
    /// Count added per occurrence.
    const STEP: u32 = 32;

    /// A model of `n` equally likely symbols (`n` clamped to 1..=64).
    pub fn new(n: usize) -> Self {
        let n = n.clamp(1, 64);
        SymbolModel {
            freq: vec![1; n],
            total: n as u32,
        }
    }

    /// Alphabet size.
    pub fn len(&self) -> usize {
        self.freq.len()
    }

    /// Always false: a model has at least one symbol.
    pub fn is_empty(&self) -> bool {
        self.freq.is_empty()
    }

    /// Sum of the counts.
    #[inline]
    pub fn total(&self) -> u32 {
        self.total
    }

    /// `(cumulative count below, count, total)` of `symbol` (clamped into the alphabet).
    #[inline]
    pub fn interval(&self, symbol: usize) -> (u32, u32, u32) {
        let s = symbol.min(self.freq.len() - 1);
        let cum: u32 = self.freq[..s].iter().sum();
        (cum, self.freq[s], self.total)
    }

    /// The symbol whose interval holds `target` (< total): `(symbol, cum, freq)`.
    #[inline]
    pub fn find(&self, target: u32) -> (usize, u32, u32) {
        let mut cum = 0;
        for (s, &f) in self.freq.iter().enumerate() {
            if target < cum + f {
                return (s, cum, f);
            }
            cum += f;
        }
        // target >= total cannot happen (the decoder clamps); answer the last symbol.
        let last = self.freq.len() - 1;
        (last, self.total - self.freq[last], self.freq[last])
    }

    /// [`Self::find`] of `min(code / r, total - 1)`, by multiplication: the first symbol
    /// whose scaled upper end `r (cum + freq)` lies above `code`, else the last one. `r` is at
    /// most `u32::MAX / total` (a range coder's `range / total`), so no product overflows.
    #[inline]
    pub fn find_scaled(&self, code: u32, r: u32) -> (usize, u32, u32) {
        let mut cum = 0;
        for (s, &f) in self.freq.iter().enumerate() {
            if code < r * (cum + f) {
                return (s, cum, f);
            }
            cum += f;
        }
        let last = self.freq.len() - 1;
        (last, self.total - self.freq[last], self.freq[last])
    }

    /// Counts one more occurrence of `symbol`.
    #[inline]
    pub fn update(&mut self, symbol: usize) {
        let s = symbol.min(self.freq.len() - 1);
        self.freq[s] += Self::STEP;
        self.total += Self::STEP;
        if self.total > Self::LIMIT {
            self.total = 0;
            for f in &mut self.freq {
                *f = (*f).div_ceil(2);
                self.total += *f;
            }
        }
    }

    /// Cost of coding `symbol` now, in 1/[`crate::COST_ONE`] bits.
    pub fn cost(&self, symbol: usize) -> u32 {
        let (_, f, t) = self.interval(symbol);
        crate::cost::ratio_cost(f, t)
    }
}

/// Many adaptive frequency tables over one small alphabet, in one flat array: the counting
/// rule of [`SymbolModel`] (counts start at 1, each occurrence adds 32, the table halves when
/// its total passes 2^16) for coders that pick one of thousands of contexts per symbol, where
/// a [`SymbolModel`] each would cost an allocation per context.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SymbolTables {
    symbols: usize,
    freq: Vec<u32>,
    total: Vec<u32>,
}

impl SymbolTables {
    /// `tables` tables (at least one) of `symbols` equally likely symbols (`symbols` clamped
    /// to 1..=64).
    pub fn new(tables: usize, symbols: usize) -> Self {
        let symbols = symbols.clamp(1, 64);
        let tables = tables.max(1);
        SymbolTables {
            symbols,
            freq: vec![1; tables * symbols],
            total: vec![symbols as u32; tables],
        }
    }

    /// Number of tables.
    pub fn len(&self) -> usize {
        self.total.len()
    }

    /// Always false: a set has at least one table.
    pub fn is_empty(&self) -> bool {
        self.total.is_empty()
    }

    /// Codes `symbol` (clamped into the alphabet) with table `table` (clamped into range),
    /// then counts it.
    #[inline]
    pub fn encode<S: BitSink>(&mut self, sink: &mut S, table: usize, symbol: usize) {
        let t = table.min(self.total.len() - 1);
        let s = symbol.min(self.symbols - 1);
        let row = &self.freq[t * self.symbols..(t + 1) * self.symbols];
        let cum: u32 = row[..s].iter().sum();
        sink.encode_interval(cum, row[s], self.total[t]);
        self.update(t, s);
    }

    /// Decodes a symbol coded with table `table` by [`SymbolTables::encode`], then counts it.
    #[inline]
    pub fn decode(&mut self, dec: &mut RangeDecoder<'_>, table: usize) -> usize {
        let t = table.min(self.total.len() - 1);
        let n = self.symbols;
        let total = self.total[t];
        // One slice for the search and the count (the decoder's hot path: one bounds check).
        let row = &mut self.freq[t * n..(t + 1) * n];
        // Found by multiplication (`decode_scaled_with`): one division on the chain from
        // label to label instead of two.
        let s = dec.decode_scaled_with(total, |code, r| {
            let mut cum = 0;
            for (s, &f) in row.iter().enumerate() {
                if code < r * (cum + f) {
                    return (s, cum, f);
                }
                cum += f;
            }
            // Only a corrupt stream gets here: the last symbol, as a clamped target gives.
            (n - 1, cum - row[n - 1], row[n - 1])
        });
        self.total[t] = Self::count(row, s, total);
        s
    }

    /// Counts `s` in `row` whose counts sum to `total`; the new total.
    #[inline]
    fn count(row: &mut [u32], s: usize, total: u32) -> u32 {
        if let Some(f) = row.get_mut(s) {
            *f += SymbolModel::STEP;
        }
        let total = total + SymbolModel::STEP;
        if total <= SymbolModel::LIMIT {
            return total;
        }
        let mut halved = 0;
        for f in row.iter_mut() {
            *f = (*f).div_ceil(2);
            halved += *f;
        }
        halved
    }

    /// Cost of coding `symbol` with table `table` now, in 1/[`crate::COST_ONE`] bits.
    pub fn cost(&self, table: usize, symbol: usize) -> u32 {
        let t = table.min(self.total.len() - 1);
        let s = symbol.min(self.symbols - 1);
        crate::cost::ratio_cost(self.freq[t * self.symbols + s], self.total[t])
    }

    #[inline]
    fn update(&mut self, t: usize, s: usize) {
        let row = &mut self.freq[t * self.symbols..(t + 1) * self.symbols];
        self.total[t] = Self::count(row, s, self.total[t]);
    }
}

/// Adaptive code for unsigned integers: the bit length through a bit tree, the two bits below
/// the leading one with models per length, the rest raw.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UnsignedIntModel {
    length: BitTree,
    mantissa: Vec<[BitModel; 3]>,
}

impl Default for UnsignedIntModel {
    fn default() -> Self {
        Self::new()
    }
}

impl UnsignedIntModel {
    /// Modelled mantissa bits below the leading one.
    const MODELLED: u32 = 2;

    /// A fresh model for any `u32`.
    pub fn new() -> Self {
        UnsignedIntModel {
            length: BitTree::new(6),
            mantissa: vec![[BitModel::new(); 3]; 33],
        }
    }

    /// A fresh model for values below `2^31` only: the bit length then fits a 5-level tree,
    /// one binary decision fewer per value. Larger values are coded as `2^31 - 1`; callers
    /// guarantee they never occur (e.g. residuals of clamped predictions).
    pub fn below_2_31() -> Self {
        UnsignedIntModel {
            length: BitTree::new(5),
            mantissa: vec![[BitModel::new(); 3]; 33],
        }
    }

    /// Codes `v`.
    pub fn encode<S: BitSink>(&mut self, sink: &mut S, v: u32) {
        let v = if self.length.bits() < 6 {
            v.min((1 << 31) - 1)
        } else {
            v
        };
        let len = 32 - v.leading_zeros();
        sink.encode_tree(&mut self.length, len);
        if len > 1 {
            let rest = len - 1;
            let modelled = rest.min(Self::MODELLED);
            let models = &mut self.mantissa[len as usize];
            // Top modelled bits, the second one in the context of the first.
            let mut ctx = 0usize;
            for i in 0..modelled {
                let bit = (v >> (rest - 1 - i)) & 1 == 1;
                sink.encode_bit(&mut models[ctx.min(2)], bit);
                ctx = 1 + bit as usize;
            }
            let raw = rest - modelled;
            if raw > 0 {
                sink.encode_direct(v & ((1u32 << raw) - 1), raw);
            }
        }
    }

    /// Decodes a value coded by [`UnsignedIntModel::encode`].
    pub fn decode(&mut self, d: &mut RangeDecoder<'_>) -> u32 {
        let len = d.decode_tree(&mut self.length).min(32);
        if len == 0 {
            return 0;
        }
        let rest = len - 1;
        let mut v: u64 = 1;
        let modelled = rest.min(Self::MODELLED);
        let models = &mut self.mantissa[len as usize];
        let mut ctx = 0usize;
        for _ in 0..modelled {
            let bit = d.decode_bit(&mut models[ctx.min(2)]);
            v = (v << 1) | bit as u64;
            ctx = 1 + bit as usize;
        }
        let raw = rest - modelled;
        if raw > 0 {
            v = (v << raw) | d.decode_direct(raw) as u64;
        }
        v as u32
    }

    /// Cost of coding `v` now, in 1/[`crate::COST_ONE`] bits.
    pub fn cost(&self, v: u32) -> u32 {
        let len = 32 - v.leading_zeros();
        let mut c = self.length.cost(len);
        if len > 1 {
            let rest = len - 1;
            let modelled = rest.min(Self::MODELLED);
            let models = &self.mantissa[len as usize];
            let mut ctx = 0usize;
            for i in 0..modelled {
                let bit = (v >> (rest - 1 - i)) & 1 == 1;
                c += models[ctx.min(2)].cost(bit);
                ctx = 1 + bit as usize;
            }
            c += (rest - modelled) * crate::COST_ONE;
        }
        c
    }
}

/// Adaptive code for signed integers: magnitude as [`UnsignedIntModel`], then an adaptive
/// sign bit.
#[derive(Clone, Debug, PartialEq, Eq, Default)]
pub struct SignedIntModel {
    magnitude: UnsignedIntModel,
    sign: BitModel,
}

impl SignedIntModel {
    /// A fresh model for any `i32`.
    pub fn new() -> Self {
        Self::default()
    }

    /// A fresh model for magnitudes below `2^31` (see [`UnsignedIntModel::below_2_31`]).
    pub fn below_2_31() -> Self {
        SignedIntModel {
            magnitude: UnsignedIntModel::below_2_31(),
            sign: BitModel::new(),
        }
    }

    /// Codes `v`.
    pub fn encode<S: BitSink>(&mut self, sink: &mut S, v: i32) {
        self.magnitude.encode(sink, v.unsigned_abs());
        if v != 0 {
            sink.encode_bit(&mut self.sign, v < 0);
        }
    }

    /// Decodes a value coded by [`SignedIntModel::encode`]. Garbage input gives some value,
    /// never a panic.
    pub fn decode(&mut self, d: &mut RangeDecoder<'_>) -> i32 {
        let m = self.magnitude.decode(d);
        if m == 0 {
            return 0;
        }
        let negative = d.decode_bit(&mut self.sign);
        if negative {
            (m as i32).wrapping_neg()
        } else {
            m as i32
        }
    }

    /// Cost of coding `v` now, in 1/[`crate::COST_ONE`] bits.
    pub fn cost(&self, v: i32) -> u32 {
        let mut c = self.magnitude.cost(v.unsigned_abs());
        if v != 0 {
            c += self.sign.cost(v < 0);
        }
        c
    }
}
