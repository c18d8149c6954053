//! The `exact` mode's geometry: positions quantized to `Q` bits per axis, visited in the
//! Edgebreaker traversal order, predicted by [`crate::parallelogram`] and coded as residuals.
//!
//! One function, [`code_positions`], walks the vertices for both sides; the encoder plugs in
//! a [`ResidualIo`] that writes `actual - prediction` and the decoder one that reads it and
//! writes `prediction + residual`, so the visiting order, the predictions and the contexts
//! are the same code.
//!
//! Per component: the start triangle's first vertex raw (`Q` bits per axis), the second as a
//! delta from the first, the third as a delta from their midpoint; then one residual triple per
//! C tip. Residual contexts: how many parallelograms the prediction averaged (0, 1, 2+) x axis
//! x bit length of the previous axis's residual of the same vertex (0..=5), which captures that
//! a vertex badly predicted on one axis is usually badly predicted on the others.

use crate::parallelogram::{
    average, gate_midpoint, masked_sum, mean, partial_gate, MAX_CANDIDATES,
};
use whet_bits::{BitModel, RangeDecoder, ResidualModel, SignedIntModel};
use whet_edgebreaker::{Connectivity, TraversalError};
use whet_mesh::Scratch;

const CLASSES: usize = 4;
/// Candidate counts up to which [`ResidualWriter::select`] builds subset sums incrementally
/// (a table of `2^k` sums on the stack); more candidates are averaged subset by subset.
const MAX_SUBSET_PRICED: usize = 4;
const PREV_BUCKETS: usize = 6;

/// Adaptive models of the position stream.
pub(crate) struct PositionModels {
    residual: Vec<ResidualModel>,
    seed: [SignedIntModel; 3],
    /// "Average all candidates" flag, by candidate count - 1.
    use_all: [BitModel; MAX_CANDIDATES],
    /// Subset flags by (candidate count - 1, candidate index).
    selection: [[BitModel; MAX_CANDIDATES]; MAX_CANDIDATES],
}

impl PositionModels {
    pub(crate) fn new() -> Self {
        PositionModels {
            // Predictions are clamped into the grid, so residuals stay below 2^30.
            residual: (0..CLASSES * 3 * PREV_BUCKETS)
                .map(|_| ResidualModel::new())
                .collect(),
            seed: [(); 3].map(|_| SignedIntModel::below_2_31()),
            use_all: [BitModel::new(); MAX_CANDIDATES],
            selection: [[BitModel::new(); MAX_CANDIDATES]; MAX_CANDIDATES],
        }
    }
}

/// Reads or writes one vertex's grid coordinates given a prediction.
pub(crate) trait ResidualIo {
    /// True when the encoder may stop early (its output already exceeds a budget).
    fn exhausted(&self) -> bool {
        false
    }
    /// Raw coordinates of a component's first vertex.
    fn raw(&mut self, bits: u32, q: &mut [i32; 3]);
    /// Chooses (encoder) or reads (decoder) which of the `cands` to average: a non-zero
    /// mask over them.
    fn select(&mut self, models: &mut PositionModels, cands: &[[i64; 3]], q: &[i32; 3]) -> u32;
    /// Codes `q - prediction` with the model chosen for each axis by `model(axis, prev)`.
    fn residual(
        &mut self,
        models: &mut PositionModels,
        class: Option<usize>,
        prediction: [i32; 3],
        q: &mut [i32; 3],
    );
}

#[inline]
fn bucket(v: i32) -> usize {
    ((32 - v.unsigned_abs().leading_zeros()) as usize).min(PREV_BUCKETS - 1)
}

/// Residual context class of a selection: how many parallelograms were averaged (1, 2, 3+).
#[inline]
fn class_of(mask: u32) -> usize {
    (mask.count_ones() as usize).min(CLASSES - 1)
}

fn selection_cost(models: &PositionModels, k: usize, mask: u32) -> u32 {
    let all = (1u32 << k) - 1;
    let mut c = models.use_all[k - 1].cost(mask == all);
    if mask == all || k == 1 {
        return c;
    }
    let flags = &models.selection[k - 1];
    for i in 0..k {
        if i == k - 1 && mask & ((1 << i) - 1) == 0 {
            break;
        }
        c += flags[i].cost(mask >> i & 1 == 1);
    }
    c
}

#[inline]
fn model_index(class: usize, axis: usize, prev: usize) -> usize {
    (class * 3 + axis) * PREV_BUCKETS + prev
}

/// Writes residuals to a sink.
pub(crate) struct ResidualWriter<'a> {
    pub sink: &'a mut whet_bits::RangeEncoder,
    /// Choose a subset of the parallelograms per vertex (else always average all).
    pub constrained: bool,
    /// Give up once the output exceeds this many bytes (a cheaper alternative exists).
    pub budget: usize,
}

impl ResidualIo for ResidualWriter<'_> {
    fn exhausted(&self) -> bool {
        self.sink.bytes_written() > self.budget
    }
    fn select(&mut self, models: &mut PositionModels, cands: &[[i64; 3]], q: &[i32; 3]) -> u32 {
        let k = cands.len();
        if !self.constrained {
            return (1u32 << k) - 1;
        }
        // One parallelogram leaves no choice (the flag below still codes it).
        let mut best = (u64::MAX, 1u32);
        if k > 1 {
            // Each subset's sum from a smaller one's (drop its lowest member): the same sums
            // `average` forms, one addition per axis per subset.
            let mut sums = [[0i64; 3]; 1 << MAX_SUBSET_PRICED];
            for mask in 1..(1u32 << k) {
                let p = if k <= MAX_SUBSET_PRICED {
                    let low = mask.trailing_zeros() as usize;
                    let rest = sums[(mask & (mask - 1)) as usize];
                    let c = cands[low];
                    let sum = [rest[0] + c[0], rest[1] + c[1], rest[2] + c[2]];
                    sums[mask as usize] = sum;
                    mean(sum, mask.count_ones() as i64)
                } else {
                    average(cands, mask)
                };
                let class = class_of(mask);
                let mut cost = selection_cost(models, k, mask) as u64;
                let mut prev = 0usize;
                for axis in 0..3 {
                    // Costs only grow: a subset already at the best cost cannot win.
                    if cost >= best.0 {
                        break;
                    }
                    let r = q[axis].wrapping_sub(p[axis]);
                    cost += models.residual[model_index(class, axis, prev)].cost(r) as u64;
                    prev = bucket(r);
                }
                if cost < best.0 {
                    best = (cost, mask);
                }
            }
        }
        let mask = best.1;
        let all = (1u32 << k) - 1;
        self.sink
            .encode_bit(&mut models.use_all[k - 1], mask == all);
        if mask == all || k == 1 {
            return mask;
        }
        let flags = &mut models.selection[k - 1];
        for i in 0..k {
            if i == k - 1 && mask & ((1 << i) - 1) == 0 {
                break; // the last flag is implied when no earlier one was set
            }
            self.sink.encode_bit(&mut flags[i], mask >> i & 1 == 1);
        }
        mask
    }
    fn raw(&mut self, bits: u32, q: &mut [i32; 3]) {
        for c in q.iter() {
            self.sink.encode_direct(*c as u32, bits);
        }
    }
    #[inline(always)]
    fn residual(
        &mut self,
        models: &mut PositionModels,
        class: Option<usize>,
        prediction: [i32; 3],
        q: &mut [i32; 3],
    ) {
        let mut prev = 0usize;
        for axis in 0..3 {
            let r = q[axis].wrapping_sub(prediction[axis]);
            match class {
                Some(cl) => models.residual[model_index(cl, axis, prev)].encode(self.sink, r),
                None => models.seed[axis].encode(self.sink, r),
            }
            prev = bucket(r);
        }
    }
}

/// Both of the encoder's strategies in one walk (the coding order depends only on the
/// connectivity, and the encoder's coordinates are the same in both): averaging every
/// parallelogram into `all`, choosing subsets into `subsets` with its own models. Each
/// vertex's prediction and class for `subsets` are fixed by [`ResidualIo::select`] and used
/// by the [`ResidualIo::residual`] call that follows it.
pub(crate) struct DualWriter<'a> {
    pub all: ResidualWriter<'a>,
    pub subsets: ResidualWriter<'a>,
    pub subset_models: PositionModels,
    pub max_level: i32,
    chosen: Option<(usize, [i32; 3])>,
    /// Set once a prefix of the walk has settled which strategy is cheaper (`true`:
    /// subsets); from then on only that one is coded.
    pub decided: Option<bool>,
    /// Vertices coded from parallelograms so far.
    coded: usize,
}

/// Vertices after which [`DualWriter`] compares its two outputs: a difference of at least
/// [`EARLY_MARGIN`] settles the strategy then; at four times as many, at least a quarter of
/// it does; closer outputs are both coded to the end. Measured on the fixtures at q = 11 and
/// 14 (`whet encode --mode exact`): the winner's margin is 2-42 % wherever it is over 1 %
/// (scanned smooth meshes favour averaging every parallelogram by 2-8 %, CAD parts subsets
/// by 14-42 %; the regular icosphere subsets), and every fixture's and large test mesh's
/// stream is the same as with both coded to the end.
const EARLY_DECISION_VERTICES: usize = 1 << 14;

/// See [`EARLY_DECISION_VERTICES`].
const EARLY_MARGIN: f64 = 0.02;

impl<'a> DualWriter<'a> {
    pub(crate) fn new(
        all: &'a mut whet_bits::RangeEncoder,
        subsets: &'a mut whet_bits::RangeEncoder,
        max_level: i32,
    ) -> Self {
        DualWriter {
            all: ResidualWriter {
                sink: all,
                constrained: false,
                budget: usize::MAX,
            },
            subsets: ResidualWriter {
                sink: subsets,
                constrained: true,
                budget: usize::MAX,
            },
            subset_models: PositionModels::new(),
            max_level,
            chosen: None,
            decided: None,
            coded: 0,
        }
    }

    /// Settles the strategy when the outputs so far differ clearly enough (see
    /// [`EARLY_DECISION_VERTICES`]).
    fn maybe_decide(&mut self) {
        let margin = if self.coded == EARLY_DECISION_VERTICES {
            EARLY_MARGIN
        } else if self.coded == 4 * EARLY_DECISION_VERTICES {
            EARLY_MARGIN / 4.0
        } else {
            return;
        };
        let all = self.all.sink.bytes_written() as f64;
        let subsets = self.subsets.sink.bytes_written() as f64;
        if (subsets - all).abs() >= margin * all.max(subsets) {
            self.decided = Some(subsets < all);
        }
    }
}

impl ResidualIo for DualWriter<'_> {
    fn select(&mut self, models: &mut PositionModels, cands: &[[i64; 3]], q: &[i32; 3]) -> u32 {
        if self.decided != Some(false) {
            let mask = self.subsets.select(&mut self.subset_models, cands, q);
            let p = average(cands, mask).map(|c| c.clamp(0, self.max_level));
            self.chosen = Some((class_of(mask), p));
        }
        self.all.select(models, cands, q)
    }
    fn raw(&mut self, bits: u32, q: &mut [i32; 3]) {
        self.all.raw(bits, q);
        self.subsets.raw(bits, q);
    }
    fn residual(
        &mut self,
        models: &mut PositionModels,
        class: Option<usize>,
        prediction: [i32; 3],
        q: &mut [i32; 3],
    ) {
        if self.decided != Some(true) {
            self.all.residual(models, class, prediction, q);
        }
        if self.decided != Some(false) {
            let (class, prediction) = match (self.chosen.take(), class) {
                (Some((c, p)), Some(_)) => (Some(c), p),
                _ => (class, prediction),
            };
            self.subsets
                .residual(&mut self.subset_models, class, prediction, q);
        }
        if class.is_some() && self.decided.is_none() && self.coded != usize::MAX {
            self.coded += 1;
            self.maybe_decide();
        }
    }
}

/// Reads residuals from a range decoder.
pub(crate) struct ResidualReader<'a, 'b> {
    pub dec: &'a mut RangeDecoder<'b>,
    /// Largest valid grid coordinate.
    pub max_level: i32,
    /// Set when a decoded coordinate left the grid: the stream is corrupt, stop early.
    pub invalid: bool,
    /// The stream chose subsets per vertex.
    pub constrained: bool,
}

impl ResidualIo for ResidualReader<'_, '_> {
    fn exhausted(&self) -> bool {
        self.invalid || self.dec.overran()
    }
    fn select(&mut self, models: &mut PositionModels, cands: &[[i64; 3]], _q: &[i32; 3]) -> u32 {
        let k = cands.len();
        let all = (1u32 << k) - 1;
        if !self.constrained {
            return all;
        }
        if self.dec.decode_bit(&mut models.use_all[k - 1]) || k == 1 {
            return all;
        }
        let flags = &mut models.selection[k - 1];
        let mut mask = 0u32;
        for i in 0..k {
            if i == k - 1 && mask == 0 {
                mask |= 1 << i;
                break;
            }
            if self.dec.decode_bit(&mut flags[i]) {
                mask |= 1 << i;
            }
        }
        mask
    }
    fn raw(&mut self, bits: u32, q: &mut [i32; 3]) {
        for c in q.iter_mut() {
            *c = self.dec.decode_direct(bits) as i32;
            self.invalid |= outside_grid(*c, self.max_level);
        }
    }
    #[inline(always)]
    fn residual(
        &mut self,
        models: &mut PositionModels,
        class: Option<usize>,
        prediction: [i32; 3],
        q: &mut [i32; 3],
    ) {
        let mut prev = 0usize;
        for axis in 0..3 {
            let r = match class {
                Some(cl) => models.residual[model_index(cl, axis, prev)].decode(self.dec),
                None => models.seed[axis].decode(self.dec),
            };
            q[axis] = prediction[axis].wrapping_add(r);
            self.invalid |= outside_grid(q[axis], self.max_level);
            prev = bucket(r);
        }
    }
}

/// Contexts of the static residual code: the traversal's two classes (a gate fallback, one
/// parallelogram) x axis x previous axis's bucket, then the start triangles' three axes.
const STATIC_CONTEXTS: usize = 2 * 3 * PREV_BUCKETS + 3;

/// The static code's context of a residual (see [`STATIC_CONTEXTS`]).
#[inline(always)]
fn static_context(class: Option<usize>, axis: usize, prev: usize) -> usize {
    match class {
        Some(cl) => (cl.min(1) * 3 + axis) * PREV_BUCKETS + prev,
        None => 2 * 3 * PREV_BUCKETS + axis,
    }
}

/// Writes residuals to a static residual code ([`ExactPrediction::TraversalStatic`]); the
/// traversal order never selects, so [`ResidualIo::select`] takes every candidate.
pub(crate) struct StaticResidualWriter {
    pub enc: whet_bits::StaticResidualEncoder,
}

impl ResidualIo for StaticResidualWriter {
    fn select(&mut self, _: &mut PositionModels, cands: &[[i64; 3]], _: &[i32; 3]) -> u32 {
        (1u32 << cands.len()) - 1
    }
    fn raw(&mut self, bits: u32, q: &mut [i32; 3]) {
        for c in q.iter() {
            self.enc.encode_raw(bits, *c as u32);
        }
    }
    #[inline(always)]
    fn residual(
        &mut self,
        _: &mut PositionModels,
        class: Option<usize>,
        prediction: [i32; 3],
        q: &mut [i32; 3],
    ) {
        let mut prev = 0usize;
        for axis in 0..3 {
            let r = q[axis].wrapping_sub(prediction[axis]);
            self.enc.encode(static_context(class, axis, prev), axis, r);
            prev = bucket(r);
        }
    }
}

/// Reads residuals from a static residual code.
pub(crate) struct StaticResidualReader<'a> {
    pub dec: whet_bits::StaticResidualDecoder<'a>,
    /// Largest valid grid coordinate.
    pub max_level: i32,
    /// Set when a decoded coordinate left the grid: the stream is corrupt, stop early.
    pub invalid: bool,
}

impl ResidualIo for StaticResidualReader<'_> {
    fn exhausted(&self) -> bool {
        self.invalid || self.dec.overran()
    }
    fn select(&mut self, _: &mut PositionModels, cands: &[[i64; 3]], _: &[i32; 3]) -> u32 {
        (1u32 << cands.len()) - 1
    }
    fn raw(&mut self, bits: u32, q: &mut [i32; 3]) {
        for c in q.iter_mut() {
            *c = self.dec.decode_raw(bits) as i32;
            self.invalid |= outside_grid(*c, self.max_level);
        }
    }
    #[inline(always)]
    fn residual(
        &mut self,
        _: &mut PositionModels,
        class: Option<usize>,
        prediction: [i32; 3],
        q: &mut [i32; 3],
    ) {
        let mut prev = 0usize;
        for axis in 0..3 {
            // The next context from the symbol's bit length (the same as `bucket(r)`), not
            // from `r`, which waits for the raw bits.
            let (r, length) = self
                .dec
                .decode_with_length(static_context(class, axis, prev), axis);
            q[axis] = prediction[axis].wrapping_add(r);
            self.invalid |= outside_grid(q[axis], self.max_level);
            prev = (length as usize).min(PREV_BUCKETS - 1);
        }
    }
}

/// Per position `j` of a corner in its triangle, `(j, next)` and `(j, prev)`: the corner
/// after corner `c` is `c - j + next`, the one before `c - j + prev`.
const AFTER_BEFORE_CORNER: [((usize, usize), (usize, usize)); 3] =
    [((0, 1), (0, 2)), ((1, 2), (1, 0)), ((2, 0), (2, 1))];

/// Whether grid coordinate `c` lies outside `0..=max_level` (`max_level >= 0`): one
/// unsigned compare, a negative `c` wrapping above every level.
#[inline(always)]
fn outside_grid(c: i32, max_level: i32) -> bool {
    c as u32 > max_level as u32
}

/// Highest priority bucket of the prediction-degree order.
const MAX_DEGREE: usize = 4;

/// Vertex states of the prediction-degree walk, in the low two bits of a vertex's state
/// byte; an unknown vertex keeps its degree (saturating at [`MAX_DEGREE`], all the order
/// distinguishes) above them, so one load tells both and an entry of bucket `d` is current
/// exactly when its vertex's byte is `d << DEGREE_SHIFT`.
const UNKNOWN: u8 = 0;
const KNOWN: u8 = 1;
const DUMMY: u8 = 2;
const STATE_MASK: u8 = 3;
const DEGREE_SHIFT: u32 = 2;
const DEGREE_ONE: u8 = 1 << DEGREE_SHIFT;
const FULL_DEGREE: u8 = (MAX_DEGREE as u8) << DEGREE_SHIFT;

/// The walk state of [`code_positions`]: one byte of state, a degree and an anchor corner
/// per vertex, and the degree buckets.
struct DegreeOrder<'t> {
    cv: &'t [u32],
    opp: &'t [u32],
    /// State and degree per vertex (see [`UNKNOWN`]).
    state: Vec<u8>,
    // Each vertex's fan is walked from an anchor corner fixed by the order itself (the start
    // corners, then the corner where a vertex was first met), never from the table's own
    // vertex_corner: corner numbering differs between the encoder's table and the decoder's.
    anchor: Vec<u32>,
    buckets: [Vec<u32>; MAX_DEGREE + 1],
}

#[inline(always)]
fn next_corner(c: usize) -> usize {
    if c % 3 == 2 {
        c - 2
    } else {
        c + 1
    }
}

impl DegreeOrder<'_> {
    /// One walk around the fan of vertex `v` from its anchor: with `cands`, collects the
    /// parallelogram predictions of `v` (as [`crate::parallelogram::candidates`] does, in
    /// the same order) before `v` is known; and raises the degree of `v`'s unknown
    /// neighbours as if `v` were known (the raise reads only the neighbours' states, so
    /// both fit in one walk). Returns the number of candidates and their sum.
    ///
    /// Each neighbour is queued once per walk, after both its raises: the second vertex of
    /// one fan triangle is the first of the next, and the first triangle's first vertex is
    /// the last triangle's second. An entry queued just before another entry of the same
    /// vertex at the same or a higher degree is never the one popped (the later one sits
    /// above it in its bucket or the earlier one is stale), so the pop order is the same as
    /// queueing at every raise.
    #[inline(always)]
    fn walk(
        &mut self,
        v: usize,
        q: &[[i32; 3]],
        cands: Option<&mut [[i64; 3]; MAX_CANDIDATES]>,
    ) -> (usize, [i64; 3]) {
        // The walk proper takes each array as its own argument: distinct slices let the
        // compiler keep their bounds and base pointers in registers across the stores.
        walk_fan(
            self.cv,
            self.opp,
            &mut self.state,
            &mut self.anchor,
            &mut self.buckets,
            v,
            q,
            cands,
        )
    }

    /// Pops the vertex with the highest degree; stale entries (already known, or queued at
    /// a degree it no longer has) are dropped on the way.
    #[inline]
    fn pop(&mut self) -> Option<usize> {
        for d in (0..=MAX_DEGREE).rev() {
            while let Some(x) = self.buckets[d].pop() {
                let x = x as usize;
                if self.state[x] == (d as u8) << DEGREE_SHIFT {
                    return Some(x);
                }
            }
        }
        None
    }
}

/// Anchors unknown neighbour `x` of a known vertex (at corner `cx`), whose state byte the
/// caller loaded as `sx`, and raises its degree across the triangle whose third vertex is
/// known when `y_known`. True when `x` is unknown, so must be queued.
#[inline(always)]
fn raise(anchor: &mut [u32], state: &mut [u8], x: usize, sx: u8, y_known: bool, cx: usize) -> bool {
    if sx & STATE_MASK != UNKNOWN {
        // A known vertex was anchored before it became known (only queued vertices are
        // popped, and every queued one was anchored here), and a dummy is never walked.
        return false;
    }
    if anchor[x] == u32::MAX {
        anchor[x] = cx as u32;
    }
    if y_known && sx < FULL_DEGREE {
        state[x] = sx + DEGREE_ONE;
    }
    true
}

/// Queues `x` at its current degree.
#[inline(always)]
fn push(state: &[u8], buckets: &mut [Vec<u32>; MAX_DEGREE + 1], x: usize) {
    let d = (state[x] >> DEGREE_SHIFT) as usize;
    buckets[d].push(x as u32);
}

/// [`DegreeOrder::walk`].
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn walk_fan(
    cv: &[u32],
    opp: &[u32],
    state: &mut [u8],
    anchor: &mut [u32],
    buckets: &mut [Vec<u32>; MAX_DEGREE + 1],
    v: usize,
    q: &[[i32; 3]],
    mut cands: Option<&mut [[i64; 3]; MAX_CANDIDATES]>,
) -> (usize, [i64; 3]) {
    let nc = cv.len();
    let start = anchor[v] as usize;
    let mut sum = [0i64; 3];
    if start >= nc {
        return (0, sum);
    }
    let mut count = 0usize;
    let mut c = start;
    let mut guard = 0usize;
    // The first triangle's first vertex (queued at the end) and the previous triangle's
    // second vertex (queued with the next triangle's first raise, normally itself).
    let first = cv[next_corner(start)] as usize;
    let mut first_queued = false;
    let mut pending = usize::MAX;
    loop {
        // One modulo per step: the corners after and before c in its triangle.
        let (ca, cb) = {
            let c32 = c as u32;
            let j = c32 % 3;
            let base = c32 - j;
            let ca = if j == 2 { base } else { c32 + 1 };
            let cb = if j == 0 { base + 2 } else { c32 - 1 };
            (ca as usize, cb as usize)
        };
        let a = cv[ca] as usize;
        let b = cv[cb] as usize;
        // Both state bytes once per step: a raise changes only the degree bits of its own
        // vertex (a != b in a checked table), never whether a vertex is known.
        let (sa, sb) = (state[a], state[b]);
        let (a_known, b_known) = (sa & STATE_MASK == KNOWN, sb & STATE_MASK == KNOWN);
        if let Some(out) = cands.as_deref_mut() {
            if count < MAX_CANDIDATES && a_known && b_known {
                let o = opp[c] as usize;
                if o < nc {
                    let w = cv[o] as usize;
                    if state[w] & STATE_MASK == KNOWN && w != v {
                        let (qa, qb, qw) = (q[a], q[b], q[w]);
                        let p = [
                            qa[0] as i64 + qb[0] as i64 - qw[0] as i64,
                            qa[1] as i64 + qb[1] as i64 - qw[1] as i64,
                            qa[2] as i64 + qb[2] as i64 - qw[2] as i64,
                        ];
                        out[count] = p;
                        sum = [sum[0] + p[0], sum[1] + p[1], sum[2] + p[2]];
                        count += 1;
                    }
                }
            }
        }
        if pending != a && pending != usize::MAX {
            push(state, buckets, pending);
        }
        if raise(anchor, state, a, sa, b_known, ca) && c != start {
            push(state, buckets, a);
        }
        pending = if raise(anchor, state, b, sb, a_known, cb) {
            b
        } else {
            usize::MAX
        };
        let o = opp[ca];
        if o as usize >= nc {
            break;
        }
        let n = (if o % 3 == 2 { o - 2 } else { o + 1 }) as usize;
        if n == start {
            first_queued = pending == first;
            break;
        }
        c = n;
        guard += 1;
        if guard > nc {
            break;
        }
    }
    if pending != usize::MAX {
        push(state, buckets, pending);
    }
    if !first_queued && state[first] & STATE_MASK == UNKNOWN {
        push(state, buckets, first);
    }
    (count, sum)
}

/// Codes each real vertex's grid coordinates through `io`, in the prediction-degree order
/// (Draco's `MESH_TRAVERSAL_PREDICTION_DEGREE` idea): per component, the start triangle's
/// vertices, then always a vertex with the most incident triangles whose two other vertices
/// are known (ties: the most recently raised), so that most vertices are predicted from
/// several parallelograms. The order depends only on the connectivity, which the decoder has
/// in full before the positions. `q` is indexed by table vertex id; on return the vector marks
/// every real vertex reached.
///
/// One walk around each vertex's fan both collects its parallelograms and raises its
/// neighbours' degrees.
pub(crate) fn code_positions<I: ResidualIo>(
    conn: &Connectivity,
    bits: u32,
    q: &mut [[i32; 3]],
    io: &mut I,
) -> Result<Vec<bool>, TraversalError> {
    let table = &conn.table;
    let nv = table.vertex_count();
    let max_level = max_grid_level(bits);
    let mut models = PositionModels::new();
    let mut st = DegreeOrder {
        cv: table.corner_vertices(),
        opp: table.opposites(),
        state: initial_states(conn, nv),
        anchor: vec![u32::MAX; nv],
        buckets: Default::default(),
    };
    // About one queue entry per fan corner; reserve what a closed mesh needs at the start.
    st.buckets[MAX_DEGREE].reserve(nv);
    st.buckets[1].reserve(nv / 4);
    st.buckets[2].reserve(nv / 4);
    let known_vec = |st: &DegreeOrder| st.state.iter().map(|&s| s == KNOWN).collect();

    for &start in &conn.starts {
        if start.index() >= table.corner_count() {
            return Err(TraversalError::BadStart(start.0));
        }
        let corners = [start, table.next(start), table.prev(start)];
        let vs = corners.map(|c| table.vertex(c).index());
        for (&vi, c) in vs.iter().zip(corners) {
            if st.anchor[vi] == u32::MAX {
                st.anchor[vi] = c.0;
            }
        }
        code_start_triangle(io, &mut models, bits, q, &mut st.state, vs);
        for &vi in &vs {
            if st.state[vi] == KNOWN {
                st.walk(vi, q, None);
            }
        }
        let mut cands = [[0i64; 3]; MAX_CANDIDATES];
        while let Some(v) = st.pop() {
            // v was queued by a neighbour, so it has an anchor.
            let corner = st.anchor[v];
            if corner as usize >= table.corner_count() {
                continue;
            }
            let (k, sum) = st.walk(v, q, Some(&mut cands));
            let mut value = q[v];
            // A prediction off the grid is never better than the nearest grid point, and
            // clamping keeps residuals below 2^30. (Clamped in each branch, so that the
            // merged prediction is read back lane by lane, as it was stored.)
            let grid = |p: [i32; 3]| {
                [
                    p[0].clamp(0, max_level),
                    p[1].clamp(0, max_level),
                    p[2].clamp(0, max_level),
                ]
            };
            let (class, prediction) = if k == 0 {
                let known: &[u8] = &st.state;
                (
                    0,
                    grid(neighbour_fallback(
                        table,
                        whet_mesh::CornerId(corner),
                        q,
                        known,
                    )),
                )
            } else {
                let mask = io.select(&mut models, &cands[..k], &value);
                let prediction = if mask == (1u32 << k) - 1 {
                    grid(mean(sum, k as i64))
                } else {
                    let (sum, n) = masked_sum(&cands[..k], mask);
                    grid(mean(sum, n))
                };
                (class_of(mask), prediction)
            };
            io.residual(&mut models, Some(class), prediction, &mut value);
            q[v] = value;
            st.state[v] = KNOWN;
            if io.exhausted() {
                return Ok(known_vec(&st));
            }
        }
    }
    Ok(known_vec(&st))
}

/// The largest grid coordinate at `bits` bits per axis (clamped to 1..=30).
fn max_grid_level(bits: u32) -> i32 {
    ((1u64 << bits.clamp(1, 30)) - 1) as i32
}

/// Each vertex's state before any is coded: a hole's dummy, or unknown.
fn initial_states(conn: &Connectivity, nv: usize) -> Vec<u8> {
    initial_states_in(conn, nv, Vec::new())
}

/// [`initial_states`] in the memory of `buffer` (its contents ignored).
fn initial_states_in(conn: &Connectivity, nv: usize, mut buffer: Vec<u8>) -> Vec<u8> {
    buffer.clear();
    buffer.extend((0..nv).map(|v| {
        if conn.is_dummy.get(v).copied().unwrap_or(false) {
            DUMMY
        } else {
            UNKNOWN
        }
    }));
    buffer
}

/// Codes a component's start triangle `vs` (its vertices in creation order), for both
/// orders: the first unknown vertex raw, the second as a residual from the first, the third
/// from their midpoint; vertices already known or dummies (by their `state` byte) are
/// skipped. Marks the coded ones known.
fn code_start_triangle<I: ResidualIo>(
    io: &mut I,
    models: &mut PositionModels,
    bits: u32,
    q: &mut [[i32; 3]],
    state: &mut [u8],
    vs: [usize; 3],
) {
    let mut first: Option<[i32; 3]> = None;
    let mut second: Option<[i32; 3]> = None;
    for vi in vs {
        if state[vi] & STATE_MASK != UNKNOWN {
            continue;
        }
        let mut value = q[vi];
        match (first, second) {
            (None, _) => {
                io.raw(bits, &mut value);
                first = Some(value);
            }
            (Some(f), None) => {
                io.residual(models, None, f, &mut value);
                second = Some(value);
            }
            (Some(f), Some(s)) => {
                // i64: a corrupt stream can decode values near the i32 limits.
                let mid = [0, 1, 2].map(|k| ((f[k] as i64 + s[k] as i64).div_euclid(2)) as i32);
                io.residual(models, None, mid, &mut value);
            }
        }
        q[vi] = value;
        state[vi] = KNOWN;
    }
}

/// Codes each real vertex's grid coordinates through `io` in traversal order (the order the
/// connectivity decoder creates vertices): per component the start triangle's vertices as
/// [`code_positions`] codes them, then each C triangle's tip predicted by the one
/// parallelogram across its gate (`v(n t) + v(p t) - v(o t)`), or by the gate's known
/// vertices where a hole's dummy takes part. No walk and no queue: the traversal's steps come
/// from the decoder's construction order, so decoding is one pass in memory order.
///
/// Returns the vertex states, in the memory of `states` (its contents ignored): a vertex
/// was coded exactly when its state is `KNOWN`.
pub(crate) fn code_positions_traversal<I: ResidualIo>(
    conn: &Connectivity,
    bits: u32,
    q: &mut [[i32; 3]],
    io: &mut I,
    states: Vec<u8>,
) -> Result<Vec<u8>, TraversalError> {
    let table = &conn.table;
    let nv = table.vertex_count();
    let max_level = i64::from(max_grid_level(bits));
    let mut models = PositionModels::new();
    let cv = table.corner_vertices();
    let opp = table.opposites();
    let nc = cv.len();
    // One byte per vertex: unknown, known, or a dummy (never coded).
    let mut state = initial_states_in(conn, nv, states);
    let mut stop = false;
    // In line in the step loop: called once per step (1.3M on the bench), the closure was
    // a call passing each step through memory (decode 999.9 -> 976.9 M instructions).
    conn.for_each_step(
        #[inline(always)]
        |step| {
            if stop {
                return;
            }
            match step {
                whet_edgebreaker::Step::Start { corner } => {
                    let c = corner.index();
                    if c >= nc {
                        stop = true;
                        return;
                    }
                    let base = c - c % 3;
                    let vs = [c, base + (c + 1) % 3, base + (c + 2) % 3].map(|x| cv[x] as usize);
                    code_start_triangle(io, &mut models, bits, q, &mut state, vs);
                }
                whet_edgebreaker::Step::Triangle {
                    tip,
                    label: whet_edgebreaker::Clers::C,
                    ..
                } => {
                    let t = tip.index();
                    if t >= nc {
                        stop = true;
                        return;
                    }
                    let v = cv[t] as usize;
                    if state[v] != UNKNOWN {
                        return;
                    }
                    // The corners after and before the tip from one modulo.
                    let (after, before) = AFTER_BEFORE_CORNER[t % 3];
                    let a = cv[t - after.0 + after.1] as usize;
                    let b = cv[t - before.0 + before.1] as usize;
                    let o = opp[t] as usize;
                    let w = if o < nc { cv[o] as usize } else { v };
                    let (a_known, b_known) = (state[a] == KNOWN, state[b] == KNOWN);
                    let (class, prediction) = if a_known && b_known && state[w] == KNOWN {
                        // Per axis, clamped into the grid, written out (an array map here was
                        // an out-of-line call per vertex).
                        let (qa, qb, qw) = (q[a], q[b], q[w]);
                        // (`max`/`min`: `clamp` stayed an out-of-line call with its bounds assert.)
                        let x = (qa[0] as i64 + qb[0] as i64 - qw[0] as i64)
                            .max(0)
                            .min(max_level);
                        let y = (qa[1] as i64 + qb[1] as i64 - qw[1] as i64)
                            .max(0)
                            .min(max_level);
                        let z = (qa[2] as i64 + qb[2] as i64 - qw[2] as i64)
                            .max(0)
                            .min(max_level);
                        (1, [x as i32, y as i32, z as i32])
                    } else {
                        (
                            0,
                            partial_gate(a_known.then(|| q[a]), b_known.then(|| q[b])),
                        )
                    };
                    let mut value = q[v];
                    io.residual(&mut models, Some(class), prediction, &mut value);
                    q[v] = value;
                    state[v] = KNOWN;
                    if io.exhausted() {
                        stop = true;
                    }
                }
                _ => {}
            }
        },
    )?;
    Ok(state)
}

/// Prediction without a parallelogram: the midpoint of the first triangle around the vertex
/// with both other vertices known, else the first known neighbour.
fn neighbour_fallback(
    table: &whet_mesh::CornerTable,
    corner: whet_mesh::CornerId,
    q: &[[i32; 3]],
    state: &[u8],
) -> [i32; 3] {
    let known = |x: usize| state[x] == KNOWN;
    let mut c = corner;
    let mut single: Option<usize> = None;
    let mut guard = 0usize;
    loop {
        let a = table.vertex(table.next(c)).index();
        let b = table.vertex(table.prev(c)).index();
        if known(a) && known(b) {
            return gate_midpoint(q[a], q[b]);
        }
        if single.is_none() {
            single = [a, b].into_iter().find(|&x| known(x));
        }
        match table.swing(c) {
            Some(n) if n != corner => c = n,
            _ => break,
        }
        guard += 1;
        if guard > table.corner_count() {
            break;
        }
    }
    single.map(|x| q[x]).unwrap_or([0; 3])
}

/// How an exact-mode stream orders and predicts its positions (header field
/// `exact_prediction`, docs/format.md).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum ExactPrediction {
    /// The prediction-degree order (the vertex with the most known parallelograms next),
    /// averaging them or a subset the encoder chose: the smaller stream (the default).
    #[default]
    Degree,
    /// Traversal order, one parallelogram across each vertex's gate: no walk and no queue,
    /// so about 1.8 times as fast to decode and 1.3 times as fast to encode, for 3-15 %
    /// more bytes on most meshes and up to about 50 % on blocky CAD parts (one parallelogram
    /// across a crease predicts badly). Format 1.5.
    Traversal,
    /// The traversal order and prediction of [`ExactPrediction::Traversal`], its residuals
    /// coded with one static frequency table per context for the whole stream and four
    /// interleaved rANS states, one per axis ([`whet_bits::StaticResidualEncoder`]) instead
    /// of adaptive models, and the connectivity's labels likewise
    /// ([`whet_edgebreaker::LabelCode::Static`]): a table lookup per coordinate and per label
    /// where the adaptive codes search and update their models, for streams that must decode
    /// fastest. Format 1.6.
    TraversalStatic,
}

impl ExactPrediction {
    /// The value of header field `exact_prediction`.
    pub const fn code(self) -> u64 {
        match self {
            ExactPrediction::Degree => 0,
            ExactPrediction::Traversal => 1,
            ExactPrediction::TraversalStatic => 2,
        }
    }

    /// How the connectivity payload of a stream with this prediction codes its labels: the
    /// static code with the static residual code.
    pub const fn label_code(self) -> whet_edgebreaker::LabelCode {
        match self {
            ExactPrediction::TraversalStatic => whet_edgebreaker::LabelCode::Static,
            _ => whet_edgebreaker::LabelCode::Adaptive,
        }
    }

    /// The prediction of a header value; `None` for a value this build does not know.
    pub const fn from_code(code: u64) -> Option<ExactPrediction> {
        match code {
            0 => Some(ExactPrediction::Degree),
            1 => Some(ExactPrediction::Traversal),
            2 => Some(ExactPrediction::TraversalStatic),
            _ => None,
        }
    }
}

/// The two payloads of an exact-mode stream and what the encoder knows about them.
#[derive(Clone, Debug)]
pub struct ExactPayloads {
    /// Connectivity section payload.
    pub connectivity: Vec<u8>,
    /// Geometry section payload.
    pub geometry: Vec<u8>,
    /// The quantization grid.
    pub quantizer: crate::Quantizer,
    /// Input vertex of each output vertex (the decoder's vertex order).
    pub vertex_order: Vec<u32>,
    /// Components coded.
    pub components: usize,
    /// Triangles coded.
    pub triangles: usize,
    /// Counts of C, L, E, R, S.
    pub clers_histogram: [usize; 5],
}

/// Encodes an oriented manifold (holes, handles, components allowed) in the exact mode.
/// `bbox` is `mesh`'s bounding box (the caller's, computed once: a pass over the positions
/// costs a few milliseconds on a large mesh).
pub(crate) fn encode_exact(
    mesh: &whet_mesh::Mesh,
    bbox: &whet_mesh::Aabb,
    table: whet_mesh::CornerTable,
    bits: u32,
    check_fans: bool,
    prediction: ExactPrediction,
    scratch: &mut Scratch,
) -> Result<ExactPayloads, crate::Error> {
    encode_exact_with(
        mesh, bbox, table, bits, check_fans, true, prediction, scratch,
    )
    .map(|(p, _)| p)
}

/// [`encode_exact`], with or without the early choice of the geometry strategy; also says
/// whether the choice was made early (`Some(true)`: subsets).
#[allow(clippy::too_many_arguments)] // the stages' inputs, passed through once
fn encode_exact_with(
    mesh: &whet_mesh::Mesh,
    bbox: &whet_mesh::Aabb,
    table: whet_mesh::CornerTable,
    bits: u32,
    check_fans: bool,
    early: bool,
    prediction: ExactPrediction,
    scratch: &mut Scratch,
) -> Result<(ExactPayloads, Option<bool>), crate::Error> {
    if !bbox.is_empty() && !bbox.size().max_element().is_finite() {
        // The grid's step would be infinite: every position would land on one corner.
        return Err(crate::Error::InvalidInput(
            whet_mesh::MeshError::ExtentOverflow,
        ));
    }
    let quantizer = crate::Quantizer::new(bbox, bits);
    let mut enc = whet_edgebreaker::encode_connectivity_coded_in(
        table,
        &mesh.triangles,
        mesh.positions.len(),
        prediction.label_code(),
        scratch,
    )?;
    let clers_histogram = enc.histogram();
    // The geometry passes walk a copy of the table relabelled in traversal order: the same
    // corners, so the same coding order, but walked roughly in memory order.
    let (conn, old_id) = enc.traversal_ordered_in(scratch)?;
    if check_fans {
        // The input's table was built without walking its closed fans: walk them here, in
        // memory order. (The relabelled table is the same mesh, closed.)
        conn.table
            .check_fans()
            .map_err(crate::Error::InvalidInput)?;
    }
    let vertex_order = enc
        .connectivity
        .output_vertices_iter()
        .map(|v| v.0)
        .collect();
    // Quantize in input order and scatter to the traversal order: on an input in random
    // order, scattered stores overlap where gathered loads would wait one by one.
    let mut new_id = scratch.take_filled(mesh.positions.len(), u32::MAX);
    for (new, &old) in old_id.iter().enumerate() {
        if let Some(slot) = new_id.get_mut(old as usize) {
            if *slot != u32::MAX {
                // One input vertex became two traversal vertices: the only contact of two
                // components, which the traversal ranks once per component (the deferred
                // fan check cannot see it: the relabelled table has split it). Only one
                // copy would get the position; the caller's full path cuts the vertex with
                // `make_manifold` and reports it.
                return Err(crate::Error::InvalidInput(
                    whet_mesh::MeshError::NonManifoldVertex {
                        vertex: old,
                        fans: 2,
                    },
                ));
            }
            *slot = new as u32;
        }
    }
    let mut q: Vec<[i32; 3]> = scratch.take_filled(conn.table.vertex_count(), [0; 3]);
    for (p, &new) in mesh.positions.iter().zip(&new_id) {
        if let Some(qi) = q.get_mut(new as usize) {
            *qi = quantizer.quantize(*p);
        }
    }
    scratch.give(new_id);
    scratch.give(old_id);
    let (geometry, decided) = match prediction {
        ExactPrediction::Degree => degree_geometry(&conn, bits, &mut q, early)?,
        ExactPrediction::Traversal => {
            // One coder, no strategy to choose: the payload is the residuals alone.
            let mut sink = whet_bits::RangeEncoder::new();
            let mut io = ResidualWriter {
                sink: &mut sink,
                constrained: false,
                budget: usize::MAX,
            };
            let states = scratch.take_empty(conn.table.vertex_count());
            let states = code_positions_traversal(&conn, bits, &mut q, &mut io, states)
                .map_err(whet_edgebreaker::Error::from)?;
            scratch.give(states);
            (sink.finish(), None)
        }
        ExactPrediction::TraversalStatic => {
            let mut io = StaticResidualWriter {
                enc: whet_bits::StaticResidualEncoder::new(STATIC_CONTEXTS),
            };
            let states = scratch.take_empty(conn.table.vertex_count());
            let states = code_positions_traversal(&conn, bits, &mut q, &mut io, states)
                .map_err(whet_edgebreaker::Error::from)?;
            scratch.give(states);
            (io.enc.finish(), None)
        }
    };
    scratch.give(q);
    let components = conn.starts.len();
    conn.recycle(scratch);
    let connectivity = std::mem::take(&mut enc.bytes);
    enc.recycle(scratch);
    Ok((
        ExactPayloads {
            connectivity,
            geometry,
            quantizer,
            vertex_order,
            components,
            triangles: mesh.triangles.len(),
            clers_histogram,
        },
        decided,
    ))
}

/// The degree order's geometry payload and whether the strategy was settled early
/// (`Some(true)`: subsets). Per mesh, keep the cheaper of the two prediction strategies:
/// averaging every parallelogram suits smooth surfaces, choosing subsets suits creased CAD
/// parts. Both are coded in one walk until a prefix settles the choice
/// (EARLY_DECISION_VERTICES); coded to the end, subsets win only when strictly smaller.
fn degree_geometry(
    conn: &Connectivity,
    bits: u32,
    q: &mut [[i32; 3]],
    early: bool,
) -> Result<(Vec<u8>, Option<bool>), crate::Error> {
    let max_level = max_grid_level(bits);
    let mut all = whet_bits::RangeEncoder::new();
    let mut subsets = whet_bits::RangeEncoder::new();
    all.encode_direct(0, 1);
    subsets.encode_direct(1, 1);
    let mut io = DualWriter::new(&mut all, &mut subsets, max_level);
    if !early {
        io.coded = usize::MAX;
    }
    code_positions(conn, bits, q, &mut io).map_err(whet_edgebreaker::Error::from)?;
    let decided = io.decided;
    let (all, subsets) = (all.finish(), subsets.finish());
    let geometry = match decided {
        // The other coder stopped when the prefix settled it.
        Some(true) => subsets,
        Some(false) => all,
        None if subsets.len() < all.len() => subsets,
        None => all,
    };
    Ok((geometry, decided))
}

/// Decodes the two payloads of an exact-mode stream.
/// The arrays the exact decoder works in, kept between decodes (see
/// [`crate::DecodeBuffers`]).
#[derive(Debug, Default)]
pub(crate) struct ExactBuffers {
    pub connectivity: whet_edgebreaker::ConnectivityBuffers,
    grid: Vec<[i32; 3]>,
    states: Vec<u8>,
    pub positions: Vec<whet_mesh::DVec3>,
}

/// The decoder's error for a static residual code that failed its checks.
fn geometry_error(e: &whet_bits::Error) -> crate::Error {
    match e {
        whet_bits::Error::Truncated => crate::Error::Truncated("geometry"),
        whet_bits::Error::Corrupt(what) => crate::Error::Corrupt(format!("geometry: {what}")),
        other => crate::Error::Corrupt(format!("geometry: {other}")),
    }
}

pub(crate) fn decode_exact(
    connectivity: &[u8],
    geometry: &[u8],
    quantizer: &crate::Quantizer,
    limits: &whet_edgebreaker::ConnectivityLimits,
    prediction: ExactPrediction,
    buffers: &mut ExactBuffers,
) -> Result<whet_mesh::Mesh, crate::Error> {
    let (conn, used) = whet_edgebreaker::decode_connectivity_coded(
        connectivity,
        limits,
        prediction.label_code(),
        &mut buffers.connectivity,
    )?;
    if used != connectivity.len() {
        return Err(crate::Error::Corrupt(
            "connectivity section has trailing bytes".into(),
        ));
    }
    let nv = conn.table.vertex_count();
    // Kept from the last decode as it is: both orders read a vertex's coordinates only once
    // it is known (decoded in this decode), so only new entries need a value.
    let mut q = std::mem::take(&mut buffers.grid);
    q.resize(nv, [0; 3]);
    // Per vertex, whether it was decoded: the degree walk's flags, or the traversal's
    // states (kept for the next decode); and whether a coordinate left the grid (every one
    // the readers decode is checked as it is written, so below only each real vertex's
    // state is).
    let (known, states, off_grid) = if prediction == ExactPrediction::TraversalStatic {
        let dec = whet_bits::StaticResidualDecoder::new(geometry, STATIC_CONTEXTS)
            .map_err(|e| geometry_error(&e))?;
        let mut io = StaticResidualReader {
            dec,
            max_level: quantizer.max_level(),
            invalid: false,
        };
        let states = std::mem::take(&mut buffers.states);
        let states = code_positions_traversal(&conn, quantizer.bits, &mut q, &mut io, states)
            .map_err(whet_edgebreaker::Error::from)?;
        if !io.invalid {
            io.dec.finish().map_err(|e| geometry_error(&e))?;
        }
        (Vec::new(), Some(states), io.invalid)
    } else {
        let mut dec =
            RangeDecoder::new(geometry).map_err(|_| crate::Error::Truncated("geometry"))?;
        // The degree order's payload opens with its strategy bit; the traversal order has
        // none.
        let constrained = prediction == ExactPrediction::Degree && dec.decode_direct(1) == 1;
        let mut io = ResidualReader {
            dec: &mut dec,
            constrained,
            max_level: quantizer.max_level(),
            invalid: false,
        };
        let (known, states) = match prediction {
            ExactPrediction::Degree => (
                code_positions(&conn, quantizer.bits, &mut q, &mut io)
                    .map_err(whet_edgebreaker::Error::from)?,
                None,
            ),
            _ => {
                let states = std::mem::take(&mut buffers.states);
                let states =
                    code_positions_traversal(&conn, quantizer.bits, &mut q, &mut io, states)
                        .map_err(whet_edgebreaker::Error::from)?;
                (Vec::new(), Some(states))
            }
        };
        let off_grid = io.invalid;
        if dec.finish().is_err() {
            return Err(crate::Error::Truncated("geometry"));
        }
        (known, states, off_grid)
    };
    // decode_connectivity numbers the vertices in traversal order, the real ones first: the
    // output is ids 0..real in order, and the triangles that touch no dummy.
    let real = conn.is_dummy.iter().position(|&d| d).unwrap_or(nv);
    let mut positions = std::mem::take(&mut buffers.positions);
    positions.clear();
    positions.reserve(real);
    // Every real vertex decoded, checked without branches in the pass that writes the
    // positions (sequential: the output's ids are the traversal's).
    let mut bad = off_grid;
    match &states {
        Some(s) => positions.extend(q[..real].iter().zip(&s[..real]).map(|(g, &st)| {
            bad |= st != KNOWN;
            quantizer.dequantize(*g)
        })),
        None => positions.extend(q[..real].iter().zip(&known[..real]).map(|(g, &k)| {
            bad |= !k;
            quantizer.dequantize(*g)
        })),
    }
    if bad {
        return Err(crate::Error::Corrupt(
            "a decoded position falls outside the quantization grid".into(),
        ));
    }
    buffers.grid = q;
    if let Some(s) = states {
        buffers.states = s;
    }
    // The triangles leave with the mesh; the table's other arrays stay for the next decode.
    let mut triangles = buffers.connectivity.recycle_all_but_triangles(conn);
    if real < nv {
        triangles.retain(|t| t.iter().all(|&x| (x as usize) < real));
    }
    Ok(whet_mesh::Mesh::new(positions, triangles))
}

#[cfg(test)]
mod tests {
    use super::encode_exact_with;

    #[test]
    fn outside_grid_is_the_signed_range_test() {
        for max in [0, 1, 2047, (1 << 30) - 1] {
            for c in [
                i32::MIN,
                -(1 << 30),
                -2,
                -1,
                0,
                1,
                max - 1,
                max,
                max + 1,
                i32::MAX,
            ] {
                assert_eq!(
                    super::outside_grid(c, max),
                    c < 0 || c > max,
                    "{c} against {max}"
                );
            }
        }
    }

    fn payloads(mesh: &whet_mesh::Mesh, bits: u32, early: bool) -> (Vec<u8>, Option<bool>) {
        let table = whet_mesh::CornerTable::new(mesh).unwrap();
        let (p, decided) = encode_exact_with(
            mesh,
            &mesh.bounding_box(),
            table,
            bits,
            false,
            early,
            super::ExactPrediction::Degree,
            &mut whet_mesh::Scratch::new(),
        )
        .unwrap();
        (p.geometry, decided)
    }

    /// The strategy settled after 16k vertices is the one coding both to the end picks: on
    /// the armadillo (43k vertices; averaging every parallelogram wins by 6 % at 11 bits)
    /// and on joint (21k vertices, a CAD part; subsets win by 19 %), the same geometry
    /// payload byte for byte, the choice made early.
    #[test]
    fn the_early_strategy_choice_matches_the_full_one() {
        for (name, subsets) in [("armadillo.off", false), ("joint.off", true)] {
            let mesh = whet_io::read_path(&whet_testkit::shared_fixture(name), None).unwrap();
            assert!(mesh.positions.len() > 1 << 14, "{name}");
            let (early, decided) = payloads(&mesh, 11, true);
            let (full, none) = payloads(&mesh, 11, false);
            assert_eq!(none, None, "{name}");
            assert_eq!(decided, Some(subsets), "{name}");
            assert_eq!(early, full, "{name}");
        }
    }
}
