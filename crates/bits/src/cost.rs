//! Pricing symbols in fractions of a bit, with integer arithmetic only, so that an encoder's
//! rate-driven choices (and so its output) are identical on every machine.
//!
//! `-log2(p)` is tabulated at compile time by the classic squaring method: normalise `x` into
//! `[1, 2)` and square it repeatedly; each squaring that overflows 2 yields one fraction bit.

use crate::models::{
    BitModel, BitSink, BitTree, CountingBitModel, SymbolModel, PROB_BITS, PROB_ONE,
};

/// Fraction bits of a cost: costs are in units of `1 / COST_ONE` bit.
pub const COST_FRAC_BITS: u32 = 8;
/// One bit, in cost units.
pub const COST_ONE: u32 = 1 << COST_FRAC_BITS;

/// `log2(x)` in cost units for `x >= 1` (integer squaring; exact to about one unit).
const fn log2_fixed(x: u64) -> u32 {
    if x == 0 {
        return 0;
    }
    let int = 63 - x.leading_zeros();
    // y = x / 2^int in [1, 2) with 32 fraction bits.
    let mut y: u64 = if int >= 32 {
        x >> (int - 32)
    } else {
        x << (32 - int)
    };
    let mut frac = 0u32;
    let mut i = 0;
    while i < COST_FRAC_BITS {
        // Square in 32.32 fixed point; y < 2^33 so y*y < 2^66: split to stay in u64.
        let hi = y >> 16;
        y = hi * hi;
        // hi*hi has 2*16 fraction bits = 32: y stays in 32.32 form (losing 16 low bits).
        frac <<= 1;
        if y >= (2u64 << 32) {
            y >>= 1;
            frac |= 1;
        }
        i += 1;
    }
    (int << COST_FRAC_BITS) | frac
}

const PRICE_TABLE_BITS: u32 = PROB_BITS;

/// `-log2(p / PROB_ONE)` in cost units for every `p` in `0..=PROB_ONE`.
static PRICES: [u32; (1 << PRICE_TABLE_BITS) + 1] = {
    let mut t = [0u32; (1 << PRICE_TABLE_BITS) + 1];
    let mut p = 1;
    while p <= (1 << PRICE_TABLE_BITS) {
        t[p] = (PROB_BITS << COST_FRAC_BITS) - log2_fixed(p as u64);
        p += 1;
    }
    // p = 0 never happens for a model; price it as 32 bits.
    t[0] = 32 << COST_FRAC_BITS;
    t
};

/// Cost of an event of probability `p / PROB_ONE`.
#[inline]
pub(crate) fn price(p: u32) -> u32 {
    PRICES[p.min(PROB_ONE) as usize]
}

/// Cost of an event of probability `f / total` (any 32-bit counts).
#[inline]
pub(crate) fn ratio_cost(f: u32, total: u32) -> u32 {
    if f == 0 || total == 0 {
        return 32 << COST_FRAC_BITS;
    }
    log2_fixed(total as u64).saturating_sub(log2_fixed(f as u64))
}

/// A [`BitSink`] that codes nothing and adds up what the symbols would cost, updating the
/// models exactly as the encoder would. Run an encoder on clones of its models to price a
/// choice, or on the real models to measure a stream's size without building it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CostCounter {
    cost: u64,
}

impl CostCounter {
    /// A counter at zero.
    pub fn new() -> Self {
        Self::default()
    }

    /// Accumulated cost in 1/[`COST_ONE`] bits.
    pub fn cost(&self) -> u64 {
        self.cost
    }

    /// Accumulated cost in bits.
    pub fn bits(&self) -> f64 {
        self.cost as f64 / COST_ONE as f64
    }
}

impl BitSink for CostCounter {
    #[inline]
    fn encode_bit(&mut self, model: &mut BitModel, bit: bool) {
        self.cost += model.cost(bit) as u64;
        model.update(bit);
    }
    #[inline]
    fn encode_direct(&mut self, _value: u32, bits: u32) {
        self.cost += (bits.min(32) * COST_ONE) as u64;
    }
    #[inline]
    fn encode_symbol(&mut self, model: &mut SymbolModel, symbol: usize) {
        self.cost += model.cost(symbol) as u64;
        model.update(symbol);
    }
    #[inline]
    fn encode_interval(&mut self, _cum: u32, freq: u32, total: u32) {
        self.cost += ratio_cost(freq, total) as u64;
    }
    #[inline]
    fn encode_counting_bit(&mut self, model: &mut CountingBitModel, bit: bool) {
        self.cost += model.cost(bit) as u64;
        model.update(bit);
    }
    #[inline]
    fn encode_tree(&mut self, tree: &mut BitTree, value: u32) {
        let bits = tree.bits();
        let mut node = 1usize;
        for i in (0..bits).rev() {
            let bit = (value >> i) & 1 == 1;
            let m = tree.node(node);
            self.cost += m.cost(bit) as u64;
            m.update(bit);
            node = (node << 1) | bit as usize;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::RangeEncoder;

    #[test]
    fn log2_is_accurate() {
        for x in [1u64, 2, 3, 5, 7, 100, 1000, 4095, 4096, 65535, 1 << 40] {
            let want = (x as f64).log2() * COST_ONE as f64;
            let got = log2_fixed(x) as f64;
            assert!((got - want).abs() <= 2.0, "log2({x}): {got} vs {want}");
        }
    }

    #[test]
    fn prices_match_entropy() {
        assert_eq!(price(PROB_ONE), 0);
        assert_eq!(price(PROB_ONE / 2), COST_ONE);
        assert!((price(PROB_ONE / 4) as i64 - 2 * COST_ONE as i64).abs() <= 1);
    }

    #[test]
    fn counter_predicts_encoder_size() {
        let mut m1 = SymbolModel::new(5);
        let mut m2 = m1.clone();
        let mut b1 = BitModel::new();
        let mut b2 = b1;
        let mut counter = CostCounter::new();
        let mut enc = RangeEncoder::new();
        let mut x = 12345u32;
        for _ in 0..20000 {
            x = x.wrapping_mul(1664525).wrapping_add(1013904223);
            let s = [0, 0, 0, 1, 1, 2, 3, 4][(x >> 29) as usize];
            counter.encode_symbol(&mut m1, s);
            enc.encode_symbol(&mut m2, s);
            let bit = (x >> 10) & 7 == 0;
            counter.encode_bit(&mut b1, bit);
            enc.encode_bit(&mut b2, bit);
        }
        let actual = enc.finish().len() as f64 * 8.0;
        let predicted = counter.bits();
        assert!(
            (actual - predicted).abs() < 0.01 * actual + 64.0,
            "{actual} vs {predicted}"
        );
    }
}
