//! Uniform scalar quantization of positions on one cubic grid (`../shared/docs/algorithms.md`
//! 3.1): the same step on every axis, so parallelogram predictions are exact in integers.

use whet_mesh::{Aabb, DVec3};

/// Maps positions to integer grid coordinates in `[0, 2^bits - 1]` and back.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Quantizer {
    /// Grid origin (the bounding box minimum).
    pub min: DVec3,
    /// Grid step (the largest box extent over `2^bits - 1`; 1 for a box of zero size).
    pub step: f64,
    /// Bits per coordinate.
    pub bits: u32,
}

impl Quantizer {
    /// The grid of `bits` bits (1..=30) over `bbox`.
    pub fn new(bbox: &Aabb, bits: u32) -> Self {
        let ext = bbox.size().max_element();
        let levels = ((1u64 << bits) - 1) as f64;
        let step = if ext > 0.0 && ext.is_finite() {
            ext / levels
        } else {
            1.0
        };
        Quantizer {
            min: if bbox.is_empty() {
                DVec3::ZERO
            } else {
                bbox.min
            },
            step,
            bits,
        }
    }

    /// Largest grid coordinate.
    #[inline]
    pub fn max_level(&self) -> i32 {
        ((1u64 << self.bits) - 1) as i32
    }

    /// Grid coordinates of `p` (clamped into the grid).
    #[inline]
    pub fn quantize(&self, p: DVec3) -> [i32; 3] {
        let q = (p - self.min) / self.step;
        let m = self.max_level();
        [q.x, q.y, q.z].map(|c| grid_coordinate(c, m))
    }

    /// Position of grid point `q`.
    #[inline]
    pub fn dequantize(&self, q: [i32; 3]) -> DVec3 {
        self.min + DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64) * self.step
    }
}

/// `x.round()` (half away from zero) bit for bit, signed zeros, infinities and NaN
/// included, without the call to the software `round` that baseline x86-64 makes: the swing
/// decoder's prediction rounds once per triangle, on its chain of dependent operations.
#[inline]
pub(crate) fn round_half_away(x: f64) -> f64 {
    // From 2^52 on every f64 is an integer (and NaN and the infinities round to themselves).
    if x.is_nan() || x.abs() >= 4_503_599_627_370_496.0 {
        return x;
    }
    // |x| < 2^52: the truncation through i64 is exact, and so is the fraction.
    let t = x as i64 as f64;
    let fraction = x - t;
    let r = if fraction >= 0.5 {
        t + 1.0
    } else if fraction <= -0.5 {
        t - 1.0
    } else {
        t
    };
    // A result of zero keeps the sign of x (round(-0.3) is -0.0); others have it already.
    r.copysign(x)
}

/// `c` rounded half away from zero and clamped into `[0, m]` (`m` < 2^31), as
/// `c.round().clamp(0.0, m as f64) as i32` gives, NaN included (0), without the call to the
/// software `round` that baseline x86-64 makes (a few percent of an exact encode).
#[inline]
fn grid_coordinate(c: f64, m: i32) -> i32 {
    if c.is_nan() || c <= 0.0 {
        return 0;
    }
    if c >= f64::from(m) {
        return m;
    }
    // 0 < c < m < 2^31: the truncation is exact, and so is the fraction (c and its integer
    // part are within a factor of two of each other, or the part is 0).
    let t = c as i32;
    let fraction = c - f64::from(t);
    t + i32::from(fraction >= 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// 20 000 values spread over `[low, low + width)` (xorshift from `seed`), each with the
    /// half-integer nearest it away from zero and that half's two neighbouring doubles: the
    /// cases where rounding differs.
    fn spread_with_halves(seed: u64, low: f64, width: f64) -> Vec<f64> {
        let mut state = seed;
        let mut out = Vec::with_capacity(80_000);
        for _ in 0..20_000 {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            let x = low + (state >> 11) as f64 / (1u64 << 53) as f64 * width;
            let half = x.trunc() + 0.5 * x.signum();
            // Both neighbours of the half (never 0), whatever its sign.
            let (a, b) = (half.to_bits() + 1, half.to_bits() - 1);
            out.extend([x, half, f64::from_bits(a), f64::from_bits(b)]);
        }
        out
    }

    #[test]
    fn round_half_away_matches_round_bit_for_bit() {
        let mut cases = vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -0.0,
            0.0,
            0.5,
            -0.5,
            0.49999999999999994,
            -0.49999999999999994,
            -0.3,
            2.5,
            -2.5,
            4_503_599_627_370_495.5,
            -4_503_599_627_370_495.5,
            4_503_599_627_370_496.0,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
        ];
        cases.extend(spread_with_halves(0x9E37_79B9_7F4A_7C15, -100.0, 200.0));
        for x in cases {
            let (got, want) = (round_half_away(x), x.round());
            assert!(
                got.to_bits() == want.to_bits() || (got.is_nan() && want.is_nan()),
                "{x:e}: {got:e} != {want:e}"
            );
        }
    }

    #[test]
    fn grid_coordinate_matches_round_then_clamp() {
        let m = (1 << 20) - 1;
        let reference = |c: f64| c.round().clamp(0.0, f64::from(m)) as i32;
        let mut cases = vec![
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -0.0,
            0.0,
            -0.5,
            -0.49999999999999994,
            0.49999999999999994,
            0.5,
            1.5,
            2.5,
            f64::from(m) - 0.5,
            f64::from(m) - 0.50000000001,
            f64::from(m),
            f64::from(m) + 0.4,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
        ];
        // Halves, their neighbours and a spread of ordinary values.
        cases.extend(spread_with_halves(
            0x2545_F491_4F6C_DD1D,
            -1000.0,
            1.1 * f64::from(m),
        ));
        for c in cases {
            assert_eq!(grid_coordinate(c, m), reference(c), "{c:e}");
        }
    }
}
