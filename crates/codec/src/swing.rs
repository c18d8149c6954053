//! The `swing` mode's geometry (SwingWrapper; Attene, Falcidieno, Spagnuolo, Rossignac, ACM
//! TOG 22(4) 2003; `../shared/docs/algorithms.md` 1.3, 1.6, 1.8, 1.10): the one vertex
//! reconstruction the retiler (whet-swing, encoder side) and the decoder both run, the coding
//! of the swing indices, and the swing container's writer and reader.
//!
//! ```text
//!                 tip = P(q·Δ)                    m  = (a + b) / 2
//!                  *  ^ e2 (parent's normal)      r  = sqrt(L² - |b - a|² / 4)
//!                 /|\ |                           e1 = away from c, in the parent's plane,
//!             L  / | \ L                               perpendicular to the gate
//!               /  |r \                           e2 = u × e1, u = (b - a) / |b - a|
//!          a --+---m---+-- b   gate a -> b        P(θ) = m + r cos θ · e1 + r sin θ · e2
//!               \  |  /
//!                \ | /        parent (b, a, c)    θ = 0 continues the parent flat across
//!                  c                              the gate; θ > 0 folds outwards.
//! ```
//!
//! Invariants. Encoder and decoder compute every frame and tip with [`SwingFrame::new`] and
//! [`SwingFrame::tip`] from *decoded* positions only, in f64, with the arithmetic spelled out
//! component by component (no glam kernels, no `mul_add`, no std `sin`/`cos`: the angle
//! table comes from `libm` once per stream), so the two sides agree to the last bit on every
//! platform. Seeds (three vertices per component) are quantized on the stream's cubic grid
//! and the encoder continues from their dequantized positions.
//!
//! Geometry payload (the container's `geometry` section): one byte giving its kind, then
//!
//! * kind 0, swing: one range-coded stream walked in the Edgebreaker traversal order of the
//!   decoded connectivity: at each component start the seed's three vertices as raw
//!   `quant_bits`-bit grid coordinates, at each `C` triangle the tip's swing index as a
//!   zigzagged `angle_bits`-bit value through one adaptive bit tree (`docs/swing.md`);
//! * kind 2, swing with deletions: kind 0, then one adaptive flag per triangle in traversal
//!   order (context: the previous flag); the decoder deletes the flagged triangles and the
//!   vertices left unused. This is how originals with boundaries are coded: the retiler
//!   closes their holes, retiles, and flags the triangles over the holes (whet-swing
//!   `holes.rs`);
//! * kinds 3 and 4: kinds 0 and 2 with each index coded as the residual of the fan-normal
//!   prediction ([`predict_swing`]), one bit tree per bucket of the prediction;
//! * kinds 5 and 6 (format 1.2): kinds 3 and 4 with the predicted
//!   angle scaled by [`PREDICTION_SCALE`] ([`predict_swing_scaled`]) and the residuals coded
//!   through adaptive frequency tables instead of bit trees;
//! * kinds 7 and 8 (format 1.2): kinds 5 and 6 with the connectivity coded inside the walk,
//!   label by label in creation order, in the context of the geometry rebuilt around each
//!   gate (module `front`); the connectivity section holds only the triangle count;
//! * kinds 9 and 10, **what the encoder writes** unless kind 7 or 8 is smaller (format 1.3):
//!   kinds 7 and 8 with each index predicted from its neighbourhood and its residual coded
//!   bit by bit (module `neighbours`). The encoder falls back to kinds 5 and 6 if the forward
//!   walk does not reproduce the retiled mesh;
//! * kind 1, explicit: the exact mode's position coder on the kept retiled triangles,
//!   positions quantized to `quant_bits` — only the safety net for a failed encoder
//!   self-check (a retiler bug), never written otherwise.
//!
//! Not handled here: the retiling itself (whet-swing).

use crate::exact::{code_positions, ResidualReader, ResidualWriter};
use crate::surface_filter::{self, SurfaceFilter, WalkSums};
use crate::{EncodeReport, Error, Quantizer};
use whet_bits::{BitModel, BitSink, BitTree, RangeDecoder, RangeEncoder, SymbolModel};
use whet_edgebreaker::{Clers, Connectivity, ConnectivityLimits, Step};
use whet_format::{tag, Container, Header, Mode, SectionKind, Version};
use whet_mesh::{Aabb, DVec3, ManifoldRepair, Mesh, VertexId};

#[path = "swing_front.rs"]
mod front;
#[path = "swing_neighbours.rs"]
mod neighbours;

/// The format version of geometry kinds 5 and 6.
const VERSION_1_2: Version = Version::new(1, 2);
/// The format version of geometry kinds 9 and 10.
const VERSION_1_3: Version = Version::new(1, 3);
/// The format version of the extended surface filter (header fields 34, 36 and 38).
const VERSION_1_4: Version = Version::new(1, 4);

/// Fewest angle bits a stream may use.
pub const MIN_ANGLE_BITS: u32 = 3;
/// Most angle bits a stream may use (the bit tree of the index coder is `2^bits` models).
pub const MAX_ANGLE_BITS: u32 = 14;

/// Geometry payload kinds (first byte of the geometry section).
const KIND_SWING: u8 = 0;
const KIND_EXPLICIT: u8 = 1;
const KIND_SWING_CUT: u8 = 2;
/// Kinds 0 and 2 with the swing indices coded as residuals of the fan-normal prediction
/// ([`predict_swing`]), one bit tree per bucket of the prediction.
const KIND_SWING_PRED: u8 = 3;
const KIND_SWING_PRED_CUT: u8 = 4;
/// Kinds 3 and 4 with the prediction scaled ([`predict_swing_scaled`]) and the residuals
/// coded through adaptive frequency tables (format 1.2); the encoder's fallback when the
/// forward walk does not reproduce the retiling.
const KIND_SWING_SCALED: u8 = 5;
const KIND_SWING_SCALED_CUT: u8 = 6;
/// Kinds 5 and 6 with the connectivity coded in the walk ([`front`]); format 1.2, what the
/// encoder writes when it is smaller than kind 9 or 10.
const KIND_SWING_FORWARD: u8 = 7;
const KIND_SWING_FORWARD_CUT: u8 = 8;
/// Kinds 7 and 8 with the neighbourhood prediction and bitwise residuals ([`neighbours`]);
/// what the encoder writes unless kind 7 or 8 is smaller (format 1.3).
const KIND_SWING_NEIGHBOURS: u8 = 9;
const KIND_SWING_NEIGHBOURS_CUT: u8 = 10;

/// How a forward walk (kinds 7 to 10) codes its swing indices.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ForwardCoding {
    /// Kinds 7 and 8: the kind 5 prediction and frequency tables.
    Scaled,
    /// Kinds 9 and 10: the neighbourhood prediction and bitwise residuals.
    Neighbours,
}

impl ForwardCoding {
    fn kind(self, cutting: bool) -> u8 {
        match (self, cutting) {
            (ForwardCoding::Scaled, false) => KIND_SWING_FORWARD,
            (ForwardCoding::Scaled, true) => KIND_SWING_FORWARD_CUT,
            (ForwardCoding::Neighbours, false) => KIND_SWING_NEIGHBOURS,
            (ForwardCoding::Neighbours, true) => KIND_SWING_NEIGHBOURS_CUT,
        }
    }
}

/// How a stream codes its swing indices (by geometry kind).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum IndexCoding {
    /// Kinds 0 and 2: the zigzagged index through one bit tree.
    Order0,
    /// Kinds 3 and 4: the residual of [`predict_swing`], a bit tree per bucket.
    Predicted,
    /// Kinds 5 and 6: the residual of [`predict_swing_scaled`], a frequency table per bucket.
    Scaled,
}

impl IndexCoding {
    /// The coding of geometry kind `kind` and whether the kind carries deletion flags
    /// (`None`: not a swing-index kind).
    fn of_kind(kind: u8) -> Option<(IndexCoding, bool)> {
        match kind {
            KIND_SWING => Some((IndexCoding::Order0, false)),
            KIND_SWING_CUT => Some((IndexCoding::Order0, true)),
            KIND_SWING_PRED => Some((IndexCoding::Predicted, false)),
            KIND_SWING_PRED_CUT => Some((IndexCoding::Predicted, true)),
            KIND_SWING_SCALED => Some((IndexCoding::Scaled, false)),
            KIND_SWING_SCALED_CUT => Some((IndexCoding::Scaled, true)),
            _ => None,
        }
    }

    /// The geometry kind of this coding, with or without deletion flags.
    fn kind(self, cutting: bool) -> u8 {
        match (self, cutting) {
            (IndexCoding::Order0, false) => KIND_SWING,
            (IndexCoding::Order0, true) => KIND_SWING_CUT,
            (IndexCoding::Predicted, false) => KIND_SWING_PRED,
            (IndexCoding::Predicted, true) => KIND_SWING_PRED_CUT,
            (IndexCoding::Scaled, false) => KIND_SWING_SCALED,
            (IndexCoding::Scaled, true) => KIND_SWING_SCALED_CUT,
        }
    }
}

// --- Exact arithmetic helpers --------------------------------------------------------------
// Spelled out so that the evaluation order is fixed by this file, not by a library version.

#[inline]
fn sub(a: DVec3, b: DVec3) -> DVec3 {
    DVec3::new(a.x - b.x, a.y - b.y, a.z - b.z)
}

#[inline]
fn add(a: DVec3, b: DVec3) -> DVec3 {
    DVec3::new(a.x + b.x, a.y + b.y, a.z + b.z)
}

#[inline]
fn scale(a: DVec3, s: f64) -> DVec3 {
    DVec3::new(a.x * s, a.y * s, a.z * s)
}

#[inline]
fn dot(a: DVec3, b: DVec3) -> f64 {
    a.x * b.x + a.y * b.y + a.z * b.z
}

/// `x` is finite and above `min` (false for NaN).
#[inline]
fn finite_above(x: f64, min: f64) -> bool {
    x.is_finite() && x > min
}

#[inline]
fn cross(a: DVec3, b: DVec3) -> DVec3 {
    DVec3::new(
        a.y * b.z - a.z * b.y,
        a.z * b.x - a.x * b.z,
        a.x * b.y - a.y * b.x,
    )
}

/// Cosines and sines of the `2^bits` quantized swing angles `q · 2π / 2^bits`,
/// `q ∈ [-2^(bits-1), 2^(bits-1))`, computed once per stream with `libm`.
#[derive(Clone, Debug, PartialEq)]
pub struct AngleTable {
    bits: u32,
    /// `2^bits / 2π`, computed once (the same division the prediction used to repeat).
    inverse_step: f64,
    cos: Vec<f64>,
    sin: Vec<f64>,
}

impl AngleTable {
    /// The table for `bits` angle bits ([`MIN_ANGLE_BITS`]..=[`MAX_ANGLE_BITS`]).
    pub fn new(bits: u32) -> Option<AngleTable> {
        if !(MIN_ANGLE_BITS..=MAX_ANGLE_BITS).contains(&bits) {
            return None;
        }
        let n = 1usize << bits;
        let step = Self::step_of(bits);
        let mut cos = Vec::with_capacity(n);
        let mut sin = Vec::with_capacity(n);
        for s in 0..n as u32 {
            let q = Self::signed_of(bits, s);
            let theta = q as f64 * step;
            cos.push(libm::cos(theta));
            sin.push(libm::sin(theta));
        }
        Some(AngleTable {
            bits,
            inverse_step: (1u64 << bits) as f64 / (2.0 * std::f64::consts::PI),
            cos,
            sin,
        })
    }

    #[inline]
    fn step_of(bits: u32) -> f64 {
        // 2π / 2^bits: a division by a power of two, exact.
        2.0 * std::f64::consts::PI / (1u64 << bits) as f64
    }

    #[inline]
    fn signed_of(bits: u32, symbol: u32) -> i32 {
        let half = 1i32 << (bits - 1);
        let s = (symbol & ((1u32 << bits) - 1)) as i32;
        if s >= half {
            s - (1 << bits)
        } else {
            s
        }
    }

    /// Angle bits.
    #[inline]
    pub fn bits(&self) -> u32 {
        self.bits
    }

    /// The quantization step `Δ = 2π / 2^bits`.
    #[inline]
    pub fn step(&self) -> f64 {
        Self::step_of(self.bits)
    }

    /// `1 / Δ` (the prediction multiplies by it).
    #[inline]
    pub fn inverse_step(&self) -> f64 {
        self.inverse_step
    }

    /// Smallest swing index.
    #[inline]
    pub fn min_index(&self) -> i32 {
        -(1 << (self.bits - 1))
    }

    /// Largest swing index.
    #[inline]
    pub fn max_index(&self) -> i32 {
        (1 << (self.bits - 1)) - 1
    }

    /// The swing index nearest to angle `theta` (radians, wrapped into the index range).
    pub fn quantize(&self, theta: f64) -> i32 {
        let q = crate::quantize::round_half_away(theta / self.step());
        if !q.is_finite() {
            return 0;
        }
        let n = 1i64 << self.bits;
        let q = (q as i64).rem_euclid(n) as u32;
        Self::signed_of(self.bits, q)
    }

    /// The angle of index `q`.
    #[inline]
    pub fn angle(&self, q: i32) -> f64 {
        q as f64 * self.step()
    }

    /// `(cos, sin)` of index `q` (taken modulo `2^bits`).
    #[inline]
    pub fn cos_sin(&self, q: i32) -> (f64, f64) {
        let s = (q as u32 & ((1u32 << self.bits) - 1)) as usize;
        (self.cos[s], self.sin[s])
    }
}

/// The circle on which a swing tip lies: centre `m` (the gate's midpoint), radius `r` and the
/// frame `(e1, e2)` of its plane (`algorithms.md` 1.3).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SwingFrame {
    /// The gate's midpoint.
    pub center: DVec3,
    /// Radius: every point of the circle is at distance `L` from both gate ends.
    pub radius: f64,
    /// Unit gate direction `a -> b` (the circle's axis).
    pub axis: DVec3,
    /// Unit vector in the parent's plane, perpendicular to the gate, away from the parent.
    pub e1: DVec3,
    /// `axis × e1`: the parent's outward normal.
    pub e2: DVec3,
}

impl SwingFrame {
    /// The frame for gate `a -> b` whose parent triangle `(b, a, c)` is already built, with
    /// target edge length `edge_length`. `None` when the swing does not exist: the gate is
    /// not shorter than `2 L` (up to a relative 1e-9), the gate has no length, or `c` lies on
    /// the gate's line. Encoder and decoder both call this, so they agree on `None` too.
    #[inline(always)]
    pub fn new(a: DVec3, b: DVec3, c: DVec3, edge_length: f64) -> Option<SwingFrame> {
        let d = sub(b, a);
        let g2 = dot(d, d);
        if !finite_above(g2, 0.0) {
            return None;
        }
        let g = g2.sqrt();
        let l2 = edge_length * edge_length;
        let r2 = l2 - 0.25 * g2;
        if !finite_above(r2, l2 * 1e-9) {
            return None;
        }
        let radius = r2.sqrt();
        let u = scale(d, 1.0 / g);
        let m = scale(add(a, b), 0.5);
        let w = sub(m, c);
        let w_perp = sub(w, scale(u, dot(w, u)));
        let len2 = dot(w_perp, w_perp);
        if !finite_above(len2, g2 * 1e-18) {
            return None;
        }
        let e1 = scale(w_perp, 1.0 / len2.sqrt());
        let e2 = cross(u, e1);
        Some(SwingFrame {
            center: m,
            radius,
            axis: u,
            e1,
            e2,
        })
    }

    /// The point of the circle at angle `(cos, sin)`.
    #[inline]
    pub fn point(&self, cos: f64, sin: f64) -> DVec3 {
        let rc = self.radius * cos;
        let rs = self.radius * sin;
        add(self.center, add(scale(self.e1, rc), scale(self.e2, rs)))
    }

    /// The tip of swing index `q`: the reconstruction both sides use.
    #[inline]
    pub fn tip(&self, table: &AngleTable, q: i32) -> DVec3 {
        let (c, s) = table.cos_sin(q);
        self.point(c, s)
    }

    /// The swing angle of point `p` (projected on the circle's plane), in `(-π, π]`.
    /// Encoder-side helper: not part of the bit-exact reconstruction.
    pub fn angle_of(&self, p: DVec3) -> f64 {
        let d = p - self.center;
        d.dot(self.e2).atan2(d.dot(self.e1))
    }
}

/// The parameters of a swing stream that are not in the connectivity.
#[derive(Clone, Debug, PartialEq)]
pub struct SwingParams {
    /// Target edge length `L` (absolute units).
    pub edge_length: f64,
    /// The quantized angles.
    pub angles: AngleTable,
    /// The grid the seeds are quantized on.
    pub quantizer: Quantizer,
    /// The box the grid was made from (written to the header, so the decoder rebuilds the
    /// very same grid).
    pub bbox: Aabb,
}

impl SwingParams {
    /// Parameters for edge length `edge_length`, `angle_bits` angle bits and seed positions
    /// quantized to `quant_bits` bits in `bbox`.
    pub fn new(
        edge_length: f64,
        angle_bits: u32,
        bbox: &Aabb,
        quant_bits: u32,
    ) -> Result<SwingParams, Error> {
        if !(edge_length > 0.0 && edge_length.is_finite()) {
            return Err(Error::Parameter(format!(
                "the swing edge length must be positive and finite, got {edge_length}"
            )));
        }
        if bbox.is_empty()
            || !bbox.min.is_finite()
            || !bbox.max.is_finite()
            || !bbox.size().max_element().is_finite()
        {
            return Err(Error::Parameter(
                "the swing mode needs a non-empty, finite bounding box whose extent does not \
                 overflow"
                    .into(),
            ));
        }
        if !(1..=30).contains(&quant_bits) {
            return Err(Error::Parameter(format!(
                "seed quantization bits must be 1..=30, got {quant_bits}"
            )));
        }
        let angles = AngleTable::new(angle_bits).ok_or_else(|| {
            Error::Parameter(format!(
                "angle bits must be {MIN_ANGLE_BITS}..={MAX_ANGLE_BITS}, got {angle_bits}"
            ))
        })?;
        Ok(SwingParams {
            edge_length,
            angles,
            quantizer: Quantizer::new(bbox, quant_bits),
            bbox: *bbox,
        })
    }

    /// The grid point nearest to `p` and its dequantized position: where a seed vertex at
    /// `p` really goes.
    pub fn snap_seed(&self, p: DVec3) -> ([i32; 3], DVec3) {
        let g = self.quantizer.quantize(p);
        (g, self.quantizer.dequantize(g))
    }

    /// The frame of gate `a -> b` with parent vertex `c` at this stream's edge length.
    #[inline]
    pub fn frame(&self, a: DVec3, b: DVec3, c: DVec3) -> Option<SwingFrame> {
        SwingFrame::new(a, b, c, self.edge_length)
    }
}

/// How a vertex of a retiled mesh is coded.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum VertexSource {
    /// One of the three vertices of a component's seed triangle, at this grid point.
    Seed([i32; 3]),
    /// Created by a `C` triangle with this swing index.
    Swing(i32),
}

/// A retiled mesh as the retiler built it: triangles in creation (= traversal) order, each
/// `[tip, a, b]` (the seed `[x0, x1, x2]`), vertices in creation order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RetiledMesh {
    /// Positions: seeds dequantized, tips reconstructed with [`SwingFrame::tip`].
    pub positions: Vec<DVec3>,
    /// Triangles.
    pub triangles: Vec<[u32; 3]>,
    /// How each vertex is coded.
    pub sources: Vec<VertexSource>,
    /// The retiler's label for each non-seed triangle, in order.
    pub labels: Vec<Clers>,
    /// Connected components (seeds).
    pub components: usize,
    /// Per triangle, true when it is to be deleted after decoding (it covers a hole of the
    /// original); empty when none is.
    pub deleted: Vec<bool>,
}

/// How the geometry of a swing stream was coded.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SwingGeometry {
    /// One swing index per vertex (the normal case).
    Swing,
    /// Explicit quantized positions, for the reason given.
    Explicit(String),
}

/// A swing stream, its report and the mesh the decoder will output.
#[derive(Clone, Debug, PartialEq)]
pub struct SwingEncoded {
    /// The `.whet` bytes.
    pub bytes: Vec<u8>,
    /// Sizes and counts (of the retiled mesh).
    pub report: EncodeReport,
    /// Exactly what `decode(bytes)` returns.
    pub decoded: Mesh,
    /// How the geometry was coded.
    pub geometry: SwingGeometry,
}

// --- Swing index models --------------------------------------------------------------------

/// Contexts of the swing index coder. Kinds 0 and 2 code the zigzagged index order-0
/// through one adaptive bit tree. Kinds 3 to 6 code the residual `q - pred` of the
/// fan-normal prediction, wrapped into the index range and zigzagged, through one model per
/// bucket of the prediction (the bit length of the zigzagged prediction, capped at 7): flat
/// regions (prediction 0) and folds (large predictions) keep apart. Measured
/// (docs/swing.md): 5-9 % fewer bits on smooth scans, 8-10 % on CAD parts. The parent
/// triangle's index, the previous index or the parent's label as contexts cost more in
/// learning than they save (within ±2 %). Kinds 5 and 6 scale the prediction and count
/// symbols in frequency tables, whose estimates settle faster and closer than the bit trees'
/// fixed-rate probabilities: 4-6 % fewer bits at 6 angle bits (docs/swing.md).
struct SwingModels {
    models: Vec<IndexModel>,
}

/// Buckets of the prediction ([`SwingModels`]).
const PRED_BUCKETS: usize = 8;

impl SwingModels {
    fn new(bits: u32, coding: IndexCoding) -> Self {
        let n = match coding {
            IndexCoding::Order0 => 1,
            _ => PRED_BUCKETS,
        };
        SwingModels {
            models: (0..n).map(|_| IndexModel::new(bits, coding)).collect(),
        }
    }

    /// The model for prediction `pred` (the only model without prediction).
    #[inline]
    fn model(&mut self, pred: i32) -> &mut IndexModel {
        let len = (32 - zigzag(pred).leading_zeros()) as usize;
        let k = len.min(self.models.len() - 1);
        &mut self.models[k]
    }
}

/// Symbols of a frequency table ([`IndexModel::Table`]); with more than 6 angle bits the
/// last one is an escape followed by the value through a bit tree.
const TABLE_SYMBOLS: u32 = 64;

/// The adaptive code of one zigzagged swing index or residual (`bits` bits).
#[derive(Clone, Debug)]
enum IndexModel {
    /// Bit by bit, each bit's probability moving a fixed fraction towards what it sees
    /// (kinds 0 to 4).
    Tree(BitTree),
    /// One symbol of an adaptive frequency table (kinds 5 and 6): the value itself when it
    /// is below `2^bits` ≤ 64, else values from 63 up as the escape symbol 63 followed by the
    /// value through `escape`.
    Table {
        symbols: SymbolModel,
        escape: BitTree,
        escapes: bool,
    },
}

impl IndexModel {
    fn new(bits: u32, coding: IndexCoding) -> Self {
        match coding {
            IndexCoding::Scaled => {
                let escapes = bits > TABLE_SYMBOLS.trailing_zeros();
                let n = if escapes { TABLE_SYMBOLS } else { 1 << bits };
                IndexModel::Table {
                    symbols: SymbolModel::new(n as usize),
                    escape: BitTree::new(if escapes { bits } else { 1 }),
                    escapes,
                }
            }
            _ => IndexModel::Tree(BitTree::new(bits)),
        }
    }

    /// Codes `z` (below `2^bits` of the stream).
    #[inline]
    fn encode<S: BitSink>(&mut self, sink: &mut S, z: u32) {
        match self {
            IndexModel::Tree(tree) => sink.encode_tree(tree, z),
            IndexModel::Table {
                symbols,
                escape,
                escapes,
            } => {
                if *escapes && z >= TABLE_SYMBOLS - 1 {
                    sink.encode_symbol(symbols, (TABLE_SYMBOLS - 1) as usize);
                    sink.encode_tree(escape, z);
                } else {
                    sink.encode_symbol(symbols, z as usize);
                }
            }
        }
    }

    /// Decodes a value coded by [`IndexModel::encode`] (below `2^bits`, whatever the input).
    #[inline]
    fn decode(&mut self, dec: &mut RangeDecoder<'_>) -> u32 {
        match self {
            IndexModel::Tree(tree) => dec.decode_tree(tree),
            IndexModel::Table {
                symbols,
                escape,
                escapes,
            } => {
                let s = dec.decode_symbol(symbols) as u32;
                if *escapes && s == TABLE_SYMBOLS - 1 {
                    dec.decode_tree(escape)
                } else {
                    s
                }
            }
        }
    }
}

/// `atan(z)` for `z` in `[0, 1]`: the odd minimax polynomial of Abramowitz and Stegun 4.4.49
/// (error under 1e-5 rad, far below the finest angle step), evaluated in this order so that
/// encoder and decoder agree to the bit (part of the stream format: docs/format.md).
#[inline]
fn atan_unit(z: f64) -> f64 {
    let z2 = z * z;
    let p = 0.020_835_1;
    let p = p * z2 + -0.085_133;
    let p = p * z2 + 0.180_141;
    let p = p * z2 + -0.330_299_5;
    let p = p * z2 + 0.999_866;
    p * z
}

/// The predicted swing index of the tip over gate `a -> b` with frame `frame`: the tip
/// direction of the circle perpendicular to `normal`, the sum of the (unnormalized) normals
/// of the already reconstructed triangles around `a` and `b` — the retiled surface bends on
/// as it bent so far. Of the two perpendicular directions the one folding less (`|θ| ≤ π/2`)
/// is taken; a zero or non-finite normal predicts 0. Encoder and decoder both call this
/// on decoded data only (the walk), with the arithmetic spelled out.
pub fn predict_swing(frame: &SwingFrame, normal: DVec3, table: &AngleTable) -> i32 {
    // |θ| ≤ π/2: the index is within the range for every table (at least 3 bits).
    crate::quantize::round_half_away(predicted_angle(frame, normal) * table.inverse_step()) as i32
}

/// How much farther than the fan normals say the surface is predicted to bend on
/// ([`predict_swing_scaled`]; exactly representable, so `θ · 1.75` rounds the same
/// everywhere).
pub const PREDICTION_SCALE: f64 = 1.75;

/// The prediction of kinds 5 and 6: [`predict_swing`]'s angle times [`PREDICTION_SCALE`],
/// rounded and clamped into the index range. The fan normal averages the triangles already
/// built around the gate, so the plane it describes lies between the parent's and the tip
/// triangle's: the surface goes on bending by about twice the angle it shows. Measured
/// (`swing_ctx`; 6 angle bits, L = 0.85 % of the diagonal): 1.5, 1.75 and 2 all save 2-5 %
/// of the index bits over 1, 1.75 the most on average.
pub fn predict_swing_scaled(frame: &SwingFrame, normal: DVec3, table: &AngleTable) -> i32 {
    let q = crate::quantize::round_half_away(
        predicted_angle(frame, normal) * PREDICTION_SCALE * table.inverse_step(),
    );
    // |θ| · 1.75 ≤ 2.75 rad: within the i32 range; the clamp keeps it in the index range.
    (q as i32).clamp(table.min_index(), table.max_index())
}

/// The angle `θ` in `[-π/2, π/2]` of the tip direction perpendicular to `normal` (0 when
/// there is none), with the arithmetic of docs/format.md.
#[inline]
fn predicted_angle(frame: &SwingFrame, normal: DVec3) -> f64 {
    // Direction cos θ e1 + sin θ e2 ⟂ normal  <=>  (x, y) = (e2·n, -e1·n) ∥ (cos θ, sin θ).
    let mut x = dot(frame.e2, normal);
    let mut y = -dot(frame.e1, normal);
    if !(x.is_finite() && y.is_finite()) {
        return 0.0;
    }
    if x < 0.0 {
        x = -x;
        y = -y;
    }
    let ay = y.abs();
    let t = if ay <= x {
        if x == 0.0 {
            return 0.0;
        }
        atan_unit(ay / x)
    } else {
        std::f64::consts::FRAC_PI_2 - atan_unit(x / ay)
    };
    if y < 0.0 {
        -t
    } else {
        t
    }
}

/// `x` wrapped into the index range of `bits` angle bits.
#[inline]
fn wrap_index(x: i32, bits: u32) -> i32 {
    // Callers pass the sum or difference of two indices: one step of wrapping suffices.
    let half = 1i32 << (bits - 1);
    if x >= half {
        x - 2 * half
    } else if x < -half {
        x + 2 * half
    } else {
        x
    }
}

#[inline]
fn zigzag(q: i32) -> u32 {
    ((q << 1) ^ (q >> 31)) as u32
}

#[inline]
fn unzigzag(z: u32) -> i32 {
    ((z >> 1) as i32) ^ -((z & 1) as i32)
}

/// Reads or writes the values of the swing walk.
trait SwingIo {
    /// The grid coordinates of seed vertex `v`.
    fn seed(&mut self, v: VertexId, bits: u32, grid: &mut [i32; 3]);
    /// The swing index of the tip `v`, predicted as `pred` (0 without prediction).
    fn index(
        &mut self,
        v: VertexId,
        model: &mut IndexModel,
        pred: i32,
        bits: u32,
        q: &mut i32,
    ) -> Result<(), Error>;
    /// The swing index of the tip `v` in kinds 9 and 10: predicted as `pred`, its residual
    /// coded through `models` in context `ctx`.
    fn neighbour_index(
        &mut self,
        v: VertexId,
        models: &mut neighbours::ResidualModels,
        ctx: &neighbours::ResidualContext,
        pred: i32,
        bits: u32,
        q: &mut i32,
    ) -> Result<(), Error>;
}

struct SwingWriter<'a> {
    sink: &'a mut RangeEncoder,
    sources: &'a [VertexSource],
    /// Set when a seed vertex has no grid point (a retiler bug).
    bad_seed: bool,
}

impl SwingIo for SwingWriter<'_> {
    fn seed(&mut self, v: VertexId, bits: u32, grid: &mut [i32; 3]) {
        match self.sources.get(v.index()) {
            Some(&VertexSource::Seed(g)) => *grid = g,
            _ => self.bad_seed = true,
        }
        for &c in grid.iter() {
            self.sink.encode_direct(c as u32, bits);
        }
    }
    fn index(
        &mut self,
        v: VertexId,
        model: &mut IndexModel,
        pred: i32,
        bits: u32,
        q: &mut i32,
    ) -> Result<(), Error> {
        match self.sources.get(v.index()) {
            Some(&VertexSource::Swing(i)) => {
                *q = i;
                let mask = (1u32 << bits) - 1;
                model.encode(self.sink, zigzag(wrap_index(i - pred, bits)) & mask);
                Ok(())
            }
            _ => Err(no_swing_index(v)),
        }
    }
    fn neighbour_index(
        &mut self,
        v: VertexId,
        models: &mut neighbours::ResidualModels,
        ctx: &neighbours::ResidualContext,
        pred: i32,
        bits: u32,
        q: &mut i32,
    ) -> Result<(), Error> {
        match self.sources.get(v.index()) {
            Some(&VertexSource::Swing(i)) => {
                *q = i;
                models.encode(self.sink, ctx, wrap_index(i - pred, bits), bits);
                Ok(())
            }
            _ => Err(no_swing_index(v)),
        }
    }
}

#[cold]
fn no_swing_index(v: VertexId) -> Error {
    Error::Corrupt(format!(
        "retiled vertex {} is created by a C triangle but has no swing index",
        v.0
    ))
}

struct SwingReader<'a, 'b> {
    dec: &'a mut RangeDecoder<'b>,
    max_level: i32,
}

impl SwingIo for SwingReader<'_, '_> {
    fn seed(&mut self, _v: VertexId, bits: u32, grid: &mut [i32; 3]) {
        for c in grid.iter_mut() {
            *c = (self.dec.decode_direct(bits) as i32).min(self.max_level);
        }
    }
    #[inline]
    fn index(
        &mut self,
        _v: VertexId,
        model: &mut IndexModel,
        pred: i32,
        bits: u32,
        q: &mut i32,
    ) -> Result<(), Error> {
        *q = wrap_index(pred + unzigzag(model.decode(self.dec)), bits);
        Ok(())
    }
    #[inline]
    fn neighbour_index(
        &mut self,
        _v: VertexId,
        models: &mut neighbours::ResidualModels,
        ctx: &neighbours::ResidualContext,
        pred: i32,
        bits: u32,
        q: &mut i32,
    ) -> Result<(), Error> {
        *q = wrap_index(pred + models.decode(self.dec, ctx, bits), bits);
        Ok(())
    }
}

/// Walks `conn` in traversal order, reconstructing every vertex through `io`: `positions`
/// in creation order and the triangles in traversal order as `[tip, n(tip), p(tip)]` in
/// creation indices, which is the output mesh of a closed connectivity (the traversal's
/// vertex order is the output order), so neither needs a remapping pass afterwards. The same
/// code runs in the encoder and the decoder. With prediction (kinds 3 to 6) every swing
/// index is coded as the residual of [`predict_swing`] (or [`predict_swing_scaled`]) from the
/// normals of the triangles reconstructed so far.
fn walk<I: SwingIo>(
    conn: &Connectivity,
    params: &SwingParams,
    io: &mut I,
    positions: &mut Vec<DVec3>,
    triangles: &mut Vec<[u32; 3]>,
    coding: IndexCoding,
) -> Result<Vec<DVec3>, Error> {
    let table = &conn.table;
    let nv = table.vertex_count();
    let bits = params.quantizer.bits;
    let angle_bits = params.angles.bits();
    let mut models = SwingModels::new(angle_bits, coding);
    // Creation index of each table vertex (u32::MAX until created).
    let mut rank = vec![u32::MAX; nv];
    positions.clear();
    positions.reserve(nv);
    // Per created vertex: the sum of the cross products of its reconstructed triangles.
    let mut fan = if coding != IndexCoding::Order0 {
        vec![DVec3::ZERO; nv]
    } else {
        Vec::new()
    };
    let accumulate = |fan: &mut Vec<DVec3>, positions: &[DVec3], vs: [u32; 3]| {
        if fan.is_empty() {
            return;
        }
        let [p0, p1, p2] = vs.map(|v| positions[v as usize]);
        let n = cross(sub(p1, p0), sub(p2, p0));
        for v in vs {
            fan[v as usize] = add(fan[v as usize], n);
        }
    };
    let mut failure: Option<Error> = None;
    let corrupt = || Error::Corrupt("a triangle uses a vertex before it is created".into());
    triangles.clear();
    triangles.reserve(table.triangle_count());
    conn.for_each_step(|step| {
        if failure.is_some() {
            return;
        }
        match step {
            Step::Start { corner } => {
                let cs = [corner, table.next(corner), table.prev(corner)];
                let vs = cs.map(|c| table.vertex(c));
                let mut created = [0u32; 3];
                for (k, v) in vs.into_iter().enumerate() {
                    let mut g = [0i32; 3];
                    io.seed(v, bits, &mut g);
                    created[k] = positions.len() as u32;
                    rank[v.index()] = created[k];
                    positions.push(params.quantizer.dequantize(g));
                }
                accumulate(&mut fan, positions, created);
                triangles.push(created);
            }
            Step::Triangle { tip, label, .. } => {
                let ra = rank[table.vertex(table.next(tip)).index()];
                let rb = rank[table.vertex(table.prev(tip)).index()];
                let v = table.vertex(tip);
                if ra == u32::MAX || rb == u32::MAX {
                    failure = Some(corrupt());
                    return;
                }
                let (pa, pb) = (positions[ra as usize], positions[rb as usize]);
                if label == Clers::C {
                    // The traversal only runs on closed tables: the opposite exists.
                    let o = table.opposite(tip).unwrap_or(tip);
                    let rc = rank[table.vertex(o).index()];
                    if rc == u32::MAX || rank[v.index()] != u32::MAX {
                        failure = Some(corrupt());
                        return;
                    }
                    let Some(frame) = params.frame(pa, pb, positions[rc as usize]) else {
                        failure = Some(Error::Corrupt(
                            "a swing gate is degenerate (longer than 2L or flat)".into(),
                        ));
                        return;
                    };
                    let pred = match coding {
                        IndexCoding::Order0 => 0,
                        IndexCoding::Predicted => {
                            let n = add(fan[ra as usize], fan[rb as usize]);
                            predict_swing(&frame, n, &params.angles)
                        }
                        IndexCoding::Scaled => {
                            let n = add(fan[ra as usize], fan[rb as usize]);
                            predict_swing_scaled(&frame, n, &params.angles)
                        }
                    };
                    let mut q = 0i32;
                    let model = models.model(pred);
                    if let Err(e) = io.index(v, model, pred, angle_bits, &mut q) {
                        failure = Some(e);
                        return;
                    }
                    rank[v.index()] = positions.len() as u32;
                    positions.push(frame.tip(&params.angles, q));
                }
                let rv = rank[v.index()];
                if rv == u32::MAX {
                    failure = Some(corrupt());
                    return;
                }
                accumulate(&mut fan, positions, [rv, ra, rb]);
                triangles.push([rv, ra, rb]);
            }
        }
    })
    .map_err(whet_edgebreaker::Error::from)?;
    match failure {
        Some(e) => Err(e),
        None => Ok(fan),
    }
}

/// The output mesh of a connectivity whose table vertices sit at `positions`: vertices in
/// traversal order, triangles in traversal order as `[tip, n(tip), p(tip)]`, dummy fans left
/// out. Encoder and decoder both build their result with it.
fn output_mesh(conn: &Connectivity, positions: &[DVec3], triangles: &[[u32; 3]]) -> Mesh {
    let rank = conn.output_rank();
    let order = conn.output_vertices();
    let out_positions: Vec<DVec3> = order.iter().map(|v| positions[v.index()]).collect();
    let mut out_tris = Vec::with_capacity(triangles.len());
    for t in triangles {
        if t.iter().any(|&v| conn.is_dummy[v as usize]) {
            continue;
        }
        out_tris.push(t.map(|v| rank[v as usize]));
    }
    Mesh::new(out_positions, out_tris)
}

/// Triangles of `conn` in traversal order (`[tip, n, p]`, table ids), dummies included.
fn traversal_triangles(conn: &Connectivity) -> Result<Vec<[u32; 3]>, Error> {
    let table = &conn.table;
    let mut tris = Vec::with_capacity(table.triangle_count());
    conn.for_each_step(|step| {
        let c = match step {
            Step::Start { corner } => corner,
            Step::Triangle { tip, .. } => tip,
        };
        tris.push([
            table.vertex(c).0,
            table.vertex(table.next(c)).0,
            table.vertex(table.prev(c)).0,
        ]);
    })
    .map_err(whet_edgebreaker::Error::from)?;
    Ok(tris)
}

/// Everything the writer needs besides the retiled mesh.
#[derive(Clone, Copy, Debug)]
pub struct SwingStreamInfo<'a> {
    /// Container version to write.
    pub version: Version,
    /// What manifold repair changed in the original.
    pub repair: &'a ManifoldRepair,
    /// Unused vertices of the original left out.
    pub dropped_unused_vertices: usize,
    /// The surface filter the decoder applies to its output ([`SurfaceFilter::NONE`]: none).
    pub filter: SurfaceFilter,
    /// The surface filter for after EdgeSharpener ([`SurfaceFilter::apply_after_sharpening`];
    /// optional header fields 17 and 19, written when not [`SurfaceFilter::NONE`]).
    pub sharpened_filter: SurfaceFilter,
    /// The sharpening the encoder measured best (optional header field 21, written when
    /// `Some`; [`crate::SharpenHint`]).
    pub sharpen_hint: Option<crate::SharpenHint>,
    /// Its smooth factor (optional header field 23, written when `Some` and the hint is;
    /// [`crate::SharpenHint::smooth_factor_code`]).
    pub sharpen_smooth_factor: Option<f64>,
    /// Its curved-wall factor (optional header field 27, written when `Some` and the hint
    /// is; [`crate::SharpenHint::curved_walls_code`]).
    pub sharpen_curved_walls: Option<f64>,
    /// Its EdgeSharpener passes (optional header field 29, written when `Some` and the hint
    /// is).
    pub sharpen_passes: Option<u32>,
    /// Its gray-vertex labels on surface samplings (optional header field 41, written as 1
    /// when true and the hint is; [`crate::SharpenHint::gray_labels_of`]).
    pub sharpen_gray_labels: bool,
}

/// Writes the swing stream of a retiled mesh, after checking that Edgebreaker reproduces the
/// retiler's labels and vertex order and that the shared reconstruction reproduces every
/// position bit for bit. When a check fails (a retiler bug: this panics in debug builds) the
/// geometry is coded explicitly instead ([`SwingGeometry::Explicit`]) and the stream is still
/// valid. Triangles flagged in `retiled.deleted` (over holes of the original) are sent with
/// the closed mesh and deleted by the decoder.
pub fn encode_retiled(
    retiled: &RetiledMesh,
    params: &SwingParams,
    info: &SwingStreamInfo<'_>,
) -> Result<SwingEncoded, Error> {
    // Kinds 9 and 10 code smaller on every fixture measured (docs/results.md); kinds 7 and
    // 8 are kept when they are not larger, so no stream grows.
    let scaled = encode_forward(retiled, params, info, ForwardCoding::Scaled)?;
    let neighbours = encode_forward(retiled, params, info, ForwardCoding::Neighbours)?;
    match (scaled, neighbours) {
        (Some(s), Some(n)) => Ok(if n.bytes.len() < s.bytes.len() { n } else { s }),
        (Some(e), None) | (None, Some(e)) => Ok(e),
        (None, None) => encode_retiled_as(retiled, params, info, IndexCoding::Scaled),
    }
}

/// A seed and index coder `inner` with what a forward walk needs besides (kinds 7 and 8):
/// `state` for the labels and S tips.
struct Forward<W, S> {
    inner: W,
    state: S,
}

impl<W: SwingIo, S> SwingIo for Forward<W, S> {
    fn seed(&mut self, v: VertexId, bits: u32, grid: &mut [i32; 3]) {
        self.inner.seed(v, bits, grid)
    }
    #[inline]
    fn index(
        &mut self,
        v: VertexId,
        model: &mut IndexModel,
        pred: i32,
        bits: u32,
        q: &mut i32,
    ) -> Result<(), Error> {
        self.inner.index(v, model, pred, bits, q)
    }
    #[inline]
    fn neighbour_index(
        &mut self,
        v: VertexId,
        models: &mut neighbours::ResidualModels,
        ctx: &neighbours::ResidualContext,
        pred: i32,
        bits: u32,
        q: &mut i32,
    ) -> Result<(), Error> {
        self.inner.neighbour_index(v, models, ctx, pred, bits, q)
    }
}

/// The writer of kinds 7 and 8: labels, S tips, seeds and indices from the retiled mesh.
type FrontWriter<'a> = Forward<SwingWriter<'a>, LabelSource<'a>>;

/// The reader of kinds 7 and 8.
type FrontReader<'a, 'b> = Forward<SwingReader<'a, 'b>, ()>;

/// Where the writer of kinds 7 and 8 takes labels and S tips from.
struct LabelSource<'a> {
    labels: &'a [Clers],
    next_label: usize,
    triangles: &'a [[u32; 3]],
    /// Directed edge -> triangle of the whole retiled mesh, built at the first S.
    edges: Option<std::collections::HashMap<u64, u32>>,
    /// What the labels and S tips cost, in 1/`COST_ONE` bits.
    connectivity_cost: u64,
}

impl front::FrontIo for FrontWriter<'_> {
    fn label(&mut self, tables: &mut whet_bits::SymbolTables, ctx: usize) -> Result<Clers, Error> {
        let label = *self
            .state
            .labels
            .get(self.state.next_label)
            .ok_or_else(|| {
                Error::Corrupt("the walk needs more labels than the retiler made".into())
            })?;
        self.state.next_label += 1;
        self.state.connectivity_cost += tables.cost(ctx, label as usize) as u64;
        tables.encode(self.inner.sink, ctx, label as usize);
        Ok(label)
    }

    fn split_target(
        &mut self,
        front: &front::Front,
        models: &mut front::SplitModels,
        candidates: &mut [front::Candidate],
        triangle: usize,
        vertices: usize,
    ) -> Result<u32, Error> {
        let mismatch = || Error::Corrupt("the walk's S does not match the retiled mesh".into());
        let [w, a, _] = *self.state.triangles.get(triangle).ok_or_else(mismatch)?;
        let triangles = self.state.triangles;
        let edges = self.state.edges.get_or_insert_with(|| {
            let mut m = std::collections::HashMap::with_capacity(3 * triangles.len());
            for (i, t) in triangles.iter().enumerate() {
                for k in 0..3 {
                    m.insert(((t[k] as u64) << 32) | t[(k + 1) % 3] as u64, i as u32);
                }
            }
            m
        });
        // The tip's node is the one whose loop edge w -> x the S cut off from its wedge: turn
        // around w from the S triangle across its edge to a, through the triangles built after
        // it, to the first one built before it; the edge crossed last is w -> x.
        let mut from = a;
        let mut x = None;
        for _ in 0..256 {
            let &t = edges
                .get(&(((from as u64) << 32) | w as u64))
                .ok_or_else(mismatch)?;
            if (t as usize) < triangle {
                x = Some(from);
                break;
            }
            let tri = triangles[t as usize];
            let k = tri.iter().position(|&u| u == w).ok_or_else(mismatch)?;
            from = tri[(k + 1) % 3];
        }
        let node = front
            .node_towards(w, x.ok_or_else(mismatch)?)
            .ok_or_else(mismatch)?;
        let sink = &mut *self.inner.sink;
        if let Some(me) = candidates.iter().find(|c| c.2 == node).copied() {
            let rank = candidates
                .iter()
                .filter(|c| front::candidate_order(c, &me).is_lt())
                .count();
            self.state.connectivity_cost += models.rank.cost(rank as u32) as u64;
            models.rank.encode(sink, rank as u32);
        } else {
            // A tip on another loop (a handle closes): the vertex, then which of its nodes.
            let escape = candidates.len() as u32;
            let which = front
                .live_nodes(w)
                .iter()
                .position(|&m| m == node)
                .ok_or_else(mismatch)? as u32;
            let bits = front::vertex_bits(vertices);
            self.state.connectivity_cost += (models.rank.cost(escape)
                + models.which.cost(which)
                + bits * whet_bits::COST_ONE) as u64;
            models.rank.encode(sink, escape);
            sink.encode_direct(w, bits);
            models.which.encode(sink, which);
        }
        Ok(node)
    }
}

impl front::FrontIo for FrontReader<'_, '_> {
    #[inline]
    fn label(&mut self, tables: &mut whet_bits::SymbolTables, ctx: usize) -> Result<Clers, Error> {
        // A stream read past its end decodes zeros, which walk on as C after C: stop there
        // rather than at the announced triangle count (a complete stream never overruns).
        if self.inner.dec.overran() {
            return Err(Error::Truncated("geometry"));
        }
        let s = tables.decode(self.inner.dec, ctx);
        Clers::from_index(s).ok_or_else(|| Error::Corrupt("a label out of range".into()))
    }

    fn split_target(
        &mut self,
        front: &front::Front,
        models: &mut front::SplitModels,
        candidates: &mut [front::Candidate],
        _triangle: usize,
        vertices: usize,
    ) -> Result<u32, Error> {
        let dec = &mut *self.inner.dec;
        let rank = models.rank.decode(dec) as usize;
        if rank < candidates.len() {
            let (_, nth, _) = candidates.select_nth_unstable_by(rank, front::candidate_order);
            return Ok(nth.2);
        }
        if rank > candidates.len() {
            return Err(Error::Corrupt("an S tip rank past its loop".into()));
        }
        let w = dec.decode_direct(front::vertex_bits(vertices));
        let which = models.which.decode(dec) as usize;
        if w as usize >= vertices {
            return Err(Error::Corrupt("an S tip vertex not yet created".into()));
        }
        front
            .live_nodes(w)
            .get(which)
            .copied()
            .ok_or_else(|| Error::Corrupt("an S tip vertex without that front node".into()))
    }
}

/// Kinds 7 and 8, or `None` when the forward walk does not reproduce the retiled mesh (a
/// retiler state the walk does not mirror; the caller writes kinds 5 and 6 instead).
fn encode_forward(
    retiled: &RetiledMesh,
    params: &SwingParams,
    info: &SwingStreamInfo<'_>,
    coding: ForwardCoding,
) -> Result<Option<SwingEncoded>, Error> {
    let n = retiled.triangles.len();
    let cutting = retiled.deleted.iter().any(|&d| d);
    if cutting && retiled.deleted.len() != n {
        return Err(Error::Parameter(
            "one deletion flag per retiled triangle is needed".into(),
        ));
    }
    if retiled.components == 0 || n == 0 || n > (u32::MAX / 4) as usize {
        return Ok(None);
    }
    let mut range = RangeEncoder::new();
    let mut io = FrontWriter {
        inner: SwingWriter {
            sink: &mut range,
            sources: &retiled.sources,
            bad_seed: false,
        },
        state: LabelSource {
            labels: &retiled.labels,
            next_label: 0,
            triangles: &retiled.triangles,
            edges: None,
            connectivity_cost: 0,
        },
    };
    let Ok(walked) = front::front_walk(&mut io, params, coding, retiled.components, n, n) else {
        return Ok(None);
    };
    let same_positions = walked.positions.len() == retiled.positions.len()
        && walked
            .positions
            .iter()
            .zip(&retiled.positions)
            .all(|(p, r)| p.to_array().map(f64::to_bits) == r.to_array().map(f64::to_bits));
    if io.inner.bad_seed
        || io.state.next_label != retiled.labels.len()
        || walked.triangles != retiled.triangles
        || !same_positions
    {
        return Ok(None);
    }
    let connectivity_cost = io.state.connectivity_cost;
    let mut mesh = Mesh::new(walked.positions, walked.triangles);
    if cutting {
        code_cut_flags(&mut range, &retiled.deleted);
        mesh = cut(mesh, &retiled.deleted);
        info.filter.apply(&mut mesh, params.edge_length);
    } else {
        info.filter
            .apply_closed(&mut mesh, walked.sums, params.edge_length);
    }
    let mut geometry = vec![coding.kind(cutting)];
    geometry.extend_from_slice(&range.finish());
    let mut connectivity = Vec::new();
    whet_format::write_varint(&mut connectivity, n as u64);
    let mut clers_histogram = [0usize; 5];
    for &l in &retiled.labels {
        clers_histogram[l as usize] += 1;
    }
    // One range-coded stream holds labels and geometry: the labels' share is priced.
    let connectivity_bits =
        connectivity.len() as u64 * 8 + connectivity_cost.div_ceil(whet_bits::COST_ONE as u64);
    let geometry_bits = (geometry.len() as u64 * 8).saturating_sub(connectivity_bits);
    write_stream(
        mesh,
        connectivity,
        geometry,
        StreamReport {
            components: retiled.components,
            clers_histogram,
            connectivity_bits,
            geometry_bits,
        },
        params,
        info,
        SwingGeometry::Swing,
    )
    .map(Some)
}

/// [`encode_retiled`] with the swing indices coded by `coding` (the tests write the older
/// kinds with it, which decoders keep reading).
fn encode_retiled_as(
    retiled: &RetiledMesh,
    params: &SwingParams,
    info: &SwingStreamInfo<'_>,
    coding: IndexCoding,
) -> Result<SwingEncoded, Error> {
    let nv = retiled.positions.len();
    let cutting = retiled.deleted.iter().any(|&d| d);
    if cutting && retiled.deleted.len() != retiled.triangles.len() {
        return Err(Error::Parameter(
            "one deletion flag per retiled triangle is needed".into(),
        ));
    }
    let mut enc = whet_edgebreaker::encode_connectivity(&retiled.triangles, nv)?;
    let conn = &enc.connectivity;

    let mut geometry_kind = SwingGeometry::Swing;
    if conn.is_dummy.iter().any(|&d| d) {
        geometry_kind = SwingGeometry::Explicit("the retiled mesh is not closed".into());
    } else if conn.summary.labels != retiled.labels {
        geometry_kind =
            SwingGeometry::Explicit("Edgebreaker does not reproduce the retiler's labels".into());
    } else if conn
        .summary
        .vertex_order
        .iter()
        .enumerate()
        .any(|(i, v)| v.index() != i)
    {
        geometry_kind = SwingGeometry::Explicit(
            "Edgebreaker does not reproduce the retiler's vertex order".into(),
        );
    }

    let mut geometry = Vec::new();
    let mut decoded = None;
    if geometry_kind == SwingGeometry::Swing {
        let mut range = RangeEncoder::new();
        let mut positions = Vec::new();
        let mut tris = Vec::new();
        let mut io = SwingWriter {
            sink: &mut range,
            sources: &retiled.sources,
            bad_seed: false,
        };
        let walked = walk(conn, params, &mut io, &mut positions, &mut tris, coding);
        // The traversal's vertex order is the retiler's (checked above), so creation order
        // is the retiled mesh's own order.
        let exact = walked.is_ok()
            && !io.bad_seed
            && positions.len() == retiled.positions.len()
            && positions
                .iter()
                .zip(&retiled.positions)
                .all(|(p, r)| p.to_array().map(f64::to_bits) == r.to_array().map(f64::to_bits));
        if exact {
            let mut mesh = Mesh::new(positions, tris);
            if cutting {
                // The walk met the triangles in creation order (the labels matched).
                code_cut_flags(&mut range, &retiled.deleted);
                mesh = cut(mesh, &retiled.deleted);
                info.filter.apply(&mut mesh, params.edge_length);
            } else if let (Ok(fan), true) = (walked, coding != IndexCoding::Order0) {
                info.filter
                    .apply_closed(&mut mesh, WalkSums::of_fan(fan), params.edge_length);
            } else {
                info.filter.apply(&mut mesh, params.edge_length);
            }
            geometry.push(coding.kind(cutting));
            geometry.extend_from_slice(&range.finish());
            decoded = Some(mesh);
        } else {
            geometry_kind = SwingGeometry::Explicit(match walked {
                Err(e) => format!("the swing walk failed: {e}"),
                Ok(_) => {
                    "the shared reconstruction does not reproduce the retiler's positions".into()
                }
            });
        }
    }
    if let SwingGeometry::Explicit(reason) = &geometry_kind {
        debug_assert!(false, "swing self-check failed: {reason}");
        // The kept triangles as an ordinary (possibly open) mesh, positions quantized.
        let kept = cut(
            Mesh::new(retiled.positions.clone(), retiled.triangles.clone()),
            if cutting { &retiled.deleted } else { &[] },
        );
        enc = whet_edgebreaker::encode_connectivity(&kept.triangles, kept.positions.len())?;
        let (bytes, positions) =
            encode_explicit(&enc.connectivity, &kept.positions, &params.quantizer)?;
        geometry.push(KIND_EXPLICIT);
        geometry.extend_from_slice(&bytes);
        let tris = traversal_triangles(&enc.connectivity)?;
        let mut mesh = output_mesh(&enc.connectivity, &positions, &tris);
        info.filter.apply(&mut mesh, params.edge_length);
        decoded = Some(mesh);
    }
    let decoded = decoded.unwrap_or_default();
    let report = StreamReport {
        components: enc.connectivity.starts.len(),
        clers_histogram: enc.histogram(),
        connectivity_bits: enc.bytes.len() as u64 * 8,
        geometry_bits: geometry.len() as u64 * 8,
    };
    write_stream(
        decoded,
        enc.bytes,
        geometry,
        report,
        params,
        info,
        geometry_kind,
    )
}

/// Counts for [`EncodeReport`] that depend on how the connectivity was coded.
struct StreamReport {
    components: usize,
    clers_histogram: [usize; 5],
    connectivity_bits: u64,
    geometry_bits: u64,
}

/// The container around a swing stream's two sections, and the encoder's report.
fn write_stream(
    decoded: Mesh,
    connectivity: Vec<u8>,
    geometry: Vec<u8>,
    counts: StreamReport,
    params: &SwingParams,
    info: &SwingStreamInfo<'_>,
    geometry_kind: SwingGeometry,
) -> Result<SwingEncoded, Error> {
    let components = counts.components;
    let (min, max) = (params.bbox.min.to_array(), params.bbox.max.to_array());
    let mut header = Header::new(
        Mode::Swing,
        decoded.positions.len() as u64,
        decoded.triangles.len() as u64,
    )
    .with_version(info.version)
    .with(tag::COMPONENT_COUNT, components as u64)
    .with(tag::QUANT_BITS, params.quantizer.bits as u64)
    .with(tag::EDGE_LENGTH, params.edge_length)
    .with(tag::ANGLE_BITS, params.angles.bits() as u64);
    if geometry.first().is_some_and(|&k| k >= KIND_SWING_SCALED) && header.version < VERSION_1_2 {
        // Geometry kinds 5 and 6 are format 1.2 (docs/format.md section 6): older readers
        // refuse them by kind.
        header = header.with_version(VERSION_1_2);
    }
    if geometry
        .first()
        .is_some_and(|&k| k >= KIND_SWING_NEIGHBOURS)
        && header.version < VERSION_1_3
    {
        // Kinds 9 and 10 are format 1.3; older readers refuse them by kind too.
        header = header.with_version(VERSION_1_3);
    }
    if !info.filter.is_none() {
        // The filter fields are format 1.1 (docs/format.md section 6): a 1.0 reader refuses
        // them as unknown required tags.
        if header.version < Version::new(1, 1) {
            header = header.with_version(Version::new(1, 1));
        }
        header = header
            .with(tag::FILTER_NORMAL, info.filter.normal)
            .with(tag::FILTER_SMOOTHED, info.filter.smoothed);
        if info.filter.is_extended() {
            // The extended filter's fields are format 1.4, and required (even): a stream
            // with them decodes to another mesh, so an older reader must refuse it.
            if header.version < VERSION_1_4 {
                header = header.with_version(VERSION_1_4);
            }
            header = header
                .with(tag::FILTER_SMOOTHED2, info.filter.smoothed2)
                .with(tag::FILTER_QUADRATIC, info.filter.quadratic)
                .with(tag::FILTER_TANGENTIAL, info.filter.tangential);
        }
    }
    if !info.sharpened_filter.is_none() {
        // Optional (odd) tags: a reader that does not know them skips them.
        header = header
            .with(tag::SHARPENED_FILTER_NORMAL, info.sharpened_filter.normal)
            .with(
                tag::SHARPENED_FILTER_SMOOTHED,
                info.sharpened_filter.smoothed,
            );
    }
    if let Some(hint) = info.sharpen_hint {
        // Optional (odd) too: an older reader sharpens with its default.
        header = header.with(tag::SHARPEN_METHOD, hint.code());
        if let Some(code) = info
            .sharpen_smooth_factor
            .and_then(crate::SharpenHint::smooth_factor_code)
        {
            header = header.with(tag::SHARPEN_SMOOTH_FACTOR, code);
        }
        if let Some(code) = info
            .sharpen_curved_walls
            .and_then(crate::SharpenHint::curved_walls_code)
        {
            header = header.with(tag::SHARPEN_CURVED_WALLS, code);
        }
        if let Some(p) = info.sharpen_passes {
            header = header.with(tag::SHARPEN_PASSES, u64::from(p));
        }
        if info.sharpen_gray_labels {
            header = header.with(tag::SHARPEN_GRAY_LABELS, 1u64);
        }
    }
    // With kinds 9 and 10 (format 1.3 already) a box of binary32 coordinates, what the
    // swing encoder makes, takes 24 bytes (docs/format.md, tag 32); streams of the older
    // kinds keep the 48-byte box, and with it the version they need.
    if geometry
        .first()
        .is_some_and(|&k| k >= KIND_SWING_NEIGHBOURS)
    {
        header.set_bbox_compact(min, max);
    } else {
        header.set_bbox(min, max);
    }
    let container = Container::new(header)
        .with_section(SectionKind::CONNECTIVITY, connectivity)
        .with_section(SectionKind::GEOMETRY, geometry);
    let bytes = container.to_bytes()?;
    let report = EncodeReport {
        bytes: bytes.len(),
        vertices: decoded.positions.len(),
        triangles: decoded.triangles.len(),
        connectivity_bits: counts.connectivity_bits,
        geometry_bits: counts.geometry_bits,
        components,
        clers_histogram: counts.clers_histogram,
        vertex_order: Vec::new(),
        repair: *info.repair,
        dropped_unused_vertices: info.dropped_unused_vertices,
    };
    Ok(SwingEncoded {
        bytes,
        report,
        decoded,
        geometry: geometry_kind,
    })
}

/// Deletion flags, one per triangle in traversal order, each in the context of the previous
/// one (deleted triangles come in runs along the holes).
fn code_cut_flags<S: BitSink>(sink: &mut S, flags: &[bool]) {
    let mut models = [BitModel::new(); 2];
    let mut prev = false;
    for &f in flags {
        sink.encode_bit(&mut models[prev as usize], f);
        prev = f;
    }
}

fn decode_cut_flags(dec: &mut RangeDecoder<'_>, n: usize) -> Vec<bool> {
    let mut models = [BitModel::new(); 2];
    let mut prev = false;
    let mut out = Vec::with_capacity(n);
    for _ in 0..n {
        let f = dec.decode_bit(&mut models[prev as usize]);
        out.push(f);
        prev = f;
    }
    out
}

/// `mesh` without the triangles flagged in `deleted` (no flags: unchanged) and without the
/// vertices no remaining triangle uses; the order of what remains is kept.
fn cut(mesh: Mesh, deleted: &[bool]) -> Mesh {
    if !deleted.iter().any(|&d| d) {
        return mesh;
    }
    let tris: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .zip(deleted)
        .filter(|(_, &d)| !d)
        .map(|(t, _)| *t)
        .collect();
    let mut remap = vec![u32::MAX; mesh.positions.len()];
    for t in &tris {
        for &v in t {
            remap[v as usize] = 0;
        }
    }
    let mut positions = Vec::new();
    for (i, p) in mesh.positions.iter().enumerate() {
        if remap[i] == 0 {
            remap[i] = positions.len() as u32;
            positions.push(*p);
        }
    }
    let triangles = tris.iter().map(|t| t.map(|v| remap[v as usize])).collect();
    Mesh::new(positions, triangles)
}

/// The explicit geometry: positions quantized on `quantizer`, coded by the exact mode's
/// position coder. Returns the payload (without the kind byte) and the dequantized positions
/// by table vertex.
fn encode_explicit(
    conn: &Connectivity,
    positions: &[DVec3],
    quantizer: &Quantizer,
) -> Result<(Vec<u8>, Vec<DVec3>), Error> {
    let nv = conn.table.vertex_count();
    let mut q = vec![[0i32; 3]; nv];
    for (i, p) in positions.iter().enumerate().take(nv) {
        q[i] = quantizer.quantize(*p);
    }
    let mut range = RangeEncoder::new();
    let mut io = ResidualWriter {
        sink: &mut range,
        constrained: false,
        budget: usize::MAX,
    };
    code_positions(conn, quantizer.bits, &mut q, &mut io).map_err(whet_edgebreaker::Error::from)?;
    let out = q.iter().map(|&g| quantizer.dequantize(g)).collect();
    Ok((range.finish(), out))
}

/// Decodes a swing container (called by [`crate::decode_container`]).
pub(crate) fn decode_swing(
    container: &Container,
    opts: &crate::DecodeOptions,
) -> Result<Mesh, Error> {
    let limits = &opts.limits;
    let h = &container.header;
    let edge_length = h
        .get_f64(tag::EDGE_LENGTH)
        .ok_or(Error::MissingField("edge_length"))?;
    let angle_bits = h
        .get_u64(tag::ANGLE_BITS)
        .ok_or(Error::MissingField("angle_bits"))?;
    let quant_bits = h
        .get_u64(tag::QUANT_BITS)
        .ok_or(Error::MissingField("quant_bits"))?;
    let components = h
        .get_u64(tag::COMPONENT_COUNT)
        .ok_or(Error::MissingField("component_count"))?;
    let (min, max) = h.bbox().ok_or(Error::MissingField("bbox"))?;
    let bbox = Aabb {
        min: DVec3::from_array(min),
        max: DVec3::from_array(max),
    };
    if !bbox.min.is_finite() || !bbox.max.is_finite() {
        return Err(Error::Corrupt("bounding box is not finite".into()));
    }
    if !(MIN_ANGLE_BITS as u64..=MAX_ANGLE_BITS as u64).contains(&angle_bits) {
        return Err(Error::Corrupt(format!(
            "angle bits {angle_bits} out of range"
        )));
    }
    if !(1..=30).contains(&quant_bits) {
        return Err(Error::Corrupt(format!(
            "quantization bits {quant_bits} out of range"
        )));
    }
    if !(edge_length > 0.0 && edge_length.is_finite()) {
        return Err(Error::Corrupt(format!(
            "edge length {edge_length} is not positive and finite"
        )));
    }
    let filter = SurfaceFilter::of_header(h);
    if !filter.in_range() {
        return Err(Error::Corrupt(format!(
            "surface filter factors {:?} out of range (at most {} in magnitude)",
            filter.coded(),
            surface_filter::MAX_CODED
        )));
    }
    let params = SwingParams::new(edge_length, angle_bits as u32, &bbox, quant_bits as u32)?;
    let conn_bytes = container
        .section(SectionKind::CONNECTIVITY)
        .ok_or(Error::MissingSection("connectivity"))?;
    let geom = container
        .section(SectionKind::GEOMETRY)
        .ok_or(Error::MissingSection("geometry"))?;
    if let Some(&kind @ KIND_SWING_FORWARD..=KIND_SWING_NEIGHBOURS_CUT) = geom.first() {
        return decode_forward(
            conn_bytes,
            &geom[1..],
            kind,
            &params,
            components,
            filter,
            opts,
        );
    }
    // The connectivity may hold more triangles than the output (dummy fans of the explicit
    // kind, triangles deleted over holes): bounded by the caller's face limit and by what
    // its byte limit allows at the decoders' peak per triangle (the header's counts, which
    // `decode_container` held to it, do not bound this).
    let conn_limits = ConnectivityLimits::DEFAULT.with_max_triangles(
        limits
            .max_faces
            .min(limits.max_alloc_bytes / crate::DECODE_BYTES_PER_TRIANGLE),
    );
    let (conn, used) = whet_edgebreaker::decode_connectivity(conn_bytes, &conn_limits)?;
    if used != conn_bytes.len() {
        return Err(Error::Corrupt(
            "connectivity section has trailing bytes".into(),
        ));
    }
    if conn.starts.len() as u64 != components {
        return Err(Error::Corrupt(format!(
            "the header announces {components} components, the connectivity has {}",
            conn.starts.len()
        )));
    }
    let (&kind, payload) = geom.split_first().ok_or(Error::Truncated("geometry"))?;
    let nv = conn.table.vertex_count();
    let mut dec = RangeDecoder::new(payload).map_err(|_| Error::Truncated("geometry"))?;
    match (kind, IndexCoding::of_kind(kind)) {
        (_, Some((coding, cutting))) => {
            if conn.is_dummy.iter().any(|&d| d) {
                return Err(Error::Corrupt(
                    "swing geometry on an open connectivity".into(),
                ));
            }
            let mut positions = Vec::new();
            let mut tris = Vec::new();
            let mut io = SwingReader {
                dec: &mut dec,
                max_level: params.quantizer.max_level(),
            };
            let fan = walk(&conn, &params, &mut io, &mut positions, &mut tris, coding)?;
            let flags = if cutting {
                decode_cut_flags(&mut dec, tris.len())
            } else {
                Vec::new()
            };
            if dec.finish().is_err() {
                return Err(Error::Truncated("geometry"));
            }
            if positions.iter().any(|p| !p.is_finite()) {
                return Err(Error::Corrupt("a decoded position is not finite".into()));
            }
            if positions.len() != conn.summary.vertex_order.len() {
                return Err(Error::Corrupt(
                    "the swing walk did not create every vertex".into(),
                ));
            }
            let mut mesh = cut(Mesh::new(positions, tris), &flags);
            if opts.surface_filter {
                // As the encoder does: the walk's fan sums on a closed (uncut) predicted
                // mesh, else the filter's own normals.
                if !cutting && coding != IndexCoding::Order0 {
                    filter.apply_closed(&mut mesh, WalkSums::of_fan(fan), params.edge_length);
                } else {
                    filter.apply(&mut mesh, params.edge_length);
                }
            }
            Ok(mesh)
        }
        (KIND_EXPLICIT, None) => {
            let mut q = vec![[0i32; 3]; nv];
            let mut io = ResidualReader {
                dec: &mut dec,
                constrained: false,
                max_level: params.quantizer.max_level(),
                invalid: false,
            };
            let known = code_positions(&conn, quant_bits as u32, &mut q, &mut io)
                .map_err(whet_edgebreaker::Error::from)?;
            if dec.finish().is_err() {
                return Err(Error::Truncated("geometry"));
            }
            let max = params.quantizer.max_level();
            for v in conn.output_vertices() {
                let g = q[v.index()];
                if !known[v.index()] || g.iter().any(|&c| c < 0 || c > max) {
                    return Err(Error::Corrupt(
                        "a decoded position falls outside the quantization grid".into(),
                    ));
                }
            }
            let positions: Vec<DVec3> = q.iter().map(|&g| params.quantizer.dequantize(g)).collect();
            let tris = traversal_triangles(&conn)?;
            let mut mesh = output_mesh(&conn, &positions, &tris);
            if opts.surface_filter {
                filter.apply(&mut mesh, params.edge_length);
            }
            Ok(mesh)
        }
        (other, None) => Err(Error::Corrupt(format!(
            "unknown swing geometry kind {other} (this whet reads kinds 0 to {KIND_SWING_NEIGHBOURS_CUT}; \
             a newer whet may have written it)"
        ))),
    }
}

/// Decodes geometry kinds 7 to 10 (`kind`; the even ones carry deletion flags): the triangle
/// count from the connectivity section, then the forward walk over the geometry payload.
fn decode_forward(
    conn_bytes: &[u8],
    payload: &[u8],
    kind: u8,
    params: &SwingParams,
    components: u64,
    filter: SurfaceFilter,
    opts: &crate::DecodeOptions,
) -> Result<Mesh, Error> {
    let coding = if kind >= KIND_SWING_NEIGHBOURS {
        ForwardCoding::Neighbours
    } else {
        ForwardCoding::Scaled
    };
    let cutting = kind == KIND_SWING_FORWARD_CUT || kind == KIND_SWING_NEIGHBOURS_CUT;
    let mut pos = 0;
    let n = whet_format::read_varint(conn_bytes, &mut pos)?;
    if pos != conn_bytes.len() {
        return Err(Error::Corrupt(
            "connectivity section has trailing bytes".into(),
        ));
    }
    // Every component has at least two triangles (a pillow: the seed and its back face).
    if components == 0 || components.saturating_mul(2) > n {
        return Err(Error::Corrupt(format!(
            "{components} components cannot hold {n} triangles"
        )));
    }
    // The walk may hold more triangles than the output (those deleted over holes): bounded
    // by the caller's face limit, and by its byte limit at the decoders' peak per triangle
    // and per vertex of the closed mesh it builds (at most half its triangles plus two per
    // component: Euler's formula, genus 0 the most).
    let max = opts.limits.max_faces;
    if n > max {
        return Err(whet_format::Error::LimitExceeded {
            what: "swing triangle count",
            limit: max,
            value: n,
        }
        .into());
    }
    let vertices = (n / 2).saturating_add(components.saturating_mul(2));
    let peak = n
        .saturating_mul(crate::DECODE_BYTES_PER_TRIANGLE)
        .saturating_add(vertices.saturating_mul(crate::DECODE_BYTES_PER_VERTEX));
    if peak > opts.limits.max_alloc_bytes {
        return Err(whet_format::Error::LimitExceeded {
            what: crate::DECODE_PEAK_LIMIT,
            limit: opts.limits.max_alloc_bytes,
            value: peak,
        }
        .into());
    }
    // Vertex and node ids are u32: a caller's raised face limit cannot take them past it.
    if n > u64::from(u32::MAX / 4) {
        return Err(whet_format::Error::LimitExceeded {
            what: "swing triangle count (32-bit indices)",
            limit: u64::from(u32::MAX / 4),
            value: n,
        }
        .into());
    }
    let mut dec = RangeDecoder::new(payload).map_err(|_| Error::Truncated("geometry"))?;
    let mut io = FrontReader {
        inner: SwingReader {
            dec: &mut dec,
            max_level: params.quantizer.max_level(),
        },
        state: (),
    };
    // A retiled triangle costs about a bit and a half; 64 per byte is far beyond any stream.
    let capacity = payload.len().saturating_mul(64).saturating_add(1024);
    let walked = front::front_walk(
        &mut io,
        params,
        coding,
        components as usize,
        n as usize,
        capacity,
    )?;
    let flags = if cutting {
        decode_cut_flags(&mut dec, walked.triangles.len())
    } else {
        Vec::new()
    };
    if dec.finish().is_err() {
        return Err(Error::Truncated("geometry"));
    }
    if walked.positions.iter().any(|p| !p.is_finite()) {
        return Err(Error::Corrupt("a decoded position is not finite".into()));
    }
    let mut mesh = cut(Mesh::new(walked.positions, walked.triangles), &flags);
    if opts.surface_filter {
        if cutting {
            filter.apply(&mut mesh, params.edge_length);
        } else {
            filter.apply_closed(&mut mesh, walked.sums, params.edge_length);
        }
    }
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zigzag_round_trips() {
        for q in -2048..2048 {
            assert_eq!(unzigzag(zigzag(q)), q);
        }
        assert_eq!(zigzag(0), 0);
        assert_eq!(zigzag(-1), 1);
        assert_eq!(zigzag(1), 2);
        // The index range of B bits maps onto [0, 2^B).
        for bits in MIN_ANGLE_BITS..=MAX_ANGLE_BITS {
            let t = AngleTable::new(bits).unwrap();
            assert!(zigzag(t.min_index()) < 1 << bits);
            assert!(zigzag(t.max_index()) < 1 << bits);
        }
    }

    #[test]
    fn angle_table_is_symmetric_and_quantizes() {
        let t = AngleTable::new(8).unwrap();
        assert_eq!(t.cos_sin(0), (1.0, 0.0));
        assert_eq!(t.quantize(0.0), 0);
        assert_eq!(t.quantize(t.step() * 3.4), 3);
        assert_eq!(t.quantize(-t.step() * 3.6), -4);
        // Angles past the range wrap (the index is an angle modulo 2π).
        assert_eq!(t.quantize(std::f64::consts::PI), -128);
        let (c, s) = t.cos_sin(64);
        assert!(c.abs() < 1e-15 && (s - 1.0).abs() < 1e-15);
        assert!(AngleTable::new(2).is_none() && AngleTable::new(15).is_none());
    }

    /// A tetrahedron built the way the retiler builds: seed [x0, x1, x2], a C at the first
    /// gate x0 -> x2, then R and E.
    fn tetrahedron(q: i32) -> (RetiledMesh, SwingParams) {
        let bbox = Aabb {
            min: DVec3::splat(-2.0),
            max: DVec3::splat(2.0),
        };
        let params = SwingParams::new(1.0, 6, &bbox, 16).unwrap();
        let seed = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.5, 0.85, 0.0),
        ]
        .map(|p| params.snap_seed(p));
        let mut positions: Vec<DVec3> = seed.iter().map(|s| s.1).collect();
        let frame = params
            .frame(positions[0], positions[2], positions[1])
            .unwrap();
        positions.push(frame.tip(&params.angles, q));
        let mut sources: Vec<VertexSource> = seed.iter().map(|s| VertexSource::Seed(s.0)).collect();
        sources.push(VertexSource::Swing(q));
        (
            RetiledMesh {
                positions,
                triangles: vec![[0, 1, 2], [3, 0, 2], [1, 3, 2], [0, 3, 1]],
                sources,
                labels: vec![Clers::C, Clers::R, Clers::E],
                components: 1,
                deleted: Vec::new(),
            },
            params,
        )
    }

    fn info() -> SwingStreamInfo<'static> {
        static REPAIR: std::sync::OnceLock<ManifoldRepair> = std::sync::OnceLock::new();
        SwingStreamInfo {
            version: Version::CURRENT,
            repair: REPAIR.get_or_init(ManifoldRepair::default),
            dropped_unused_vertices: 0,
            filter: SurfaceFilter::NONE,
            sharpened_filter: SurfaceFilter::NONE,
            sharpen_hint: None,
            sharpen_smooth_factor: None,
            sharpen_curved_walls: None,
            sharpen_passes: None,
            sharpen_gray_labels: false,
        }
    }

    #[test]
    fn the_sharpen_hint_is_written_only_when_given_and_changes_no_geometry() {
        let (retiled, params) = tetrahedron(-20);
        let plain = encode_retiled(&retiled, &params, &info()).unwrap();
        let header = |b: &[u8]| {
            whet_format::parse(b, &crate::Limits::DEFAULT)
                .unwrap()
                .header
        };
        assert_eq!(crate::SharpenHint::of(&header(&plain.bytes)), None);
        for hint in crate::SharpenHint::ALL {
            let with = SwingStreamInfo {
                sharpen_hint: Some(hint),
                ..info()
            };
            let enc = encode_retiled(&retiled, &params, &with).unwrap();
            assert_eq!(crate::SharpenHint::of(&header(&enc.bytes)), Some(hint));
            // Two bytes (key and value), and the same decoded mesh.
            assert_eq!(enc.bytes.len(), plain.bytes.len() + 2);
            assert_eq!(
                crate::decode(&enc.bytes, &crate::DecodeOptions::DEFAULT).unwrap(),
                plain.decoded
            );
        }
        // Field 41 goes with a hint only: three bytes more with one, none without.
        let extended = SwingStreamInfo {
            sharpen_hint: Some(crate::SharpenHint::Extended),
            ..info()
        };
        let hinted = encode_retiled(&retiled, &params, &extended).unwrap();
        let gray = encode_retiled(
            &retiled,
            &params,
            &SwingStreamInfo {
                sharpen_gray_labels: true,
                ..extended
            },
        )
        .unwrap();
        assert!(crate::SharpenHint::gray_labels_of(&header(&gray.bytes)));
        assert!(!crate::SharpenHint::gray_labels_of(&header(&hinted.bytes)));
        // Three bytes: a key of two (41 << 2 is over 127) and the value.
        assert_eq!(gray.bytes.len(), hinted.bytes.len() + 3);
        let unhinted = SwingStreamInfo {
            sharpen_gray_labels: true,
            ..info()
        };
        let unhinted = encode_retiled(&retiled, &params, &unhinted).unwrap();
        assert_eq!(unhinted.bytes, plain.bytes);
    }

    /// Every coordinate of `m` as its bits (an exact comparison that tells -0 from +0).
    fn position_bits(m: &Mesh) -> Vec<[u64; 3]> {
        m.positions
            .iter()
            .map(|p| p.to_array().map(f64::to_bits))
            .collect()
    }

    #[test]
    fn the_surface_filter_is_written_applied_and_checked() {
        let (retiled, params) = tetrahedron(-20);
        let filter = SurfaceFilter::from_factors(0.25, -0.125);
        let with_filter = SwingStreamInfo { filter, ..info() };
        let enc = encode_retiled(&retiled, &params, &with_filter).unwrap();
        assert_eq!(enc.geometry, SwingGeometry::Swing);
        // Every vertex of a tetrahedron is convex with a closed fan: all of them moved.
        for (p, r) in enc.decoded.positions.iter().zip(&retiled.positions) {
            assert_ne!(p, r);
        }
        let mut expected = Mesh::new(retiled.positions.clone(), retiled.triangles.clone());
        filter.apply(&mut expected, params.edge_length);
        assert_eq!(enc.decoded, expected);
        let back = crate::decode(&enc.bytes, &crate::DecodeOptions::DEFAULT).unwrap();
        assert_eq!(position_bits(&back), position_bits(&enc.decoded));
        assert_eq!(back.triangles, enc.decoded.triangles);
        // Skipping the filter gives the swing construction's own positions.
        let raw = crate::decode(
            &enc.bytes,
            &crate::DecodeOptions::DEFAULT.with_surface_filter(false),
        )
        .unwrap();
        assert_eq!(raw.positions, retiled.positions);
        // Format 1.2 for kind 7, 1.3 for kind 9 (whose header states the tetrahedron's box,
        // binary32 coordinates, in 24 bytes: tag 32).
        let header = crate::peek_header(&enc.bytes).unwrap();
        let c = whet_format::parse(&enc.bytes, &crate::Limits::DEFAULT).unwrap();
        if kind_of(&enc.bytes) >= KIND_SWING_NEIGHBOURS {
            assert_eq!(header.version, VERSION_1_3);
            assert!(c.header.get(tag::BBOX_F32).is_some() && c.header.get(tag::BBOX).is_none());
        } else {
            assert_eq!(header.version, VERSION_1_2);
            assert!(c.header.get(tag::BBOX).is_some());
        }
        // The filter for after sharpening: optional fields, read back as written, absent
        // (no filter) unless given.
        let parsed = |bytes: &[u8]| {
            SurfaceFilter::after_sharpening_of(
                &whet_format::parse(bytes, &crate::Limits::DEFAULT)
                    .unwrap()
                    .header,
            )
        };
        assert_eq!(parsed(&enc.bytes), SurfaceFilter::NONE);
        let after = SurfaceFilter::from_factors(-0.25, 0.5);
        let both = SwingStreamInfo {
            sharpened_filter: after,
            ..with_filter
        };
        let enc2 = encode_retiled(&retiled, &params, &both).unwrap();
        assert_eq!(parsed(&enc2.bytes), after);
        assert_eq!(
            crate::decode(&enc2.bytes, &crate::DecodeOptions::DEFAULT).unwrap(),
            enc.decoded
        );
        // Geometry kind 3 with a filter is format 1.1; without a filter it stays 1.0 and
        // has no filter field.
        let kind3 =
            encode_retiled_as(&retiled, &params, &with_filter, IndexCoding::Predicted).unwrap();
        assert_eq!(
            crate::peek_header(&kind3.bytes).unwrap().version,
            Version::new(1, 1)
        );
        let plain = encode_retiled_as(&retiled, &params, &info(), IndexCoding::Predicted).unwrap();
        assert_eq!(
            crate::peek_header(&plain.bytes).unwrap().version,
            Version::CURRENT
        );
        // A factor beyond the range is refused by name.
        let mut container = whet_format::parse(&enc.bytes, &crate::Limits::DEFAULT).unwrap();
        container.header = container
            .header
            .clone()
            .with(tag::FILTER_NORMAL, surface_filter::MAX_CODED + 1);
        let bad = container.to_bytes().unwrap();
        let err = crate::decode(&bad, &crate::DecodeOptions::DEFAULT).unwrap_err();
        assert!(err.to_string().contains("surface filter"), "{err}");
    }

    #[test]
    fn the_extended_surface_filter_is_format_1_4_required_and_checked() {
        let (retiled, params) = tetrahedron(-20);
        let filter = SurfaceFilter::from_extended_factors([0.25, -0.125, 0.5, -0.75, 0.125]);
        let with_filter = SwingStreamInfo { filter, ..info() };
        let enc = encode_retiled(&retiled, &params, &with_filter).unwrap();
        let mut expected = Mesh::new(retiled.positions.clone(), retiled.triangles.clone());
        filter.apply(&mut expected, params.edge_length);
        assert_eq!(enc.decoded, expected);
        let back = crate::decode(&enc.bytes, &crate::DecodeOptions::DEFAULT).unwrap();
        assert_eq!(position_bits(&back), position_bits(&enc.decoded));
        // Unlike the two-field filter's result.
        let two = encode_retiled(
            &retiled,
            &params,
            &SwingStreamInfo {
                filter: SurfaceFilter::from_factors(0.25, -0.125),
                ..info()
            },
        )
        .unwrap();
        assert_ne!(position_bits(&two.decoded), position_bits(&enc.decoded));
        // Version 1.4, the three fields even (required: a reader before 1.4 refuses the
        // stream rather than decode another mesh), read back as written.
        let c = whet_format::parse(&enc.bytes, &crate::Limits::DEFAULT).unwrap();
        assert_eq!(c.header.version, VERSION_1_4);
        for (t, v) in [
            (tag::FILTER_SMOOTHED2, filter.smoothed2),
            (tag::FILTER_QUADRATIC, filter.quadratic),
            (tag::FILTER_TANGENTIAL, filter.tangential),
        ] {
            assert_eq!(t % 2, 0);
            assert_eq!(c.header.get_i64(t), Some(v));
        }
        assert_eq!(
            whet_format::parse(&two.bytes, &crate::Limits::DEFAULT)
                .unwrap()
                .header
                .get_i64(tag::FILTER_TANGENTIAL),
            None
        );
        // A factor beyond the range is refused by name.
        let mut container = c;
        container.header = container
            .header
            .clone()
            .with(tag::FILTER_TANGENTIAL, -surface_filter::MAX_CODED - 1);
        let bad = container.to_bytes().unwrap();
        let err = crate::decode(&bad, &crate::DecodeOptions::DEFAULT).unwrap_err();
        assert!(err.to_string().contains("surface filter"), "{err}");
    }

    #[test]
    fn the_walks_filter_sums_decode_the_bits_the_filters_own_counting_does() {
        // A real stream with the extended filter (the fuzz seed of a synth torus-box): its
        // decode, whose filter takes the walk's triangle counts and next-corner sums, against
        // the filter counting and summing them itself on the unfiltered decode, from the
        // same fan sums (the walk's cross products, in triangle order).
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../fuzz/corpus/decode/seed-swing-extended-filter.whet");
        let bytes = std::fs::read(path).unwrap();
        let decoded = crate::decode(&bytes, &crate::DecodeOptions::DEFAULT).unwrap();
        let raw = crate::decode(
            &bytes,
            &crate::DecodeOptions::DEFAULT.with_surface_filter(false),
        )
        .unwrap();
        let c = whet_format::parse(&bytes, &crate::Limits::DEFAULT).unwrap();
        let h = &c.header;
        let filter = SurfaceFilter::of_header(h);
        assert!(filter.is_extended());
        let mut fan = vec![DVec3::ZERO; raw.positions.len()];
        for t in &raw.triangles {
            let [i, j, k] = t.map(|v| v as usize);
            let p = &raw.positions;
            let n = cross(sub(p[j], p[i]), sub(p[k], p[i]));
            for v in [i, j, k] {
                fan[v] = add(fan[v], n);
            }
        }
        let mut counted = raw.clone();
        let l = h.get_f64(tag::EDGE_LENGTH).unwrap();
        filter.apply_closed(&mut counted, WalkSums::of_fan(fan), l);
        assert_eq!(position_bits(&counted), position_bits(&decoded));
        assert_ne!(position_bits(&raw), position_bits(&decoded));
    }

    #[test]
    fn a_hand_built_tetrahedron_round_trips_bit_exactly() {
        // q = -20: the tip folds 112 degrees below the seed's plane.
        let (retiled, params) = tetrahedron(-20);
        let enc = encode_retiled(&retiled, &params, &info()).unwrap();
        assert_eq!(enc.geometry, SwingGeometry::Swing);
        assert_eq!(enc.decoded.positions, retiled.positions);
        assert_eq!(enc.decoded.triangles, retiled.triangles);
        let back = crate::decode(&enc.bytes, &crate::DecodeOptions::DEFAULT).unwrap();
        assert_eq!(back, enc.decoded);
        // One deleted triangle: kind 2 drops it and nothing else.
        let mut cut_mesh = retiled.clone();
        cut_mesh.deleted = vec![false, false, true, false];
        let enc = encode_retiled(&cut_mesh, &params, &info()).unwrap();
        let back = crate::decode(&enc.bytes, &crate::DecodeOptions::DEFAULT).unwrap();
        assert_eq!(back.triangles.len(), 3);
        assert_eq!(back, enc.decoded);
    }

    /// The geometry kind byte of a swing stream.
    fn kind_of(bytes: &[u8]) -> u8 {
        let c = whet_format::parse(bytes, &crate::Limits::DEFAULT).unwrap();
        c.section(SectionKind::GEOMETRY).unwrap()[0]
    }

    #[test]
    fn every_index_coding_round_trips_with_and_without_deletions() {
        // Folds from flat to past a right angle, both ways; 3 bits (the prediction's
        // clamp), 6 (tables without escape) and 9 (tables with escapes).
        let filter = SurfaceFilter::from_factors(0.25, 0.125);
        for bits in [3, 6, 9] {
            for q in [-20, -5, 0, 3, 17] {
                let (mut retiled, mut params) = tetrahedron(q);
                params = SwingParams::new(1.0, bits, &params.bbox, 16).unwrap();
                let q = q.clamp(params.angles.min_index(), params.angles.max_index());
                let frame = params
                    .frame(
                        retiled.positions[0],
                        retiled.positions[2],
                        retiled.positions[1],
                    )
                    .unwrap();
                retiled.positions[3] = frame.tip(&params.angles, q);
                retiled.sources[3] = VertexSource::Swing(q);
                for deleted in [vec![], vec![false, false, true, false]] {
                    retiled.deleted = deleted;
                    let cutting = !retiled.deleted.is_empty();
                    for coding in [
                        IndexCoding::Order0,
                        IndexCoding::Predicted,
                        IndexCoding::Scaled,
                    ] {
                        let info = SwingStreamInfo { filter, ..info() };
                        let enc = encode_retiled_as(&retiled, &params, &info, coding).unwrap();
                        assert_eq!(enc.geometry, SwingGeometry::Swing);
                        assert_eq!(kind_of(&enc.bytes), coding.kind(cutting));
                        assert_eq!(
                            IndexCoding::of_kind(coding.kind(cutting)),
                            Some((coding, cutting))
                        );
                        let back =
                            crate::decode(&enc.bytes, &crate::DecodeOptions::DEFAULT).unwrap();
                        assert_eq!(back, enc.decoded, "bits {bits} q {q} {coding:?}");
                        let raw = crate::decode(
                            &enc.bytes,
                            &crate::DecodeOptions::DEFAULT.with_surface_filter(false),
                        )
                        .unwrap();
                        if !cutting {
                            assert_eq!(raw.positions, retiled.positions);
                        }
                    }
                    // The forward kinds: 7 and 9, or 8 and 10 with deletions; the encoder
                    // writes the smaller of the two.
                    let info = SwingStreamInfo { filter, ..info() };
                    let mut unfiltered =
                        Mesh::new(retiled.positions.clone(), retiled.triangles.clone());
                    if cutting {
                        unfiltered = cut(unfiltered, &retiled.deleted);
                    }
                    let mut sizes = Vec::new();
                    for coding in [ForwardCoding::Scaled, ForwardCoding::Neighbours] {
                        let enc = encode_forward(&retiled, &params, &info, coding)
                            .unwrap()
                            .unwrap();
                        assert_eq!(kind_of(&enc.bytes), coding.kind(cutting));
                        let back =
                            crate::decode(&enc.bytes, &crate::DecodeOptions::DEFAULT).unwrap();
                        assert_eq!(back, enc.decoded, "bits {bits} q {q} {coding:?}");
                        let raw = crate::decode(
                            &enc.bytes,
                            &crate::DecodeOptions::DEFAULT.with_surface_filter(false),
                        )
                        .unwrap();
                        assert_eq!(raw, unfiltered);
                        sizes.push(enc.bytes.len());
                    }
                    let enc = encode_retiled(&retiled, &params, &info).unwrap();
                    assert!((KIND_SWING_FORWARD..=KIND_SWING_NEIGHBOURS_CUT)
                        .contains(&kind_of(&enc.bytes)));
                    assert_eq!(enc.bytes.len(), sizes[0].min(sizes[1]), "bits {bits} q {q}");
                }
            }
        }
    }

    #[test]
    fn a_forward_stream_cut_short_stops_at_its_end_not_at_its_count() {
        // A kind 7 stream holding a seed and nothing else, announcing 2^22 triangles: read
        // past its end, the decoder sees zeros, that is C after C with the predicted index,
        // each on a valid frame, up to the count (gigabytes at the default limits).
        let (retiled, params) = tetrahedron(-20);
        let enc = encode_retiled(&retiled, &params, &info()).unwrap();
        let c = whet_format::parse(&enc.bytes, &crate::Limits::DEFAULT).unwrap();
        let mut range = RangeEncoder::new();
        for source in &retiled.sources[..3] {
            let VertexSource::Seed(g) = *source else {
                panic!("the seed comes first")
            };
            for x in g {
                range.encode_direct(x as u32, params.quantizer.bits);
            }
        }
        let mut geometry = vec![KIND_SWING_FORWARD];
        geometry.extend_from_slice(&range.finish());
        let mut count = Vec::new();
        whet_format::write_varint(&mut count, 1 << 22);
        let bytes = Container::new(c.header.clone())
            .with_section(SectionKind::CONNECTIVITY, count)
            .with_section(SectionKind::GEOMETRY, geometry)
            .to_bytes()
            .unwrap();
        let t = std::time::Instant::now();
        let err = crate::decode(&bytes, &crate::DecodeOptions::DEFAULT).unwrap_err();
        assert!(err.to_string().contains("truncated"), "{err}");
        // Stopped within a few labels of its end.
        assert!(t.elapsed() < std::time::Duration::from_secs(1));
    }

    #[test]
    fn the_scaled_prediction_stays_in_the_index_range() {
        // A normal lying in the parent's plane, pointing away from the gate: the tip is
        // predicted to fold a right angle, which 1.75 times takes past the range of 3 bits.
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(1.0, 0.0, 0.0);
        let c = DVec3::new(0.5, -0.8, 0.0);
        let f = SwingFrame::new(a, b, c, 1.0).unwrap();
        for bits in MIN_ANGLE_BITS..=MAX_ANGLE_BITS {
            let t = AngleTable::new(bits).unwrap();
            for n in [
                DVec3::Y,
                -DVec3::Y,
                DVec3::new(0.0, 1.0, 1.0),
                DVec3::Z,
                DVec3::ZERO,
            ] {
                let p = predict_swing_scaled(&f, n, &t);
                assert!(
                    p >= t.min_index() && p <= t.max_index(),
                    "bits {bits} {n:?}: {p}"
                );
                let plain = predict_swing(&f, n, &t);
                // Same sign and at least as far as the plain prediction, within the range.
                assert!(p.signum() == plain.signum() && p.abs() >= plain.abs().min(t.max_index()));
            }
        }
        // 45 degrees of fold predict 78.75 degrees.
        let t = AngleTable::new(8).unwrap();
        let n = DVec3::new(0.0, -1.0, 1.0);
        assert_eq!(predict_swing(&f, n, &t), 32);
        assert_eq!(predict_swing_scaled(&f, n, &t), 56);
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "swing self-check failed")]
    fn a_retiler_bug_fails_loudly_in_debug_builds() {
        let (mut retiled, params) = tetrahedron(-20);
        retiled.labels[1] = Clers::L;
        let _ = encode_retiled(&retiled, &params, &info());
    }

    #[test]
    #[cfg(not(debug_assertions))]
    fn a_retiler_bug_falls_back_to_explicit_positions_in_release_builds() {
        let (mut retiled, params) = tetrahedron(-20);
        retiled.labels[1] = Clers::L;
        let enc = encode_retiled(&retiled, &params, &info()).unwrap();
        assert!(matches!(enc.geometry, SwingGeometry::Explicit(_)));
        let back = crate::decode(&enc.bytes, &crate::DecodeOptions::DEFAULT).unwrap();
        assert_eq!(back, enc.decoded);
    }

    #[test]
    fn frame_tip_is_at_distance_l_from_the_gate() {
        let a = DVec3::new(0.0, 0.0, 0.0);
        let b = DVec3::new(1.0, 0.0, 0.0);
        let c = DVec3::new(0.5, -0.8, 0.0);
        let f = SwingFrame::new(a, b, c, 1.0).unwrap();
        // e1 points away from the parent, e2 along the parent's outward normal (b, a, c).
        assert!((f.e1 - DVec3::Y).length() < 1e-15);
        assert!((f.e2 - DVec3::Z).length() < 1e-15);
        let t = AngleTable::new(7).unwrap();
        for q in t.min_index()..=t.max_index() {
            let p = f.tip(&t, q);
            assert!(((p - a).length() - 1.0).abs() < 1e-12);
            assert!(((p - b).length() - 1.0).abs() < 1e-12);
            let back = t.quantize(f.angle_of(p));
            assert_eq!(back, q);
        }
        // No swing for gates of length 2L or more, or a parent on the gate's line.
        assert!(SwingFrame::new(a, DVec3::new(2.0, 0.0, 0.0), c, 1.0).is_none());
        assert!(SwingFrame::new(a, b, DVec3::new(3.0, 0.0, 0.0), 1.0).is_none());
    }
}
