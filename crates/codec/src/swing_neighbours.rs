//! Geometry kinds 9 and 10: the forward walk of kinds 7 and 8 with each swing index predicted
//! from its neighbourhood as well as from the fan normals, and its residual coded bit by bit
//! in contexts made of that neighbourhood (docs/swing.md section 2, "Neighbourhood
//! prediction"; docs/format.md, the normative arithmetic).
//!
//! What the kinds 5 to 8 prediction leaves is not noise alone. Neighbouring residuals agree in
//! sign (the surface bends on as it bent, more or less than the fan normals say), the rounded
//! prediction's fraction tells which neighbour of the rounded index is the likelier, and the
//! front vertex past the gate's end `b` lies on the surface the tip continues. So the
//! prediction is 1.4 times the fan normals' direction (kinds 5 to 8 take 1.75 times its
//! angle; here a pseudo-angle, one division instead of an arctangent, which also predicts
//! better), plus a fifth of the residuals of the gate's two vertices, a tenth of the residual
//! of the vertex across the gate and a tenth of the pseudo-angle of the front vertex `b⁺`
//! (when it lies ahead of the gate), all in index units; and the
//! residual is coded as a zero flag, a sign and a unary magnitude through
//! [`whet_bits::CountingBitModel`]s, in contexts of the prediction's bucket, its fraction and
//! the neighbouring residuals. On the 17 fixtures at L = 1 % of the diagonal: 2.7-14.2 %
//! fewer geometry bits than kinds 7 and 8 (docs/results.md).

use super::*;
use whet_bits::CountingBitModel;

/// Weight of the fan normals' pseudo-angle (in index units) in the prediction.
const W_FAN: f64 = 1.4;
/// Weight of the sum of the gate vertices' residuals.
const W_GATE: f64 = 0.2;
/// Weight of the residual of the vertex across the gate (the parent triangle's third).
const W_PARENT: f64 = 0.1;
/// Weight of the pseudo-angle of the front vertex past the gate's end `b`.
const W_FRONT: f64 = 0.1;
/// A fraction of the prediction farther than this from its rounded index selects the zero
/// flag's "far" contexts.
const FAR_FRACTION: f64 = 0.25;
/// Context-modelled unary steps of a magnitude; larger magnitudes escape to raw bits.
const UNARY_STEPS: usize = 14;
/// Buckets of the rounded prediction (`min(7, bit length of zigzag(pred))`).
const BUCKETS: usize = 8;
/// Classes of the neighbours' largest residual magnitude (0, 1, 2 or more).
const NEAR: usize = 3;
/// Low bits of a magnitude coded below the unary part: up to 14 − 6 angle bits.
const MAX_LOW_BITS: usize = (MAX_ANGLE_BITS - 6) as usize;

/// The contexts of one residual, from its prediction and neighbourhood.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct ResidualContext {
    bucket: usize,
    far: usize,
    near: usize,
    pred_sign: usize,
    fraction_negative: usize,
    sum_sign: usize,
}

impl ResidualContext {
    /// Index of the nonzero flag's model.
    #[inline]
    fn nonzero(&self) -> usize {
        (self.bucket * 2 + self.far) * NEAR + self.near
    }
    /// Index of the sign's model.
    #[inline]
    fn negative(&self) -> usize {
        ((self.bucket * 3 + self.pred_sign) * 2 + self.fraction_negative) * 3 + self.sum_sign
    }
    /// Index of the first unary step's model (step `j` adds `j · BUCKETS · NEAR`).
    #[inline]
    fn unary(&self) -> usize {
        self.bucket * NEAR + self.near
    }
}

/// Models of the sign: bucket × sign of the prediction × sign of its fraction × sign of the
/// residual sum.
const NEGATIVE_MODELS: usize = BUCKETS * 3 * 2 * 3;
/// Models of one unary step: bucket × neighbour magnitude.
const UNARY_STRIDE: usize = BUCKETS * NEAR;

/// The residuals a prediction reads: of the gate's ends `a` and `b` and of the vertex across
/// the gate (0 for seed vertices).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(super) struct Neighbourhood {
    pub a: i32,
    pub b: i32,
    pub parent: i32,
}

/// The pseudo-angle `y / (|y| + x)` of the direction `(x, y)`, `x ≥ 0`: in `[−1, 1]`,
/// monotone in the angle, exact at 0, ±45° (±1/2) and ±90° (±1), one division and no
/// polynomial; 0 when not finite or `x = y = 0`.
#[inline]
fn pseudo_angle(x: f64, y: f64) -> f64 {
    let d = y.abs() + x;
    if d > 0.0 && d.is_finite() {
        y / d
    } else {
        0.0
    }
}

/// The pseudo-angle of the tip direction perpendicular to `normal` (the direction of
/// [`predicted_angle`], without its arctangent).
#[inline]
fn fan_pseudo_angle(frame: &SwingFrame, normal: DVec3) -> f64 {
    let x = dot(frame.e2, normal);
    let y = -dot(frame.e1, normal);
    if x < 0.0 {
        pseudo_angle(-x, -y)
    } else {
        pseudo_angle(x, y)
    }
}

/// The pseudo-angle of point `p` around the gate of `frame` when it lies ahead of the gate
/// (`(p − m)·e1 > 0`), else 0.
#[inline]
fn front_pseudo_angle(frame: &SwingFrame, p: DVec3) -> f64 {
    let d = sub(p, frame.center);
    let u = dot(frame.e1, d);
    let w = dot(frame.e2, d);
    if u > 0.0 {
        pseudo_angle(u, w)
    } else {
        0.0
    }
}

/// What a walk's predictions share: the angle table's constants, computed once.
#[derive(Clone, Copy, Debug)]
pub(super) struct Predictor {
    /// `2^(B−2)`: a pseudo-angle of 1 (90°) in index units.
    quarter: f64,
    limit: f64,
    min_index: i32,
    max_index: i32,
    shift: u32,
}

impl Predictor {
    pub(super) fn new(table: &AngleTable) -> Self {
        Predictor {
            quarter: f64::from(1u32 << (table.bits() - 2)),
            limit: f64::from(1u32 << table.bits()),
            min_index: table.min_index(),
            max_index: table.max_index(),
            shift: table.bits().saturating_sub(6),
        }
    }

    /// The predicted swing index of the tip over the gate of `frame` and its residual's
    /// contexts: `normal` is `F(a) + F(b)`, `front` the position of the front vertex past `b`.
    #[inline(always)]
    pub(super) fn predict(
        &self,
        frame: &SwingFrame,
        normal: DVec3,
        front: DVec3,
        near: Neighbourhood,
    ) -> (i32, ResidualContext) {
        let q = self.quarter;
        let x = ((W_FAN * (fan_pseudo_angle(frame, normal) * q)
            + W_GATE * f64::from(near.a + near.b))
            + W_PARENT * f64::from(near.parent))
            + W_FRONT * (front_pseudo_angle(frame, front) * q);
        let x = if x.is_finite() { x } else { 0.0 };
        // Clamped first so that the cast is exact (residuals are within the index range, so
        // only a corrupt stream's could take |x| far).
        let rounded = crate::quantize::round_half_away(x.max(-self.limit).min(self.limit));
        let pred = (rounded as i32).max(self.min_index).min(self.max_index);
        let fraction = x - f64::from(pred);
        let largest = near.a.abs().max(near.b.abs()).max(near.parent.abs()) >> self.shift;
        let sum = near.a + near.b + near.parent;
        let ctx = ResidualContext {
            bucket: ((32 - zigzag(pred).leading_zeros()) as usize).min(BUCKETS - 1),
            far: (fraction.abs() > FAR_FRACTION) as usize,
            near: (largest as usize).min(NEAR - 1),
            pred_sign: (pred.signum() + 1) as usize,
            fraction_negative: (fraction < 0.0) as usize,
            sum_sign: (sum.signum() + 1) as usize,
        };
        (pred, ctx)
    }
}

/// The adaptive models of kinds 9 and 10's residuals, in flat arrays indexed by
/// [`ResidualContext`] (one bounds check per model, not one per dimension).
#[derive(Clone, Debug)]
pub(super) struct ResidualModels {
    /// Nonzero flag, by bucket, far fraction and neighbour magnitude.
    nonzero: [CountingBitModel; BUCKETS * 2 * NEAR],
    /// Negative flag, by bucket, sign of the prediction, sign of its fraction and sign of
    /// the neighbours' residual sum.
    negative: [CountingBitModel; NEGATIVE_MODELS],
    /// Unary steps of the magnitude's high part, by step, bucket and neighbour magnitude.
    unary: [CountingBitModel; UNARY_STEPS * UNARY_STRIDE],
    /// Low bits of the magnitude (more than 6 angle bits), by bit and high part (0, 1, 2+).
    low: [[CountingBitModel; 3]; MAX_LOW_BITS],
}

impl ResidualModels {
    pub(super) fn new() -> Self {
        let m = CountingBitModel::new();
        ResidualModels {
            nonzero: [m; BUCKETS * 2 * NEAR],
            negative: [m; NEGATIVE_MODELS],
            unary: [m; UNARY_STEPS * UNARY_STRIDE],
            low: [[m; 3]; MAX_LOW_BITS],
        }
    }

    /// Codes residual `r` (in the index range of `bits` angle bits).
    pub(super) fn encode<S: BitSink>(
        &mut self,
        sink: &mut S,
        c: &ResidualContext,
        r: i32,
        bits: u32,
    ) {
        sink.encode_counting_bit(&mut self.nonzero[c.nonzero()], r != 0);
        if r == 0 {
            return;
        }
        sink.encode_counting_bit(&mut self.negative[c.negative()], r < 0);
        let shift = bits.saturating_sub(6);
        let magnitude = r.unsigned_abs() - 1;
        let high = (magnitude >> shift) as usize;
        for k in 0..UNARY_STEPS {
            sink.encode_counting_bit(&mut self.unary[k * UNARY_STRIDE + c.unary()], high > k);
            if high <= k {
                break;
            }
        }
        if high >= UNARY_STEPS {
            sink.encode_direct((high - UNARY_STEPS) as u32, escape_bits(bits));
        }
        for j in (0..shift as usize).rev() {
            sink.encode_counting_bit(&mut self.low[j][high.min(2)], (magnitude >> j) & 1 == 1);
        }
    }

    /// Decodes a residual coded by [`Self::encode`]; garbage decodes to a residual within
    /// `[−2^(bits−1), 2^(bits−1)]`, which one wrap takes back into the index range.
    pub(super) fn decode(
        &mut self,
        dec: &mut RangeDecoder<'_>,
        c: &ResidualContext,
        bits: u32,
    ) -> i32 {
        if !dec.decode_counting_bit(&mut self.nonzero[c.nonzero()]) {
            return 0;
        }
        let negative = dec.decode_counting_bit(&mut self.negative[c.negative()]);
        let shift = bits.saturating_sub(6);
        let mut high = 0usize;
        let unary = c.unary();
        while high < UNARY_STEPS
            && dec.decode_counting_bit(&mut self.unary[high * UNARY_STRIDE + unary])
        {
            high += 1;
        }
        if high >= UNARY_STEPS {
            high += dec.decode_direct(escape_bits(bits)) as usize;
        }
        let mut magnitude = (high as u32) << shift;
        for j in (0..shift as usize).rev() {
            magnitude |= u32::from(dec.decode_counting_bit(&mut self.low[j][high.min(2)])) << j;
        }
        let magnitude = magnitude.min((1u32 << (bits - 1)) - 1) as i32 + 1;
        if negative {
            -magnitude
        } else {
            magnitude
        }
    }
}

/// Raw bits of an escaped high part: it is below `2^(bits − 1 − shift)`.
#[inline]
fn escape_bits(bits: u32) -> u32 {
    bits - 1 - bits.saturating_sub(6)
}

#[cfg(test)]
mod tests {
    use super::*;
    use whet_bits::RangeEncoder;

    #[test]
    fn every_residual_round_trips_at_every_angle_bits() {
        for bits in MIN_ANGLE_BITS..=MAX_ANGLE_BITS {
            let h = 1i32 << (bits - 1);
            let contexts: Vec<ResidualContext> = (0..5)
                .map(|i| ResidualContext {
                    bucket: i % BUCKETS,
                    far: i % 2,
                    near: i % NEAR,
                    pred_sign: i % 3,
                    fraction_negative: (i + 1) % 2,
                    sum_sign: (i + 2) % 3,
                })
                .collect();
            let values: Vec<i32> = (-h..h).chain([0, 0, 1, -1, 0]).collect();
            let mut models = ResidualModels::new();
            let mut enc = RangeEncoder::new();
            for (i, &r) in values.iter().enumerate() {
                models.encode(&mut enc, &contexts[i % 5], r, bits);
            }
            let bytes = enc.finish();
            let mut models = ResidualModels::new();
            let mut dec = RangeDecoder::new(&bytes).unwrap();
            for (i, &r) in values.iter().enumerate() {
                assert_eq!(
                    models.decode(&mut dec, &contexts[i % 5], bits),
                    r,
                    "bits {bits}"
                );
            }
            dec.finish().unwrap();
        }
    }

    #[test]
    fn garbage_decodes_within_one_wrap_of_the_index_range() {
        let bytes: Vec<u8> = (0..4000u32)
            .map(|i| (i.wrapping_mul(2_654_435_761) >> 13) as u8)
            .collect();
        for bits in MIN_ANGLE_BITS..=MAX_ANGLE_BITS {
            let h = 1i32 << (bits - 1);
            let mut models = ResidualModels::new();
            let mut input = bytes.clone();
            input[0] = 0;
            let mut dec = RangeDecoder::new(&input).unwrap();
            let c = ResidualContext {
                bucket: 3,
                far: 1,
                near: 2,
                pred_sign: 0,
                fraction_negative: 1,
                sum_sign: 2,
            };
            for _ in 0..2000 {
                let r = models.decode(&mut dec, &c, bits);
                assert!((-h..=h).contains(&r), "{r} at {bits} bits");
                assert!((-h..h).contains(&wrap_index(r + (h - 1), bits)));
                assert!((-h..h).contains(&wrap_index(r - h, bits)));
            }
        }
    }

    #[test]
    fn the_prediction_stays_in_the_index_range_and_reads_its_neighbourhood() {
        let frame =
            SwingFrame::new(DVec3::ZERO, DVec3::X, DVec3::new(0.5, -0.8, 0.0), 1.0).unwrap();
        let table = AngleTable::new(6).unwrap();
        let predictor = Predictor::new(&table);
        let predict = |f: &SwingFrame, n: DVec3, p: DVec3, near: Neighbourhood, _t: &AngleTable| {
            predictor.predict(f, n, p, near)
        };
        // A flat fan (normal +z) and a front vertex in the parent's plane: 0.
        let flat = predict(
            &frame,
            DVec3::Z,
            DVec3::new(1.2, 0.8, 0.0),
            Neighbourhood::default(),
            &table,
        );
        assert_eq!(flat.0, 0);
        // Residuals of the neighbours pull it their way.
        let pulled = predict(
            &frame,
            DVec3::Z,
            DVec3::new(1.2, 0.8, 0.0),
            Neighbourhood {
                a: 3,
                b: 3,
                parent: 2,
            },
            &table,
        );
        assert_eq!(pulled.0, 1);
        assert_eq!(pulled.1.sum_sign, 2);
        assert_eq!(pulled.1.near, 2);
        // Absurd residuals (a corrupt stream) are clamped into the range.
        for r in [i32::MIN / 4, i32::MAX / 4] {
            let (p, _) = predict(
                &frame,
                DVec3::Z,
                DVec3::new(1.2, 0.8, 0.0),
                Neighbourhood {
                    a: r,
                    b: r,
                    parent: r,
                },
                &table,
            );
            assert!((table.min_index()..=table.max_index()).contains(&p));
        }
        // A front vertex folded up ahead of the gate pulls the prediction up; behind the
        // gate it counts nothing.
        let up = predict(
            &frame,
            DVec3::Z,
            DVec3::new(0.5, 0.3, 0.9),
            Neighbourhood::default(),
            &table,
        );
        let behind = predict(
            &frame,
            DVec3::Z,
            DVec3::new(0.5, -0.3, 0.9),
            Neighbourhood::default(),
            &table,
        );
        // (its pseudo-angle 0.9 / 1.2 = 0.75 is 12 steps of 64; a tenth of that, 1.2, rounds
        // to 1.)
        assert_eq!(up.0, 1, "{up:?}");
        assert_eq!(behind.0, 0);
        assert_eq!(behind.1.far, 0);
    }
}
