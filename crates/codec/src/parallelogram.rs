//! The exact mode's position predictor, shared by encoder and decoder so they cannot drift
//! (Touma & Gotsman 1998, extended to every parallelogram available as in Draco's
//! multi-parallelogram prediction).
//!
//! When the traversal creates vertex `v` (the tip of a C triangle), the whole connectivity is
//! already known to both sides, so every triangle `(v, a, b)` around `v` whose `a`, `b` and
//! far vertex `w` (across edge `a b`) are already decoded gives a prediction `a + b - w`. The
//! encoder picks the subset of them whose average codes cheapest and sends the choice (one
//! adaptive flag per candidate: Draco's constrained multi-parallelogram idea, which keeps a
//! parallelogram that straddles a crease from spoiling the average). Without any
//! parallelogram the predictor falls back to the gate (Georgia Tech's partial cases): the
//! midpoint of two known gate vertices, or the one known gate vertex. Dummy hole vertices are
//! never known.

use whet_mesh::{CornerId, CornerTable};

/// Most parallelograms a prediction chooses among (the rest are ignored; valence-6 meshes
/// offer at most three when a vertex is created).
pub const MAX_CANDIDATES: usize = 8;

/// The parallelogram predictions available for the vertex at `tip` (a C corner): one per
/// triangle `(v, a, b)` around it whose `a`, `b` and far vertex `w` are known, as
/// `a + b - w`, in fan order starting at `tip` (deterministic), at most
/// [`MAX_CANDIDATES`]. Returns how many were written.
pub fn candidates(
    table: &CornerTable,
    tip: CornerId,
    q: &[[i32; 3]],
    known: &[bool],
    out: &mut [[i64; 3]; MAX_CANDIDATES],
) -> usize {
    let v = table.vertex(tip).index();
    let mut count = 0usize;
    let start = tip;
    let mut c = start;
    let mut guard = 0usize;
    loop {
        let a = table.vertex(table.next(c)).index();
        let b = table.vertex(table.prev(c)).index();
        if known[a] && known[b] {
            if let Some(o) = table.opposite(c) {
                let w = table.vertex(o).index();
                if known[w] && w != v {
                    out[count] =
                        [0, 1, 2].map(|k| q[a][k] as i64 + q[b][k] as i64 - q[w][k] as i64);
                    count += 1;
                    if count == MAX_CANDIDATES {
                        break;
                    }
                }
            }
        }
        match table.swing(c) {
            Some(n) if n != start => c = n,
            _ => break,
        }
        guard += 1;
        if guard > table.corner_count() {
            break;
        }
    }
    count
}

/// The average of the candidates selected by the bits of `mask` (non-zero), rounded half
/// away from zero.
pub fn average(cands: &[[i64; 3]], mask: u32) -> [i32; 3] {
    let (sum, n) = masked_sum(cands, mask);
    mean(sum, n)
}

/// The sum and count of the candidates selected by the bits of `mask`: [`average`] is
/// their [`mean`]. Inlined where a prediction is made, so the prediction stays in registers
/// (an out-of-line `average` returned it through memory lane by lane, and the wider load
/// that read it back could not be store-forwarded: a stall per vertex).
#[inline(always)]
pub(crate) fn masked_sum(cands: &[[i64; 3]], mask: u32) -> ([i64; 3], i64) {
    let mut sum = [0i64; 3];
    let mut n = 0i64;
    for (i, c) in cands.iter().enumerate() {
        if mask >> i & 1 == 1 {
            for k in 0..3 {
                sum[k] += c[k];
            }
            n += 1;
        }
    }
    (sum, n)
}

/// `sum / n` per axis rounded half away from zero and clamped to `i32`, as [`average`]
/// computes it (`[0; 3]` for `n == 0`).
#[inline(always)]
pub(crate) fn mean(sum: [i64; 3], n: i64) -> [i32; 3] {
    if n <= 0 {
        return [0; 3];
    }
    #[inline(always)]
    fn by(sum: [i64; 3], n: i64) -> [i32; 3] {
        let one = |s: i64| div_round(s, n).clamp(i32::MIN as i64, i32::MAX as i64) as i32;
        [one(sum[0]), one(sum[1]), one(sum[2])]
    }
    // Constant divisors for the usual counts: multiplications instead of divisions.
    match n {
        1 => by(sum, 1),
        2 => by(sum, 2),
        3 => by(sum, 3),
        4 => by(sum, 4),
        _ => by(sum, n),
    }
}

/// The prediction when no parallelogram is available: the midpoint of the known gate
/// vertices of the C triangle at `tip`, or the one known gate vertex (Georgia Tech's partial
/// cases; a gate vertex is unknown only when it is a hole's dummy).
pub fn gate_fallback(
    table: &CornerTable,
    tip: CornerId,
    q: &[[i32; 3]],
    known: &[bool],
) -> [i32; 3] {
    let a = table.vertex(table.next(tip)).index();
    let b = table.vertex(table.prev(tip)).index();
    partial_gate(known[a].then(|| q[a]), known[b].then(|| q[b]))
}

/// The prediction from a gate's known vertices (`None`: unknown): their midpoint, the one
/// known, or the origin.
#[inline]
pub(crate) fn partial_gate(a: Option<[i32; 3]>, b: Option<[i32; 3]>) -> [i32; 3] {
    match (a, b) {
        (Some(a), Some(b)) => gate_midpoint(a, b),
        (Some(x), None) | (None, Some(x)) => x,
        (None, None) => [0; 3],
    }
}

/// The midpoint of two known gate vertices, rounded half away from zero.
#[inline]
pub(crate) fn gate_midpoint(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    [0, 1, 2].map(|k| div_round(a[k] as i64 + b[k] as i64, 2) as i32)
}

/// `s / n` rounded half away from zero (n > 0), identical on every machine.
#[inline(always)]
fn div_round(s: i64, n: i64) -> i64 {
    if s >= 0 {
        (s + n / 2) / n
    } else {
        -((-s + n / 2) / n)
    }
}

#[cfg(test)]
mod tests {
    use super::div_round;

    #[test]
    fn rounding_is_symmetric() {
        assert_eq!(div_round(5, 2), 3);
        assert_eq!(div_round(-5, 2), -3);
        assert_eq!(div_round(4, 3), 1);
        assert_eq!(div_round(-4, 3), -1);
        assert_eq!(div_round(0, 7), 0);
    }
}
