//! The adaptive binary range coder every whet stream goes through (connectivity labels, swing
//! angles, position residuals).
//!
//! The coder is the carry-propagating byte-oriented range coder of Schindler/Martin, in the
//! arrangement the LZMA family uses: a 32-bit range, a 33-bit low with a cached byte and a run
//! of pending 0xFF bytes for the carry, 11-bit adaptive bit probabilities updated by a shift of
//! 5. Everything is integer arithmetic, so the output is the same on every machine.
//!
//! Invariants: after `normalize`, `range >= 2^24`. The encoder emits one leading zero byte
//! (the initial cache) which the decoder checks, and flushes five bytes at the end, so a decoder
//! never needs bytes past the end of a complete stream; reading past it means the stream is
//! truncated, which [`RangeDecoder::finish`] reports. A corrupted stream decodes to garbage
//! symbols but never panics.

use crate::models::{
    BitModel, BitTree, CountingBitModel, SymbolModel, COUNTING_PROB_BITS, PROB_BITS, PROB_INIT,
};
use crate::Error;

const TOP: u32 = 1 << 24;

/// Encodes symbols into bytes.
#[derive(Clone, Debug)]
pub struct RangeEncoder {
    low: u64,
    pub(crate) range: u32,
    cache: u8,
    cache_size: u64,
    out: Vec<u8>,
}

impl Default for RangeEncoder {
    fn default() -> Self {
        Self::new()
    }
}

impl RangeEncoder {
    /// A fresh encoder.
    pub fn new() -> Self {
        RangeEncoder {
            low: 0,
            range: u32::MAX,
            cache: 0,
            cache_size: 1,
            out: Vec::new(),
        }
    }

    /// Bytes emitted so far (the final size is this plus at most five).
    pub fn bytes_written(&self) -> usize {
        self.out.len() + self.cache_size as usize
    }

    #[inline]
    fn shift_low(&mut self) {
        if (self.low as u32) < 0xFF00_0000 || (self.low >> 32) != 0 {
            let carry = (self.low >> 32) as u8;
            let mut temp = self.cache;
            loop {
                self.out.push(temp.wrapping_add(carry));
                temp = 0xFF;
                self.cache_size -= 1;
                if self.cache_size == 0 {
                    break;
                }
            }
            self.cache = ((self.low >> 24) & 0xFF) as u8;
        }
        self.cache_size += 1;
        self.low = (self.low & 0x00FF_FFFF) << 8;
    }

    #[inline]
    fn normalize(&mut self) {
        while self.range < TOP {
            self.range <<= 8;
            self.shift_low();
        }
    }

    #[inline(always)]
    pub(crate) fn add_low(&mut self, x: u32) {
        self.low += x as u64;
    }

    #[inline(always)]
    pub(crate) fn normalize_pub(&mut self) {
        self.normalize()
    }

    /// Codes one bit with an adaptive probability, updating the model.
    #[inline]
    pub fn encode_bit(&mut self, model: &mut BitModel, bit: bool) {
        self.encode_split((self.range >> PROB_BITS) * model.p0() as u32, bit);
        model.update(bit);
    }

    /// Codes `bit` against the split of the range at `bound` (0 below it, 1 above), then
    /// normalizes: the step every binary model shares.
    #[inline(always)]
    fn encode_split(&mut self, bound: u32, bit: bool) {
        if bit {
            self.low += bound as u64;
            self.range -= bound;
        } else {
            self.range = bound;
        }
        self.normalize();
    }

    /// Codes one bit with a [`CountingBitModel`], updating it.
    #[inline]
    pub fn encode_counting_bit(&mut self, model: &mut CountingBitModel, bit: bool) {
        self.encode_split((self.range >> COUNTING_PROB_BITS) * model.p0(), bit);
        model.update(bit);
    }

    /// Codes the low `bits` bits of `value` (most significant first) with probability 1/2
    /// each; `bits` at most 32.
    #[inline]
    pub fn encode_direct(&mut self, value: u32, bits: u32) {
        for i in (0..bits.min(32)).rev() {
            self.range >>= 1;
            if (value >> i) & 1 == 1 {
                self.low += self.range as u64;
            }
            self.normalize();
        }
    }

    /// Codes `symbol` with an adaptive frequency model.
    #[inline]
    pub fn encode_symbol(&mut self, model: &mut SymbolModel, symbol: usize) {
        let (cum, freq, total) = model.interval(symbol);
        let r = self.range / total;
        self.low += (r as u64) * (cum as u64);
        self.range = r * freq;
        model.update(symbol);
        self.normalize();
    }

    /// Codes the interval `[cum, cum + freq)` of a frequency table summing to `total`.
    #[inline]
    pub fn encode_interval(&mut self, cum: u32, freq: u32, total: u32) {
        let r = self.range / total.max(1);
        self.low += (r as u64) * (cum as u64);
        self.range = r * freq;
        self.normalize();
    }

    /// Codes `value` (below `2^tree.bits()`) through a binary tree of adaptive bit models.
    #[inline]
    pub fn encode_tree(&mut self, tree: &mut BitTree, value: u32) {
        let bits = tree.bits();
        let mut node = 1usize;
        for i in (0..bits).rev() {
            let bit = (value >> i) & 1 == 1;
            self.encode_bit(tree.node(node), bit);
            node = (node << 1) | bit as usize;
        }
    }

    /// Flushes and returns the coded bytes.
    pub fn finish(mut self) -> Vec<u8> {
        for _ in 0..5 {
            self.shift_low();
        }
        self.out
    }
}

/// Decodes what a [`RangeEncoder`] wrote.
#[derive(Clone, Debug)]
pub struct RangeDecoder<'a> {
    input: &'a [u8],
    pos: usize,
    pub(crate) range: u32,
    pub(crate) code: u32,
    /// Bytes requested past the end of `input`.
    overrun: usize,
}

impl<'a> RangeDecoder<'a> {
    /// Starts decoding `input`. Fails when it is shorter than the five bytes every stream has
    /// or does not start with the zero byte every stream starts with.
    pub fn new(input: &'a [u8]) -> Result<Self, Error> {
        if input.len() < 5 {
            return Err(Error::Truncated);
        }
        if input[0] != 0 {
            return Err(Error::Corrupt("range coder stream does not start with 0"));
        }
        let code = u32::from_be_bytes([input[1], input[2], input[3], input[4]]);
        Ok(RangeDecoder {
            input,
            pos: 5,
            range: u32::MAX,
            code,
            overrun: 0,
        })
    }

    #[inline]
    fn next_byte(&mut self) -> u8 {
        match self.input.get(self.pos) {
            Some(&b) => {
                self.pos += 1;
                b
            }
            None => {
                self.overrun += 1;
                0
            }
        }
    }

    #[inline]
    fn normalize(&mut self) {
        while self.range < TOP {
            self.range <<= 8;
            self.code = (self.code << 8) | self.next_byte() as u32;
        }
    }

    #[inline(always)]
    pub(crate) fn normalize_pub(&mut self) {
        self.normalize()
    }

    /// Decodes one bit coded with `model`, updating it the same way the encoder did.
    #[inline]
    pub fn decode_bit(&mut self, model: &mut BitModel) -> bool {
        let bit = self.decode_split((self.range >> PROB_BITS) * model.p0() as u32);
        model.update(bit);
        bit
    }

    /// Decodes the bit coded against the split of the range at `bound`, then normalizes.
    #[inline(always)]
    fn decode_split(&mut self, bound: u32) -> bool {
        // Without a branch on the bit (see BitModel::update): the masked interval.
        let bit = self.code >= bound;
        let one = 0u32.wrapping_sub(bit as u32);
        self.code = self.code.wrapping_sub(bound & one);
        self.range = (bound & !one) | (self.range.wrapping_sub(bound) & one);
        self.normalize();
        bit
    }

    /// Decodes one bit coded with a [`CountingBitModel`], updating it as the encoder did.
    #[inline]
    pub fn decode_counting_bit(&mut self, model: &mut CountingBitModel) -> bool {
        let bit = self.decode_split((self.range >> COUNTING_PROB_BITS) * model.p0());
        model.update(bit);
        bit
    }

    /// Decodes `bits` equiprobable bits, most significant first.
    #[inline]
    pub fn decode_direct(&mut self, bits: u32) -> u32 {
        let mut v = 0u32;
        for _ in 0..bits.min(32) {
            self.range >>= 1;
            let bit = self.code >= self.range;
            if bit {
                self.code -= self.range;
            }
            v = (v << 1) | bit as u32;
            self.normalize();
        }
        v
    }

    /// Decodes a symbol coded with `model`.
    #[inline]
    pub fn decode_symbol(&mut self, model: &mut SymbolModel) -> usize {
        let total = model.total();
        let r = self.range / total;
        // The symbol whose scaled interval holds `code`: the same as finding
        // `min(code / r, total - 1)` among the counts (`code / r < k` exactly when
        // `code < r k`), without the second division on the chain from symbol to symbol. A
        // corrupt stream can put `code` past the last interval: that reads as the last
        // symbol, as the clamp did (garbage, which a CRC or a later check catches).
        let (symbol, cum, freq) = model.find_scaled(self.code, r);
        self.code = self.code.wrapping_sub(r * cum);
        self.range = r * freq;
        model.update(symbol);
        self.normalize();
        symbol
    }

    /// Decodes an interval coded with [`RangeEncoder::encode_interval`]: `find` maps the
    /// target count (below `total`) to `(symbol, cum, freq)` of the interval holding it.
    #[inline]
    pub fn decode_with(
        &mut self,
        total: u32,
        find: impl FnOnce(u32) -> (usize, u32, u32),
    ) -> usize {
        let total = total.max(1);
        let r = self.range / total;
        // A corrupt stream can put `code` past the last interval: clamp, as decode_symbol.
        let target = (self.code / r.max(1)).min(total - 1);
        let (symbol, cum, freq) = find(target);
        self.code = self.code.wrapping_sub(r * cum);
        self.range = r * freq;
        self.normalize();
        symbol
    }

    /// [`Self::decode_with`] without its second division: `find` gets `code` and `r =
    /// range / total` and maps them to `(symbol, cum, freq)` of the first interval whose
    /// scaled upper end `r (cum + freq)` lies above `code`, else of the last interval. That
    /// is the interval holding `min(code / r, total - 1)` (`code / r < k` exactly when `code
    /// < r k`), so the two decode the same symbols from any bytes, and the division leaves
    /// the chain from symbol to symbol. `r (cum + freq)` never overflows: it is at most
    /// `range`.
    #[inline]
    pub fn decode_scaled_with(
        &mut self,
        total: u32,
        find: impl FnOnce(u32, u32) -> (usize, u32, u32),
    ) -> usize {
        let total = total.max(1);
        // `range` is at least 2^24 after every step and a total at most 2^16 + 32, so `r` is
        // at least 255; the `max` only keeps a broken invariant from zeroing the range.
        let r = (self.range / total).max(1);
        let (symbol, cum, freq) = find(self.code, r);
        self.code = self.code.wrapping_sub(r * cum);
        self.range = r * freq;
        self.normalize();
        symbol
    }

    /// Decodes a value coded with [`RangeEncoder::encode_tree`].
    #[inline]
    pub fn decode_tree(&mut self, tree: &mut BitTree) -> u32 {
        let bits = tree.bits();
        let mut node = 1usize;
        for _ in 0..bits {
            let bit = self.decode_bit(tree.node(node));
            node = (node << 1) | bit as usize;
        }
        (node - (1usize << bits)) as u32
    }

    /// Bytes consumed so far.
    pub fn position(&self) -> usize {
        self.pos
    }

    /// Ends decoding: an error when the decoder had to read past the end of its input (the
    /// stream was cut short).
    pub fn finish(self) -> Result<(), Error> {
        if self.overrun > 0 {
            Err(Error::Truncated)
        } else {
            Ok(())
        }
    }

    /// True when the decoder has already read past the end of its input.
    pub fn overran(&self) -> bool {
        self.overrun > 0
    }
}

// Keep the initial probability in one place for the models and the docs.
const _: () = assert!(PROB_INIT == 1 << (PROB_BITS - 1));

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::SignedIntModel;
    use proptest::prelude::*;

    #[test]
    fn empty_stream_round_trips() {
        let bytes = RangeEncoder::new().finish();
        assert_eq!(bytes.len(), 5);
        let d = RangeDecoder::new(&bytes).unwrap();
        d.finish().unwrap();
    }

    #[test]
    fn skewed_bits_compress() {
        let mut e = RangeEncoder::new();
        let mut m = BitModel::new();
        for i in 0..10_000 {
            e.encode_bit(&mut m, i % 50 == 0);
        }
        let bytes = e.finish();
        // Entropy of p = 0.02 is 0.1414 bits: 10k bits -> 177 bytes; adaptation costs a little.
        assert!(bytes.len() < 230, "{}", bytes.len());
        let mut d = RangeDecoder::new(&bytes).unwrap();
        let mut m = BitModel::new();
        for i in 0..10_000 {
            assert_eq!(d.decode_bit(&mut m), i % 50 == 0);
        }
        d.finish().unwrap();
    }

    #[test]
    fn truncation_is_reported() {
        let mut e = RangeEncoder::new();
        let mut m = BitModel::new();
        for i in 0..1000u32 {
            e.encode_bit(&mut m, i.wrapping_mul(2654435761) >> 31 == 1);
        }
        let bytes = e.finish();
        let cut = &bytes[..bytes.len() - 3];
        let mut d = RangeDecoder::new(cut).unwrap();
        let mut m = BitModel::new();
        for _ in 0..1000 {
            d.decode_bit(&mut m);
        }
        assert_eq!(d.finish(), Err(Error::Truncated));
        assert_eq!(RangeDecoder::new(&bytes[..4]).err(), Some(Error::Truncated));
    }

    #[test]
    fn a_counting_bit_model_learns_fast_then_settles() {
        use crate::CountingBitModel;
        let mut m = CountingBitModel::new();
        // Six zeros in a row: past 90 % for zero (a BitModel at 1/32 is at 59 %).
        for _ in 0..6 {
            m.update(false);
        }
        assert!(m.p0() > 29_500, "{}", m.p0());
        // Settled: one contrary bit moves it by 1/64 of the way only.
        for _ in 0..100 {
            m.update(false);
        }
        let before = m.p0();
        m.update(true);
        assert_eq!(m.p0(), before - (before >> 6));
        // It never reaches certainty (at 1/64 a step stops once within 64 of it).
        for _ in 0..1000 {
            m.update(false);
        }
        assert!(
            ((1 << 15) - 64..=(1 << 15) - 32).contains(&m.p0()),
            "{}",
            m.p0()
        );
        assert!(m.cost(true) < 11 * crate::COST_ONE);
    }

    #[test]
    fn symbol_tables_code_as_symbol_models_do() {
        use crate::{BitSink, CostCounter, SymbolTables};
        // One table of n symbols counts and codes exactly as a SymbolModel of n symbols
        // (past several halvings of its counts), and tables of one set keep apart.
        let symbols: Vec<(usize, usize)> = (0..20_000u32)
            .map(|i| {
                let h = i.wrapping_mul(2654435761);
                (
                    (h >> 28) as usize % 3,
                    if h >> 31 == 0 {
                        0
                    } else {
                        (h >> 20) as usize % 5
                    },
                )
            })
            .collect();
        let mut models: Vec<SymbolModel> = (0..3).map(|_| SymbolModel::new(5)).collect();
        let mut tables = SymbolTables::new(3, 5);
        let (mut e1, mut e2) = (RangeEncoder::new(), RangeEncoder::new());
        let (mut c1, mut c2) = (CostCounter::new(), CostCounter::new());
        for &(t, s) in &symbols {
            assert_eq!(tables.cost(t, s), models[t].cost(s));
            c1.encode_symbol(&mut models[t].clone(), s);
            tables.clone().encode(&mut c2, t, s);
            e1.encode_symbol(&mut models[t], s);
            tables.encode(&mut e2, t, s);
        }
        assert_eq!(c1.cost(), c2.cost());
        let bytes = e1.finish();
        assert_eq!(bytes, e2.finish());
        let mut tables = SymbolTables::new(3, 5);
        let mut d = RangeDecoder::new(&bytes).unwrap();
        for &(t, s) in &symbols {
            assert_eq!(tables.decode(&mut d, t), s);
        }
        d.finish().unwrap();
        // Out-of-range tables and symbols are clamped, garbage never panics.
        let mut tables = SymbolTables::new(2, 70);
        let mut d = RangeDecoder::new(&[0, 255, 255, 255, 255, 1, 2]).unwrap();
        for _ in 0..100 {
            assert!(tables.decode(&mut d, 9) < 64);
        }
        let mut none = SymbolTables::new(0, 5);
        assert_eq!(none.len(), 1);
        none.encode(&mut CostCounter::new(), 3, 4);
    }

    #[derive(Debug, Clone)]
    enum Op {
        Bit(u8, bool),
        Direct(u32, u32),
        Symbol(u8, u8),
        Tree(u32),
        Int(i32),
    }

    fn op() -> impl Strategy<Value = Op> {
        prop_oneof![
            (0u8..4, any::<bool>()).prop_map(|(m, b)| Op::Bit(m, b)),
            (any::<u32>(), 0u32..=32)
                .prop_map(|(v, n)| Op::Direct(if n == 32 { v } else { v & ((1u32 << n) - 1) }, n)),
            (0u8..3, 0u8..7).prop_map(|(m, s)| Op::Symbol(m, s)),
            (0u32..256).prop_map(Op::Tree),
            any::<i32>().prop_map(Op::Int),
        ]
    }

    proptest! {
        #[test]
        fn mixed_operations_round_trip(ops in proptest::collection::vec(op(), 0..400)) {
            let mut bits = [BitModel::new(); 4];
            let mut syms: Vec<SymbolModel> = (0..3).map(|_| SymbolModel::new(7)).collect();
            let mut tree = BitTree::new(8);
            let mut ints = SignedIntModel::new();
            let mut e = RangeEncoder::new();
            for o in &ops {
                match *o {
                    Op::Bit(m, b) => e.encode_bit(&mut bits[m as usize], b),
                    Op::Direct(v, n) => e.encode_direct(v, n),
                    Op::Symbol(m, s) => e.encode_symbol(&mut syms[m as usize], s as usize),
                    Op::Tree(v) => e.encode_tree(&mut tree, v),
                    Op::Int(v) => ints.encode(&mut e, v),
                }
            }
            let bytes = e.finish();
            let mut bits = [BitModel::new(); 4];
            let mut syms: Vec<SymbolModel> = (0..3).map(|_| SymbolModel::new(7)).collect();
            let mut tree = BitTree::new(8);
            let mut ints = SignedIntModel::new();
            let mut d = RangeDecoder::new(&bytes).unwrap();
            for o in &ops {
                match *o {
                    Op::Bit(m, b) => prop_assert_eq!(d.decode_bit(&mut bits[m as usize]), b),
                    Op::Direct(v, n) => prop_assert_eq!(d.decode_direct(n), v),
                    Op::Symbol(m, s) => prop_assert_eq!(d.decode_symbol(&mut syms[m as usize]), s as usize),
                    Op::Tree(v) => prop_assert_eq!(d.decode_tree(&mut tree), v),
                    Op::Int(v) => prop_assert_eq!(ints.decode(&mut d), v),
                }
            }
            prop_assert!(d.finish().is_ok());
        }

        /// The decoder's division-free search picks what dividing and clamping picked, for
        /// any counts (updates included), any `code` (past the last interval too) and any
        /// `range` a normalized decoder holds.
        #[test]
        fn scaled_search_is_the_divided_one(
            updates in proptest::collection::vec(0usize..9, 0..3000),
            code in any::<u32>(),
            range in (1u32 << 24)..=u32::MAX,
        ) {
            let mut m = SymbolModel::new(9);
            for u in updates {
                m.update(u);
            }
            let r = range / m.total();
            let target = (code / r).min(m.total() - 1);
            prop_assert_eq!(m.find_scaled(code, r), m.find(target));
        }

        /// Counting bit models round-trip any bits in any of several contexts, the cost
        /// counter prices them as the encoder codes them (within a bit per thousand coded),
        /// and a context seeing one bit value learns it within a few bits.
        #[test]
        fn counting_bits_round_trip_and_are_priced(
            bits in proptest::collection::vec((0usize..4, any::<bool>()), 0..3000),
        ) {
            use crate::{BitSink, CostCounter, CountingBitModel};
            let mut models = [CountingBitModel::new(); 4];
            let mut priced = models;
            let mut enc = RangeEncoder::new();
            let mut cost = CostCounter::new();
            for &(c, b) in &bits {
                enc.encode_counting_bit(&mut models[c], b);
                cost.encode_counting_bit(&mut priced[c], b);
            }
            prop_assert_eq!(models, priced);
            let bytes = enc.finish();
            let mut models = [CountingBitModel::new(); 4];
            let mut d = RangeDecoder::new(&bytes).unwrap();
            for &(c, b) in &bits {
                prop_assert_eq!(d.decode_counting_bit(&mut models[c]), b);
            }
            prop_assert!(d.finish().is_ok());
            // The stream is the priced size plus the coder's flush (a few bytes).
            let size = bytes.len() as f64 * 8.0;
            prop_assert!(size <= cost.bits() * 1.001 + 48.0, "{} > {}", size, cost.bits());
        }

        /// `SymbolTables::decode` (scaled search) reads the symbols that dividing and
        /// clamping read, from any bytes and any sequence of tables: the labels of swing
        /// streams decode as they did before the division left the chain.
        #[test]
        fn scaled_tables_decode_as_the_divided_reference(
            bytes in proptest::collection::vec(any::<u8>(), 5..300),
            tables_seq in proptest::collection::vec(0usize..4, 1..2000),
        ) {
            use crate::SymbolTables;
            let mut input = bytes.clone();
            input[0] = 0;
            let (Ok(mut d1), Ok(mut d2)) = (RangeDecoder::new(&input), RangeDecoder::new(&input))
            else {
                return Ok(());
            };
            let mut tables = SymbolTables::new(4, 5);
            // The reference: one SymbolModel per table, decoded by division and clamp.
            let mut models: Vec<SymbolModel> = (0..4).map(|_| SymbolModel::new(5)).collect();
            for &t in &tables_seq {
                let m = &mut models[t];
                let reference = d1.decode_with(m.total(), |target| m.find(target));
                m.update(reference);
                prop_assert_eq!(tables.decode(&mut d2, t), reference);
            }
            prop_assert_eq!(d1.position(), d2.position());
        }

        #[test]
        fn garbage_never_panics(bytes in proptest::collection::vec(any::<u8>(), 0..64)) {
            let mut input = bytes.clone();
            if let Some(b) = input.first_mut() { *b = 0; }
            if let Ok(mut d) = RangeDecoder::new(&input) {
                let mut s = SymbolModel::new(5);
                let mut t = BitTree::new(6);
                let mut i = SignedIntModel::new();
                for _ in 0..200 {
                    d.decode_symbol(&mut s);
                    d.decode_tree(&mut t);
                    i.decode(&mut d);
                    d.decode_direct(17);
                }
                let _ = d.finish();
            }
        }
    }
}
