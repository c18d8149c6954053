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
        let m = self.max_level() as f64;
        [q.x, q.y, q.z].map(|c| c.round().clamp(0.0, m) as i32)
    }

    /// Position of grid point `q`.
    #[inline]
    pub fn dequantize(&self, q: [i32; 3]) -> DVec3 {
        self.min + DVec3::new(q[0] as f64, q[1] as f64, q[2] as f64) * self.step
    }
}
