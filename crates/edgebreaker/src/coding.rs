//! Entropy coding of the connectivity: labels, handle contacts and hole dummies, and the
//! whole-mesh encode/decode built on the traversal and the reverse decoder.
//!
//! Payload layout (inside the container's connectivity section; `docs/format.md`):
//!
//! | field | coding |
//! |---|---|
//! | symbols `N`, components `K`, split events, dummy vertices | four LEB128 varints |
//! | split events, by increasing source | range coded: source delta, `source - split`, right bit |
//! | dummy vertex positions in traversal order, increasing | range coded deltas |
//! | labels in decoding order (last first), the forced first E omitted | range coded, context = remaining valence (6) x previous decoded label (5) |
//!
//! With [`LabelCode::Static`] the labels (same order, same contexts) are one static code
//! (whet-bits `StaticResidualEncoder::encode_symbol`, context `valence · 5 + previous`, one
//! state) between the four counts and the side information: its length as a varint, then its
//! bytes; the range-coded part then holds the split events and dummies alone.

use crate::holes::close_holes;
use crate::reverse_decoder::{ReverseBuffers, ReverseDecoder, VALENCE_CONTEXTS};
use crate::traversal::{
    traverse, traverse_in, Clers, SplitEvent, Step, TraversalError, TraversalSummary,
};
use crate::Error;
use whet_bits::{
    BitModel, BitSink, CostCounter, RangeDecoder, RangeEncoder, SymbolModel, UnsignedIntModel,
};
use whet_mesh::{CornerId, CornerTable, MeshError, Scratch, VertexId};

/// The label models: one adaptive 5-symbol model per (valence, previous label) context.
struct LabelModels {
    models: Vec<SymbolModel>,
}

impl LabelModels {
    fn new() -> Self {
        LabelModels {
            models: (0..VALENCE_CONTEXTS * 5)
                .map(|_| SymbolModel::new(5))
                .collect(),
        }
    }
    #[inline]
    fn get(&mut self, valence_ctx: usize, prev: Clers) -> &mut SymbolModel {
        // valence_ctx < VALENCE_CONTEXTS and prev < 5, so the index is in range (a modulo
        // here was a division on the chain from one label to the next).
        &mut self.models[valence_ctx * 5 + prev as usize]
    }
}

/// How a connectivity payload codes its labels.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
#[non_exhaustive]
pub enum LabelCode {
    /// Adaptive models per (remaining valence, previous label) context, range coded after
    /// the side information (the layout in the module docs).
    #[default]
    Adaptive,
    /// One static frequency table per context of the adaptive code, for the whole payload
    /// (`whet_bits::StaticResidualEncoder::encode_symbol`): after the four counts, the
    /// static stream's length (varint) and the stream, then the range-coded side
    /// information alone. A table lookup per label where the adaptive code searches and
    /// updates its model: for streams that must decode fastest.
    Static,
}

/// Contexts of the static label code: remaining valence x previous label.
const STATIC_LABEL_CONTEXTS: usize = VALENCE_CONTEXTS * 5;

/// Where a label goes: the adaptive models on a range-coder sink, or a static code.
trait LabelSink {
    fn label(&mut self, context: usize, prev: Clers, sym: Clers);
}

/// The adaptive label code on any bit sink (the range encoder, or a cost counter).
struct AdaptiveLabels<'a, S: BitSink> {
    sink: &'a mut S,
    models: LabelModels,
}

impl<S: BitSink> LabelSink for AdaptiveLabels<'_, S> {
    #[inline]
    fn label(&mut self, context: usize, prev: Clers, sym: Clers) {
        self.sink
            .encode_symbol(self.models.get(context, prev), sym as usize);
    }
}

impl LabelSink for whet_bits::StaticResidualEncoder {
    #[inline]
    fn label(&mut self, context: usize, prev: Clers, sym: Clers) {
        self.encode_symbol(context * 5 + prev as usize, 0, sym as usize);
    }
}

/// Where labels come from when decoding: the adaptive models on a range decoder, or a
/// static code.
trait LabelSource {
    fn label(&mut self, context: usize, prev: Clers) -> usize;
    fn overran(&self) -> bool;
}

struct AdaptiveLabelSource<'a, 'b> {
    dec: &'a mut RangeDecoder<'b>,
    models: LabelModels,
}

impl LabelSource for AdaptiveLabelSource<'_, '_> {
    #[inline(always)]
    fn label(&mut self, context: usize, prev: Clers) -> usize {
        self.dec.decode_symbol(self.models.get(context, prev))
    }
    fn overran(&self) -> bool {
        self.dec.overran()
    }
}

impl LabelSource for whet_bits::StaticResidualDecoder<'_> {
    #[inline(always)]
    fn label(&mut self, context: usize, prev: Clers) -> usize {
        self.decode_symbol(context * 5 + prev as usize, 0)
    }
    fn overran(&self) -> bool {
        whet_bits::StaticResidualDecoder::overran(self)
    }
}

/// Side models: split events and dummy positions.
struct SideModels {
    source_delta: UnsignedIntModel,
    split_distance: UnsignedIntModel,
    right: BitModel,
    dummy_delta: UnsignedIntModel,
}

impl SideModels {
    fn new() -> Self {
        SideModels {
            source_delta: UnsignedIntModel::new(),
            split_distance: UnsignedIntModel::new(),
            right: BitModel::new(),
            dummy_delta: UnsignedIntModel::new(),
        }
    }
}

/// Bounds the decoder checks before allocating.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct ConnectivityLimits {
    /// Most triangles (symbols plus components) a stream may announce.
    pub max_triangles: u64,
}

impl ConnectivityLimits {
    /// 2^26 triangles: about 1.6 GB of decoder state at most.
    pub const DEFAULT: ConnectivityLimits = ConnectivityLimits {
        max_triangles: 1 << 26,
    };

    /// Limits with another triangle bound.
    pub const fn with_max_triangles(mut self, n: u64) -> Self {
        self.max_triangles = n;
        self
    }
}

impl Default for ConnectivityLimits {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// A closed corner table, its component start corners and its dummy vertices: what both the
/// encoder and the decoder hand to a geometry coder, which walks it with
/// [`Connectivity::for_each_step`].
#[derive(Clone, Debug)]
pub struct Connectivity {
    /// The closed mesh (holes filled with dummy fans).
    pub table: CornerTable,
    /// Start corner of each component.
    pub starts: Vec<CornerId>,
    /// Per vertex of `table`: true for a hole's dummy vertex.
    pub is_dummy: Vec<bool>,
    /// The traversal's results on `table` from `starts`.
    pub summary: TraversalSummary,
    /// Set when the table was built by the reverse decoder: per component (in encoding
    /// order) the decoder steps that made it. Decoder step `i` made triangle `i`, entered
    /// by the traversal at corner `3 i` as symbol `N - 1 - i`, so the traversal's steps
    /// are known without traversing.
    decoder_steps: Option<Vec<std::ops::Range<u32>>>,
    /// Set on the encoder's table relabelled in traversal order (triangle `i` the `i`-th
    /// visited): per triangle, the position in it (0..3) of the corner the traversal entered
    /// it by (the start corner for a start triangle), so the steps are known without
    /// traversing again.
    visit_tips: Option<Vec<u8>>,
}

impl Connectivity {
    /// Calls `visit` with every step of the traversal of `table` from `starts`, in order:
    /// what [`crate::traverse`]`(&self.table, Some(&self.starts), visit)` does, without
    /// walking the table when it was decoded (the decoder's own construction order gives
    /// the steps) or when it is the encoder's table relabelled in traversal order (the steps
    /// were recorded while traversing). A connectivity whose table was replaced by another
    /// of the same size gets the recorded steps of the one it replaced.
    pub fn for_each_step(&self, mut visit: impl FnMut(Step)) -> Result<(), TraversalError> {
        let labels = &self.summary.labels;
        // The fields are public: a caller may have edited them since decoding or relabelling.
        // When they no longer have the recorded shape, traverse instead; the fast paths then
        // cannot index out of range.
        if let Some(tips) = &self.visit_tips {
            let nt = tips.len();
            // A relabelled table: one triangle per symbol plus one start triangle per
            // component, the starts in increasing triangle order (components follow each
            // other), each start corner the one recorded for its triangle.
            if self.table.triangle_count() == nt
                && labels.len() + self.starts.len() == nt
                && self
                    .starts
                    .windows(2)
                    .all(|w| w[0].index() / 3 < w[1].index() / 3)
                && self
                    .starts
                    .iter()
                    .all(|s| tips.get(s.index() / 3) == Some(&((s.index() % 3) as u8)))
            {
                let mut next_start = 0usize;
                let mut symbol = 0usize;
                for (i, &rot) in tips.iter().enumerate() {
                    match self.starts.get(next_start) {
                        Some(&corner) if corner.index() / 3 == i => {
                            next_start += 1;
                            visit(Step::Start { corner });
                            continue;
                        }
                        _ => {}
                    }
                    let Some(&label) = labels.get(symbol) else {
                        break;
                    };
                    visit(Step::Triangle {
                        tip: CornerId(3 * i as u32 + u32::from(rot % 3)),
                        label,
                        symbol: symbol as u32,
                    });
                    symbol += 1;
                }
                return Ok(());
            }
        }
        let steps = match &self.decoder_steps {
            Some(steps)
                if steps.len() == self.starts.len()
                    && steps.iter().all(|r| r.end as usize <= labels.len())
                    && self.table.corner_count() == 3 * (labels.len() + self.starts.len()) =>
            {
                steps
            }
            _ => return traverse(&self.table, Some(&self.starts), visit).map(|_| ()),
        };
        let n = labels.len() as u32;
        for (&corner, range) in self.starts.iter().zip(steps) {
            visit(Step::Start { corner });
            for i in range.clone().rev() {
                // The decoder checked i < n; a symbol index of the encoding order.
                let symbol = n - 1 - i;
                visit(Step::Triangle {
                    tip: CornerId(3 * i),
                    label: labels[symbol as usize],
                    symbol,
                });
            }
        }
        Ok(())
    }

    /// The real triangles (dummy fans removed) with vertices renumbered in traversal order
    /// (dummies skipped): the triangle list a decoder outputs.
    pub fn output_triangles(&self) -> Vec<[u32; 3]> {
        self.output_triangles_ranked(&self.output_rank())
    }

    /// [`Connectivity::output_triangles`] given [`Connectivity::output_rank`]: a triangle
    /// with a vertex without rank (a dummy) is left out.
    pub fn output_triangles_ranked(&self, rank: &[u32]) -> Vec<[u32; 3]> {
        let mut out = Vec::with_capacity(self.table.triangle_count());
        let r = |v: u32| rank.get(v as usize).copied().unwrap_or(u32::MAX);
        for t in self.table.corner_vertices().chunks_exact(3) {
            let vs = [r(t[0]), r(t[1]), r(t[2])];
            if vs.contains(&u32::MAX) {
                continue;
            }
            out.push(vs);
        }
        out
    }

    /// Gives the connectivity's arrays (its table's included) to `scratch` for a later
    /// encode.
    pub fn recycle(self, scratch: &mut Scratch) {
        self.table.recycle(scratch);
        scratch.give(self.starts);
        scratch.give(self.is_dummy);
        scratch.give(self.summary.labels);
        scratch.give(self.summary.starts);
        scratch.give(self.summary.vertex_order);
        scratch.give(self.summary.splits);
        if let Some(t) = self.visit_tips {
            scratch.give(t);
        }
    }

    /// Output index of each table vertex (`u32::MAX` for dummies and unused ids).
    pub fn output_rank(&self) -> Vec<u32> {
        let mut rank = vec![u32::MAX; self.table.vertex_count()];
        let mut n = 0u32;
        for &v in &self.summary.vertex_order {
            if !self.is_dummy[v.index()] {
                rank[v.index()] = n;
                n += 1;
            }
        }
        rank
    }

    /// The real vertices in output order (table ids).
    pub fn output_vertices(&self) -> Vec<VertexId> {
        self.output_vertices_iter().collect()
    }

    /// [`Connectivity::output_vertices`] without collecting them.
    pub fn output_vertices_iter(&self) -> impl Iterator<Item = VertexId> + '_ {
        self.summary
            .vertex_order
            .iter()
            .copied()
            .filter(|v| !self.is_dummy[v.index()])
    }
}

/// The encoder's result.
#[derive(Clone, Debug)]
pub struct EncodedConnectivity {
    /// The payload.
    pub bytes: Vec<u8>,
    /// The encoder-side connectivity (original vertex ids; dummies numbered from the input's
    /// vertex count on).
    pub connectivity: Connectivity,
    /// Face of each triangle in traversal order (start triangles included).
    face_order: Vec<u32>,
    /// Corner vertices and opposites of the table relabelled in traversal order, built
    /// during the traversal (taken by the first [`EncodedConnectivity::traversal_ordered`]).
    ordered: Option<Relabelled>,
    /// Per triangle in traversal order, the position of the corner it was entered by
    /// (taken with `ordered`: see `Connectivity::visit_tips`).
    visit_tips: Option<Vec<u8>>,
}

impl EncodedConnectivity {
    /// Gives the encoder's arrays (the connectivity's, the traversal order's, the payload
    /// bytes') to `scratch` for a later encode.
    pub fn recycle(self, scratch: &mut Scratch) {
        self.connectivity.recycle(scratch);
        scratch.give(self.bytes);
        scratch.give(self.face_order);
        if let Some((v, o, starts)) = self.ordered {
            scratch.give(v);
            scratch.give(o);
            scratch.give(starts);
        }
        if let Some(t) = self.visit_tips {
            scratch.give(t);
        }
    }

    /// Counts of C, L, E, R, S.
    pub fn histogram(&self) -> [usize; 5] {
        let mut h = [0usize; 5];
        for &l in &self.connectivity.summary.labels {
            h[l as usize] += 1;
        }
        h
    }

    /// The connectivity relabelled in traversal order: triangle `i` is the `i`-th the
    /// traversal visits (each keeps its corners' rotation) and vertex `i` is the `i`-th
    /// created, dummies included, so the new ids of the real vertices are increasing in
    /// output order. Walks over it touch memory roughly in order, unlike the input's table,
    /// and it is the same mesh corner for corner, so every order fixed by the traversal
    /// itself (the geometry coders') is unchanged. Returns it and, per new vertex id, the
    /// old one.
    ///
    /// The first call takes the relabelled arrays the encoder built while traversing (the
    /// triangles' lines are in cache then); later calls rebuild them.
    pub fn traversal_ordered(&mut self) -> Result<(Connectivity, Vec<u32>), Error> {
        self.traversal_ordered_in(&mut Scratch::new())
    }

    /// [`EncodedConnectivity::traversal_ordered`] with the new arrays taken from `scratch`.
    pub fn traversal_ordered_in(
        &mut self,
        scratch: &mut Scratch,
    ) -> Result<(Connectivity, Vec<u32>), Error> {
        let (v, o, starts) = match self.ordered.take() {
            Some(r) => r,
            None => self.relabel()?,
        };
        let visit_tips = self.visit_tips.take();
        let conn = &self.connectivity;
        let order = &conn.summary.vertex_order;
        // A renumbering of the checked input table: consistent by construction, so only the
        // indices are checked (from_raw's pairing checks were 5 % of an exact encode).
        let new_table = CornerTable::from_relabelled_in(v, o, order.len(), scratch)
            .map_err(|_| Error::Corrupt("relabelled table is inconsistent"))?;
        let starts: Vec<CornerId> = starts.into_iter().map(CornerId).collect();
        let mut is_dummy: Vec<bool> = scratch.take_empty(order.len());
        is_dummy.extend(order.iter().map(|v| conn.is_dummy[v.index()]));
        let mut labels: Vec<Clers> = scratch.take_empty(conn.summary.labels.len());
        labels.extend_from_slice(&conn.summary.labels);
        let mut vertex_order: Vec<VertexId> = scratch.take_empty(order.len());
        vertex_order.extend((0..order.len() as u32).map(VertexId));
        let summary = TraversalSummary {
            labels,
            splits: conn.summary.splits.clone(),
            starts: starts.clone(),
            vertex_order,
        };
        let mut old: Vec<u32> = scratch.take_empty(order.len());
        old.extend(order.iter().map(|v| v.0));
        Ok((
            Connectivity {
                table: new_table,
                starts,
                is_dummy,
                summary,
                decoder_steps: None,
                visit_tips,
            },
            old,
        ))
    }

    /// The corner vertices and opposites of the table relabelled in traversal order.
    fn relabel(&self) -> Result<Relabelled, Error> {
        let conn = &self.connectivity;
        let table = &conn.table;
        let nt = table.triangle_count();
        let nv = table.vertex_count();
        let order = &conn.summary.vertex_order;
        let mut vertex_rank = vec![u32::MAX; nv];
        for (i, v) in order.iter().enumerate() {
            vertex_rank[v.index()] = i as u32;
        }
        let mut face_rank = vec![u32::MAX; nt];
        for (i, &f) in self.face_order.iter().enumerate() {
            face_rank[f as usize] = i as u32;
        }
        if self.face_order.len() != nt || face_rank.contains(&u32::MAX) {
            return Err(Error::Corrupt("the traversal did not visit every triangle"));
        }
        let map_corner = |c: u32| 3 * face_rank[c as usize / 3] + c % 3;
        let cv = table.corner_vertices();
        let opp = table.opposites();
        let mut v = vec![[0u32; 3]; nt];
        let mut o = vec![u32::MAX; 3 * nt];
        for (i, &f) in self.face_order.iter().enumerate() {
            for j in 0..3 {
                let c = 3 * f as usize + j;
                v[i][j] = vertex_rank[cv[c] as usize];
                if opp[c] != u32::MAX {
                    o[3 * i + j] = map_corner(opp[c]);
                }
            }
        }
        let starts = conn.starts.iter().map(|c| map_corner(c.0)).collect();
        Ok((v, o, starts))
    }
}

/// Triangles, corner opposites and component start corners of a table relabelled in
/// traversal order.
type Relabelled = (Vec<[u32; 3]>, Vec<u32>, Vec<u32>);

fn write_varint(out: &mut Vec<u8>, mut v: u64) {
    loop {
        let byte = (v & 0x7F) as u8;
        v >>= 7;
        if v == 0 {
            out.push(byte);
            return;
        }
        out.push(byte | 0x80);
    }
}

fn read_varint(bytes: &[u8], pos: &mut usize) -> Result<u64, Error> {
    let mut v = 0u64;
    for i in 0..10 {
        let b = *bytes.get(*pos).ok_or(Error::Truncated)?;
        *pos += 1;
        if i == 9 && b > 1 {
            return Err(Error::Corrupt("varint overflows 64 bits"));
        }
        v |= ((b & 0x7F) as u64) << (7 * i);
        if b & 0x80 == 0 {
            if b == 0 && i > 0 {
                return Err(Error::Corrupt("overlong varint"));
            }
            return Ok(v);
        }
    }
    Err(Error::Corrupt("varint longer than 10 bytes"))
}

/// Codes the labels in decoding order with their contexts, on any sink (the range encoder,
/// or a cost counter to measure).
fn code_labels<S: LabelSink>(
    sink: &mut S,
    labels: &[Clers],
    splits: &[SplitEvent],
    scratch: &mut Scratch,
) -> Result<(), Error> {
    let n = labels.len() as u32;
    // The decoder's own contexts come from replaying its reverse decoder: its arrays (the
    // size of a decoded table) are taken from the scratch pool and given back.
    let faces = labels.len() + 1;
    let buffers = ReverseBuffers {
        v: scratch.take_empty(faces),
        o: scratch.take_empty(3 * faces),
        leftmost: scratch.take_empty(faces / 2 + 3),
        valence: scratch.take_empty(faces / 2 + 3),
    };
    let mut dec = ReverseDecoder::with_buffers(n, splits, faces, buffers);
    let coded = code_labels_with(sink, labels, &mut dec);
    scratch.give(std::mem::take(&mut dec.v));
    scratch.give(std::mem::take(&mut dec.o));
    scratch.give(std::mem::take(&mut dec.leftmost));
    scratch.give(std::mem::take(&mut dec.valence));
    coded
}

fn code_labels_with<S: LabelSink>(
    sink: &mut S,
    labels: &[Clers],
    dec: &mut ReverseDecoder,
) -> Result<(), Error> {
    let mut prev = Clers::E;
    for &sym in labels.iter().rev() {
        let gate = dec.gate();
        match gate {
            None if sym != Clers::E => {
                return Err(Error::Corrupt("a component does not end with E"));
            }
            None => {}
            Some(g) => sink.label(g.context, prev, sym),
        }
        dec.apply(sym, gate)?;
        prev = sym;
    }
    Ok(())
}

/// Encodes the connectivity of an oriented manifold (holes allowed). `vertex_count` may
/// exceed the used vertices; unused ones are not coded.
pub fn encode_connectivity(
    triangles: &[[u32; 3]],
    vertex_count: usize,
) -> Result<EncodedConnectivity, Error> {
    let open = CornerTable::from_triangles(triangles, vertex_count)?;
    encode_connectivity_with_table(open, triangles, vertex_count)
}

/// [`encode_connectivity`] for a caller that already built the corner table of
/// `triangles` (saves building it twice).
pub fn encode_connectivity_with_table(
    open: CornerTable,
    triangles: &[[u32; 3]],
    vertex_count: usize,
) -> Result<EncodedConnectivity, Error> {
    encode_connectivity_with_table_in(open, triangles, vertex_count, &mut Scratch::new())
}

/// [`encode_connectivity_with_table`] with its arrays taken from `scratch` (the result's
/// included: [`EncodedConnectivity::recycle`] gives them back), for a caller that encodes
/// mesh after mesh.
pub fn encode_connectivity_with_table_in(
    open: CornerTable,
    triangles: &[[u32; 3]],
    vertex_count: usize,
    scratch: &mut Scratch,
) -> Result<EncodedConnectivity, Error> {
    encode_connectivity_coded_in(open, triangles, vertex_count, LabelCode::Adaptive, scratch)
}

/// [`encode_connectivity_with_table_in`] with the labels in `labels`' code (the decoder
/// must be told the same: [`decode_connectivity_coded`]).
pub fn encode_connectivity_coded_in(
    open: CornerTable,
    triangles: &[[u32; 3]],
    vertex_count: usize,
    labels: LabelCode,
    scratch: &mut Scratch,
) -> Result<EncodedConnectivity, Error> {
    let has_boundary = open.first_boundary_corner().is_some();
    let (table, dummies) = if has_boundary {
        let (closed, dummies) = close_holes(triangles, &open, vertex_count)?;
        drop(open);
        (
            CornerTable::from_triangles(&closed, vertex_count + dummies)?,
            dummies,
        )
    } else {
        (open, 0)
    };
    let total_vertices = vertex_count + dummies;
    let nt = table.triangle_count();
    let mut face_order = scratch.take_empty(nt);
    // The table relabelled in traversal order (see `EncodedConnectivity::traversal_ordered`),
    // built as each triangle is visited: its corners are in cache then, and so are most of
    // its neighbours' ranks.
    let (cv, opp) = (table.corner_vertices(), table.opposites());
    let mut vertex_rank = scratch.take_filled(table.vertex_count(), u32::MAX);
    let mut face_rank = scratch.take_filled(nt, u32::MAX);
    let mut next_vertex = 0u32;
    // Every triangle is written as it is visited (a traversal that misses one fails).
    let mut ov = scratch.take_overwritten(nt, [0u32; 3]);
    let mut oo = scratch.take_filled(3 * nt, u32::MAX);
    let mut new_starts = Vec::new();
    let mut tips: Vec<u8> = scratch.take_empty(nt);
    let summary = traverse_in(
        &table,
        None,
        // In line in the traversal's loop (a call per triangle otherwise).
        #[inline(always)]
        |step| {
            let f = match step {
                Step::Start { corner } => {
                    new_starts.push(3 * face_order.len() as u32 + corner.0 % 3);
                    tips.push((corner.0 % 3) as u8);
                    for c in [corner, table.next(corner), table.prev(corner)] {
                        vertex_rank[table.vertex(c).index()] = next_vertex;
                        next_vertex += 1;
                    }
                    corner.0 / 3
                }
                Step::Triangle { tip, label, .. } => {
                    if label == Clers::C {
                        vertex_rank[table.vertex(tip).index()] = next_vertex;
                        next_vertex += 1;
                    }
                    tips.push((tip.0 % 3) as u8);
                    tip.0 / 3
                }
            } as usize;
            let i = face_order.len();
            face_order.push(f as u32);
            face_rank[f] = i as u32;
            for j in 0..3 {
                let c = 3 * f + j;
                ov[i][j] = vertex_rank[cv[c] as usize];
                let o = opp[c];
                if o != u32::MAX {
                    let g = face_rank[o as usize / 3];
                    if g != u32::MAX {
                        let no = 3 * g + o % 3;
                        oo[3 * i + j] = no;
                        oo[no as usize] = (3 * i + j) as u32;
                    }
                }
            }
        },
        scratch,
    )?;
    scratch.give(vertex_rank);
    scratch.give(face_rank);
    if face_order.len() != nt {
        return Err(Error::Corrupt("the traversal did not visit every triangle"));
    }
    let starts = summary.starts.clone();
    let mut is_dummy = vec![false; total_vertices];
    for d in is_dummy.iter_mut().skip(vertex_count) {
        *d = true;
    }

    let mut bytes = Vec::new();
    let n = summary.labels.len() as u64;
    write_varint(&mut bytes, n);
    write_varint(&mut bytes, starts.len() as u64);
    write_varint(&mut bytes, summary.splits.len() as u64);
    write_varint(&mut bytes, dummies as u64);

    let mut enc = RangeEncoder::new();
    let mut side = SideModels::new();
    let mut prev_source = 0u32;
    for ev in &summary.splits {
        side.source_delta.encode(&mut enc, ev.source - prev_source);
        side.split_distance.encode(&mut enc, ev.source - ev.split);
        enc.encode_bit(&mut side.right, ev.right);
        prev_source = ev.source;
    }
    let mut prev_pos = 0u32;
    for (pos, v) in summary.vertex_order.iter().enumerate() {
        if is_dummy[v.index()] {
            side.dummy_delta.encode(&mut enc, pos as u32 - prev_pos);
            prev_pos = pos as u32;
        }
    }
    match labels {
        LabelCode::Static => {
            let mut sink = whet_bits::StaticResidualEncoder::new(STATIC_LABEL_CONTEXTS);
            code_labels(&mut sink, &summary.labels, &summary.splits, scratch)?;
            let coded = sink.finish();
            write_varint(&mut bytes, coded.len() as u64);
            bytes.extend_from_slice(&coded);
        }
        _ => {
            let mut sink = AdaptiveLabels {
                sink: &mut enc,
                models: LabelModels::new(),
            };
            code_labels(&mut sink, &summary.labels, &summary.splits, scratch)?;
        }
    }
    bytes.extend_from_slice(&enc.finish());
    Ok(EncodedConnectivity {
        bytes,
        connectivity: Connectivity {
            table,
            starts,
            is_dummy,
            summary,
            decoder_steps: None,
            visit_tips: None,
        },
        face_order,
        ordered: Some((ov, oo, new_starts)),
        visit_tips: Some(tips),
    })
}

/// Bits the labels alone cost with whet's contexts (measurement for reports and tests).
pub fn label_bits(labels: &[Clers], splits: &[SplitEvent]) -> Result<f64, Error> {
    let mut counter = CostCounter::new();
    let mut sink = AdaptiveLabels {
        sink: &mut counter,
        models: LabelModels::new(),
    };
    code_labels(&mut sink, labels, splits, &mut Scratch::new())?;
    Ok(counter.bits())
}

/// Decodes a payload written by [`encode_connectivity`]. Returns the connectivity and the
/// number of bytes consumed. Its vertices are numbered in traversal order, the real ones
/// first (`0..r`) and the holes' dummies after them, so `summary.vertex_order` lists the
/// real vertices as `0, 1, .., r - 1` with the dummies' ids at their places in the order.
pub fn decode_connectivity(
    bytes: &[u8],
    limits: &ConnectivityLimits,
) -> Result<(Connectivity, usize), Error> {
    decode_connectivity_reusing(bytes, limits, &mut ConnectivityBuffers::default())
}

/// The arrays [`decode_connectivity_reusing`] builds a connectivity in, kept between decodes
/// by a caller that decodes one stream after another: on a 1.3M-triangle mesh about 45 MB
/// that would otherwise be fresh memory, faulted in page by page, at every decode. Holds
/// the largest sizes decoded so far until dropped.
#[derive(Debug, Default)]
pub struct ConnectivityBuffers {
    reverse: ReverseBuffers,
    labels: Vec<Clers>,
    order: Vec<u32>,
    new_id: Vec<u32>,
    vertex_corner: Vec<u32>,
    is_dummy: Vec<bool>,
}

impl ConnectivityBuffers {
    /// Takes back the arrays of a connectivity this decoded (any connectivity's are fine;
    /// their contents are ignored).
    pub fn recycle(&mut self, conn: Connectivity) {
        let triangles = self.recycle_all_but_triangles(conn);
        self.recycle_triangles(triangles);
    }

    /// [`ConnectivityBuffers::recycle`] but for the table's triangle list, which it returns
    /// (what a decoder outputs).
    pub fn recycle_all_but_triangles(&mut self, conn: Connectivity) -> Vec<[u32; 3]> {
        let (triangles, opposite, vertex_corner) = conn.table.into_parts();
        self.reverse.o = opposite;
        self.vertex_corner = vertex_corner;
        self.labels = conn.summary.labels;
        self.order = conn.summary.vertex_order.into_iter().map(|v| v.0).collect();
        self.is_dummy = conn.is_dummy;
        triangles
    }

    /// Takes back a triangle list (a decoded mesh's, once its user is done with it): the
    /// next decode builds its table, and so its output, in it.
    pub fn recycle_triangles(&mut self, triangles: Vec<[u32; 3]>) {
        if triangles.capacity() > self.reverse.v.capacity() {
            self.reverse.v = triangles;
        }
    }
}

/// Clears `v` and fills it with `n` copies of `x`, in the memory it has.
fn refill<T: Copy>(mut v: Vec<T>, n: usize, x: T) -> Vec<T> {
    v.clear();
    v.resize(n, x);
    v
}

/// [`decode_connectivity`] in the arrays of `buffers` (and of connectivities recycled into
/// it): the same results, without fresh memory once the buffers are as large as the stream
/// needs.
pub fn decode_connectivity_reusing(
    bytes: &[u8],
    limits: &ConnectivityLimits,
    buffers: &mut ConnectivityBuffers,
) -> Result<(Connectivity, usize), Error> {
    decode_connectivity_coded(bytes, limits, LabelCode::Adaptive, buffers)
}

/// Decodes the labels `0..n` in decoding order from `src` into `decoded`, driving `rev`.
#[inline(always)]
fn decode_labels<L: LabelSource>(
    src: &mut L,
    rev: &mut ReverseDecoder,
    decoded: &mut Vec<Clers>,
    n: u32,
) -> Result<(), Error> {
    let mut prev = Clers::E;
    for i in 0..n {
        let gate = rev.gate();
        let sym = match gate {
            // Nothing open: the symbol is a forced E, not coded.
            None => Clers::E,
            Some(g) => Clers::from_index(src.label(g.context, prev))
                .ok_or(Error::Corrupt("label out of range"))?,
        };
        rev.apply(sym, gate)?;
        decoded.push(sym);
        prev = sym;
        // A stream cut short decodes zeros forever; stop early rather than building a
        // huge garbage mesh.
        if i % 4096 == 0 && src.overran() {
            return Err(Error::Truncated);
        }
    }
    Ok(())
}

/// [`decode_connectivity_reusing`] for a payload whose labels are in `labels`' code (what
/// its encoder was told: [`encode_connectivity_coded_in`]).
pub fn decode_connectivity_coded(
    bytes: &[u8],
    limits: &ConnectivityLimits,
    labels: LabelCode,
    buffers: &mut ConnectivityBuffers,
) -> Result<(Connectivity, usize), Error> {
    let mut pos = 0usize;
    let n = read_varint(bytes, &mut pos)?;
    let k = read_varint(bytes, &mut pos)?;
    let nsplits = read_varint(bytes, &mut pos)?;
    let ndummies = read_varint(bytes, &mut pos)?;
    let triangles = n
        .checked_add(k)
        .ok_or(Error::Corrupt("symbol count overflows"))?;
    if triangles > limits.max_triangles {
        return Err(Error::LimitExceeded {
            what: "triangles",
            limit: limits.max_triangles,
            value: triangles,
        });
    }
    // Every closed component has at least three symbols; two events per handle and a
    // handle needs several symbols; one dummy per hole, holes need several symbols.
    if k > n || nsplits > n || ndummies > n || (n > 0 && k == 0) {
        return Err(Error::Corrupt("inconsistent connectivity counts"));
    }
    // The static label stream comes before the side information.
    let static_labels = match labels {
        LabelCode::Static => {
            let len = read_varint(bytes, &mut pos)?;
            let end = usize::try_from(len)
                .ok()
                .and_then(|l| pos.checked_add(l))
                .filter(|&e| e <= bytes.len())
                .ok_or(Error::Truncated)?;
            let coded = &bytes[pos..end];
            pos = end;
            Some(coded)
        }
        _ => None,
    };
    let payload = bytes.get(pos..).ok_or(Error::Truncated)?;
    let mut dec = RangeDecoder::new(payload)?;
    let mut side = SideModels::new();
    let mut splits = Vec::with_capacity(nsplits.min(1 << 16) as usize);
    let mut source = 0u32;
    for _ in 0..nsplits {
        source = source
            .checked_add(side.source_delta.decode(&mut dec))
            .ok_or(Error::Corrupt("split source overflows"))?;
        let dist = side.split_distance.decode(&mut dec);
        let split = source
            .checked_sub(dist)
            .ok_or(Error::Corrupt("split event before the first symbol"))?;
        let right = dec.decode_bit(&mut side.right);
        if source as u64 >= n || dist == 0 {
            return Err(Error::Corrupt("split event out of range"));
        }
        splits.push(SplitEvent {
            source,
            split,
            right,
        });
        if dec.overran() {
            return Err(Error::Truncated);
        }
    }
    let mut dummy_positions = Vec::with_capacity(ndummies.min(1 << 16) as usize);
    let mut p = 0u64;
    for i in 0..ndummies {
        let d = side.dummy_delta.decode(&mut dec) as u64;
        if i > 0 && d == 0 {
            return Err(Error::Corrupt("dummy vertex listed twice"));
        }
        p += d;
        dummy_positions.push(p);
        if dec.overran() {
            return Err(Error::Truncated);
        }
    }

    let n32 = n as u32;
    let mut rev = ReverseDecoder::with_buffers(
        n32,
        &splits,
        (triangles as usize).min(1 << 22),
        std::mem::take(&mut buffers.reverse),
    );
    // Labels in decoding order (the reverse of the encoder's).
    let mut decoded: Vec<Clers> = std::mem::take(&mut buffers.labels);
    decoded.clear();
    decoded.reserve((n as usize).min(1 << 22));
    match static_labels {
        Some(coded) => {
            let mut src = whet_bits::StaticResidualDecoder::new(coded, STATIC_LABEL_CONTEXTS)?;
            decode_labels(&mut src, &mut rev, &mut decoded, n32)?;
            src.finish()?;
        }
        None => {
            let mut src = AdaptiveLabelSource {
                dec: &mut dec,
                models: LabelModels::new(),
            };
            decode_labels(&mut src, &mut rev, &mut decoded, n32)?;
        }
    }
    let consumed = pos + dec.position();
    dec.finish()?;
    let starts = rev.finish(k as usize)?;
    let steps = rev.component_steps()?;
    let vertex_ids = rev.vertex_ids();
    let v = std::mem::take(&mut rev.v);
    let o = std::mem::take(&mut rev.o);
    buffers.reverse.leftmost = std::mem::take(&mut rev.leftmost);
    buffers.reverse.valence = std::mem::take(&mut rev.valence);
    drop(rev);
    // The traversal's vertex order without traversing again: per component, the start
    // triangle's vertices, then the tip of each C in encoding order; decoder step i made
    // triangle i, whose corner 3 i is its tip. In the reverse decoder's ids first.
    let corner_vertex = v.as_flattened();
    let vertex_at = |c: u32| {
        corner_vertex
            .get(c as usize)
            .copied()
            .ok_or(Error::Corrupt("a start corner is out of range"))
    };
    let mut order = std::mem::take(&mut buffers.order);
    order.clear();
    order.reserve(vertex_ids);
    for (&s, range) in starts.iter().zip(&steps) {
        let base = s - s % 3;
        for c in [s, base + (s + 1) % 3, base + (s + 2) % 3] {
            order.push(vertex_at(c)?);
        }
        for i in range.clone().rev() {
            if decoded[i as usize] == Clers::C {
                order.push(vertex_at(3 * i)?);
            }
        }
    }
    // Renumber the vertices in that order, the real ones first and the holes' dummies
    // after them, so that a geometry decoder's output order is the ids' own (no rank
    // arrays, positions written in sequence, the triangle list kept as it is when there
    // are no holes). Every vertex must come exactly once: what the traversal guarantees,
    // and what a corrupt stream may break.
    let real = order
        .len()
        .checked_sub(dummy_positions.len())
        .ok_or(Error::Corrupt("dummy vertex position out of range"))?;
    const NONE: u32 = u32::MAX;
    let mut new_id = refill(std::mem::take(&mut buffers.new_id), vertex_ids, NONE);
    let (mut next_real, mut next_dummy) = (0u32, real as u32);
    let mut dummies = dummy_positions.iter().peekable();
    for (pos, x) in order.iter_mut().enumerate() {
        let slot = new_id
            .get_mut(*x as usize)
            .ok_or(Error::Corrupt("a corner has no vertex"))?;
        if *slot != NONE {
            return Err(Error::Corrupt(
                "the decoded vertex order is not a permutation",
            ));
        }
        // The dummy positions increase (their deltas are checked positive).
        if dummies.next_if(|&&p| p == pos as u64).is_some() {
            *slot = next_dummy;
            next_dummy += 1;
        } else {
            *slot = next_real;
            next_real += 1;
        }
        *x = *slot;
    }
    if dummies.next().is_some() {
        return Err(Error::Corrupt("dummy vertex position out of range"));
    }
    let vertex_count = order.len();
    // The reverse decoder builds fans by construction; walks over the table stay bounded
    // even if a corrupt stream produced a split fan, so the fan check is skipped. The table
    // must be closed (the holes open later): a corner left unglued is found here, in the
    // pass that checks the pairs, which also renumbers the triangles (a vertex outside the
    // order, or a corner without a vertex, has no new number).
    let table = CornerTable::from_raw_closed_renumbering(
        v,
        o,
        &new_id,
        vertex_count,
        std::mem::take(&mut buffers.vertex_corner),
    )
    .map_err(|e| match e {
        MeshError::OpenEdge { .. } => Error::Corrupt("the decoded mesh is not closed"),
        MeshError::IndexOutOfRange { .. } => {
            Error::Corrupt("a corner's vertex is missing from the decoded vertex order")
        }
        _ => Error::Corrupt("the decoded mesh is not a manifold"),
    })?;
    buffers.new_id = new_id;
    let starts: Vec<CornerId> = starts.into_iter().map(CornerId).collect();
    decoded.reverse();
    let summary = TraversalSummary {
        labels: decoded,
        splits,
        starts: starts.clone(),
        vertex_order: order.into_iter().map(VertexId).collect(),
    };
    let mut is_dummy = refill(std::mem::take(&mut buffers.is_dummy), vertex_count, false);
    is_dummy[real..].fill(true);
    Ok((
        Connectivity {
            table,
            starts,
            is_dummy,
            summary,
            // The ranges partition 0..n (component_steps checks it).
            decoder_steps: Some(steps),
            visit_tips: None,
        },
        consumed,
    ))
}
