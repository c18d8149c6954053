//! The public encoder: options, preparation of the input (validation, manifold repair,
//! unused vertices), the mode's payloads, and the container.

use crate::exact::{encode_exact, ExactPrediction};
use crate::Error;
use whet_format::{tag, Container, Header, Mode, SectionKind, Version};
use whet_mesh::{morton_spread, ManifoldRepair, Mesh, Scratch};

/// The format version of header field `exact_prediction`.
const VERSION_1_5: Version = Version::new(1, 5);
const VERSION_1_6: Version = Version::new(1, 6);

/// Options of [`Encoder`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct EncodeOptions {
    /// Codec mode.
    pub mode: Mode,
    /// Position quantization bits per coordinate (exact mode), 1..=30.
    pub quant_bits: u32,
    /// Container version to write.
    pub version: Version,
    /// Cut non-manifold input with `Mesh::make_manifold` instead of refusing it.
    pub repair: bool,
    /// Exact mode: the order and predictor of the positions (the degree order by default;
    /// the traversal order decodes about 1.8 times as fast for 3-15 % more bytes on most
    /// meshes, up to about 50 % on blocky CAD parts, and writes format 1.5). Exact mode
    /// only: other modes ignore it.
    pub prediction: ExactPrediction,
}

impl EncodeOptions {
    /// Exact mode, 14 bits, current container version, repair on.
    pub const DEFAULT: EncodeOptions = EncodeOptions {
        mode: Mode::Exact,
        quant_bits: 14,
        version: Version::CURRENT,
        repair: true,
        prediction: ExactPrediction::Degree,
    };

    /// Sets the mode.
    pub const fn with_mode(mut self, mode: Mode) -> Self {
        self.mode = mode;
        self
    }

    /// Sets the quantization bits.
    pub const fn with_quant_bits(mut self, bits: u32) -> Self {
        self.quant_bits = bits;
        self
    }

    /// Sets the container version to write.
    pub const fn with_version(mut self, version: Version) -> Self {
        self.version = version;
        self
    }

    /// Turns manifold repair on or off.
    pub const fn with_repair(mut self, repair: bool) -> Self {
        self.repair = repair;
        self
    }

    /// Sets the exact mode's prediction.
    pub const fn with_prediction(mut self, prediction: ExactPrediction) -> Self {
        self.prediction = prediction;
        self
    }
}

impl Default for EncodeOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the encoder did and what the stream costs.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct EncodeReport {
    /// Total stream size.
    pub bytes: usize,
    /// Vertices in the stream (after repair, without unused ones).
    pub vertices: usize,
    /// Triangles in the stream.
    pub triangles: usize,
    /// Connectivity section payload, in bits.
    pub connectivity_bits: u64,
    /// Geometry section payload, in bits.
    pub geometry_bits: u64,
    /// Connected components.
    pub components: usize,
    /// Counts of the CLERS labels C, L, E, R, S.
    pub clers_histogram: [usize; 5],
    /// For each decoded vertex, the input vertex it came from (the decoder outputs vertices in
    /// traversal order). Vertices added by repair map to the input vertex they copy.
    pub vertex_order: Vec<u32>,
    /// What manifold repair changed (all zero when nothing).
    pub repair: ManifoldRepair,
    /// Input vertices used by no triangle, left out of the stream.
    pub dropped_unused_vertices: usize,
}

impl EncodeReport {
    /// Whole-stream bits per vertex of the coded mesh.
    pub fn bits_per_vertex(&self) -> f64 {
        if self.vertices == 0 {
            0.0
        } else {
            self.bytes as f64 * 8.0 / self.vertices as f64
        }
    }

    /// Whole-stream bits per triangle.
    pub fn bits_per_triangle(&self) -> f64 {
        if self.triangles == 0 {
            0.0
        } else {
            self.bytes as f64 * 8.0 / self.triangles as f64
        }
    }
}

/// An encoded stream and its report.
#[derive(Clone, Debug, PartialEq)]
pub struct Encoded {
    /// The `.whet` bytes.
    pub bytes: Vec<u8>,
    /// What it contains.
    pub report: EncodeReport,
}

/// Encodes meshes with fixed options.
#[derive(Clone, Debug, Default)]
pub struct Encoder {
    opts: EncodeOptions,
}

impl Encoder {
    /// An encoder with `opts`.
    pub fn new(opts: EncodeOptions) -> Self {
        Encoder { opts }
    }

    /// The options.
    pub fn options(&self) -> &EncodeOptions {
        &self.opts
    }

    /// Encodes `mesh`.
    pub fn encode(&self, mesh: &Mesh) -> Result<Encoded, Error> {
        self.encode_reusing(mesh, &mut EncodeBuffers::new())
    }

    /// [`Encoder::encode`] in the memory of `buffers`: the same stream and report, and for
    /// a caller that encodes mesh after mesh with one set of buffers, no fresh memory to
    /// fault in once they are as large as the meshes need (see [`EncodeBuffers`]).
    pub fn encode_reusing(
        &self,
        mesh: &Mesh,
        buffers: &mut EncodeBuffers,
    ) -> Result<Encoded, Error> {
        let scratch = &mut buffers.scratch;
        let opts = &self.opts;
        if !(1..=30).contains(&opts.quant_bits) {
            return Err(Error::Parameter(format!(
                "quantization bits must be 1..=30, got {}",
                opts.quant_bits
            )));
        }
        if opts.version.major != Version::CURRENT.major {
            return Err(Error::Parameter(format!(
                "cannot write container version {}",
                opts.version
            )));
        }
        if opts.mode == Mode::Exact {
            // Fast path: the input's table skips the walk around closed fans (random
            // accesses on an input in random memory order); the encoder walks them on its
            // traversal-ordered copy instead. Any failure takes the path that checks
            // everything up front (and repairs or reports exactly as it always did).
            let fast = prepare_with(mesh, opts.repair, false, scratch)
                .and_then(|p| self.encode_exact(p, true, scratch));
            return match fast {
                Ok(encoded) => Ok(encoded),
                Err(_) => self.encode_exact(prepare(mesh, opts.repair)?, false, scratch),
            };
        }
        let _prepared = prepare(mesh, opts.repair)?;
        match opts.mode {
            Mode::Swing => Err(Error::Parameter(
                "the swing mode's encoder (the retiler) is whet_swing::SwingEncoder; \
                 whet-codec only writes and reads swing streams"
                    .into(),
            )),
            other => Err(Error::Parameter(format!(
                "mode {other} is not available in this build"
            ))),
        }
    }

    /// `check_fans`: `p.table` was built without the closed-fan walk, check on the way.
    fn encode_exact(
        &self,
        p: Prepared,
        check_fans: bool,
        scratch: &mut Scratch,
    ) -> Result<Encoded, Error> {
        let bits = self.opts.quant_bits;
        let prediction = self.opts.prediction;
        let bbox = p.bbox;
        let payloads = encode_exact(
            &p.mesh, &bbox, p.table, bits, check_fans, prediction, scratch,
        )?;
        let (min, max) = if bbox.is_empty() {
            ([0.0; 3], [0.0; 3])
        } else {
            (bbox.min.to_array(), bbox.max.to_array())
        };
        let mut header = Header::new(
            Mode::Exact,
            payloads.vertex_order.len() as u64,
            payloads.triangles as u64,
        )
        .with_version(self.opts.version)
        .with(tag::COMPONENT_COUNT, payloads.components as u64)
        .with(tag::QUANT_BITS, bits as u64);
        if prediction != ExactPrediction::Degree {
            // A reader before format 1.5 refuses the field by tag instead of misreading the
            // geometry.
            // (Value 2, the static residual code, is format 1.6: a 1.5 reader refuses the
            // value as an unknown prediction.)
            let needed = if prediction == ExactPrediction::TraversalStatic {
                VERSION_1_6
            } else {
                VERSION_1_5
            };
            if header.version < needed {
                header = header.with_version(needed);
            }
            header = header.with(tag::EXACT_PREDICTION, prediction.code());
        }
        header.set_bbox(min, max);
        let container = Container::new(header)
            .with_section(SectionKind::CONNECTIVITY, payloads.connectivity.clone())
            .with_section(SectionKind::GEOMETRY, payloads.geometry.clone());
        let bytes = container.to_bytes()?;
        let vertex_order = payloads
            .vertex_order
            .iter()
            .map(|&v| p.original[v as usize])
            .collect();
        // The working copy and the encoder's orders go back for the next mesh.
        scratch.give(p.mesh.positions);
        scratch.give(p.mesh.triangles);
        scratch.give(p.original);
        let vertices = payloads.vertex_order.len();
        scratch.give(payloads.vertex_order);
        let report = EncodeReport {
            bytes: bytes.len(),
            vertices,
            triangles: payloads.triangles,
            connectivity_bits: payloads.connectivity.len() as u64 * 8,
            geometry_bits: payloads.geometry.len() as u64 * 8,
            components: payloads.components,
            clers_histogram: payloads.clers_histogram,
            vertex_order,
            repair: p.repair,
            dropped_unused_vertices: p.dropped_unused,
        };
        Ok(Encoded { bytes, report })
    }
}

/// Encodes `mesh` with `opts` (see [`Encoder`]).
pub fn encode(mesh: &Mesh, opts: &EncodeOptions) -> Result<Encoded, Error> {
    Encoder::new(*opts).encode(mesh)
}

/// Memory an [`Encoder`] keeps between meshes ([`Encoder::encode_reusing`]): the exact
/// mode's working copy of the input, its corner tables, the traversal's arrays and the
/// quantized positions, given back at the end of each encode and taken again by the next.
/// On a 1.3M-triangle mesh an encode touches some 180 MB; fresh, that memory is faulted in
/// page by page (a seventh of the encode's time on the machines whet is measured on).
/// Holds the largest sizes encoded so far until dropped.
#[derive(Debug, Default)]
pub struct EncodeBuffers {
    scratch: Scratch,
}

impl EncodeBuffers {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }
}

/// An input mesh made ready for a codec mode by [`prepare_mesh`].
#[derive(Clone, Debug)]
#[non_exhaustive]
pub struct PreparedMesh {
    /// Finite, oriented manifold, without unused vertices.
    pub mesh: Mesh,
    /// What manifold repair changed.
    pub repair: ManifoldRepair,
    /// Input vertices used by no triangle, left out.
    pub dropped_unused_vertices: usize,
}

/// Checks and repairs an input mesh the way [`Encoder`] does before any mode: refuses
/// non-finite coordinates, cuts non-manifold input with `Mesh::make_manifold` when `repair`
/// is on (else refuses it), and drops unused vertices. The swing encoder (whet-swing) starts
/// from this.
pub fn prepare_mesh(mesh: &Mesh, repair: bool) -> Result<PreparedMesh, Error> {
    let p = prepare(mesh, repair)?;
    Ok(PreparedMesh {
        mesh: p.mesh,
        repair: p.repair,
        dropped_unused_vertices: p.dropped_unused,
    })
}

/// A mesh ready for a mode: finite, oriented manifold, no unused vertices.
pub(crate) struct Prepared {
    pub mesh: Mesh,
    /// `mesh`'s bounding box.
    pub bbox: whet_mesh::Aabb,
    /// Corner table of `mesh` (built once, reused by the connectivity coder).
    pub table: whet_mesh::CornerTable,
    /// Input vertex of each prepared vertex.
    pub original: Vec<u32>,
    pub repair: ManifoldRepair,
    pub dropped_unused: usize,
}

pub(crate) fn prepare(mesh: &Mesh, repair: bool) -> Result<Prepared, Error> {
    prepare_with(mesh, repair, true, &mut Scratch::new())
}

/// [`prepare`]; without `walk_fans` the input's table is built with
/// `CornerTable::from_triangles_deferring_fans` (a vertex pinching closed fans is not
/// detected, nor repaired: the caller must check the fans later and fall back to
/// [`prepare`]).
fn prepare_with(
    mesh: &Mesh,
    repair: bool,
    walk_fans: bool,
    scratch: &mut Scratch,
) -> Result<Prepared, Error> {
    if let Some(v) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(Error::InvalidInput(
            whet_mesh::MeshError::NonFiniteCoordinate { vertex: v as u32 },
        ));
    }
    // The fast path works on a copy in spatial order when the input's memory order is poor:
    // building the table and traversing it then read memory in order (the reordering costs
    // less than the misses it saves on a mesh in random order; docs/codec.md, "Speed").
    // The box of the input's positions: the prepared mesh's too unless vertices are dropped
    // below (a permutation or repair copies keep it).
    let mut bbox = mesh.bounding_box();
    let reordered = if walk_fans {
        None
    } else {
        spatial_order(mesh, &bbox, REORDER_MIN_TRIANGLES, scratch)
    };
    let (mut work, reorder) = match reordered {
        Some((m, order)) => (m, Some(order)),
        None => {
            let mut positions = scratch.take_empty(mesh.positions.len());
            positions.extend_from_slice(&mesh.positions);
            let mut triangles = scratch.take_empty(mesh.triangles.len());
            triangles.extend_from_slice(&mesh.triangles);
            (Mesh::new(positions, triangles), None)
        }
    };
    let input_vertices = work.positions.len();
    let mut rep = ManifoldRepair::default();
    // The table of a valid input is built once and kept unless vertices are dropped below.
    let built = if walk_fans {
        whet_mesh::CornerTable::new(&work)
    } else {
        whet_mesh::CornerTable::from_triangles_deferring_fans_in(
            &work.triangles,
            work.positions.len(),
            scratch,
        )
    };
    let mut table = match built {
        Ok(t) => Some(t),
        // A reordered copy is never repaired: the caller's full path repairs and reports the
        // input in its own numbering.
        Err(e) if reorder.is_some() => return Err(Error::InvalidInput(e)),
        Err(e) => {
            if !repair {
                return Err(Error::InvalidInput(e));
            }
            rep = work.make_manifold();
            None
        }
    };
    // Repair appends copies; remember which input vertex each one copies by position (the
    // repair copies positions exactly, and the first input vertex at that position is the
    // one it split from or an identical one).
    let mut original: Vec<u32> = reorder.unwrap_or_else(|| {
        let mut o = scratch.take_empty(work.positions.len());
        o.extend(0..work.positions.len() as u32);
        o
    });
    if work.positions.len() > input_vertices {
        let mut by_bits: std::collections::HashMap<[u64; 3], u32> = Default::default();
        for (i, p) in mesh.positions.iter().enumerate() {
            by_bits
                .entry([p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .or_insert(i as u32);
        }
        for (i, p) in work.positions.iter().enumerate().skip(input_vertices) {
            original[i] = by_bits
                .get(&[p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
                .copied()
                .unwrap_or(i as u32);
        }
    }
    // Drop unused vertices.
    let mut used = scratch.take_filled(work.positions.len(), false);
    for t in &work.triangles {
        for &v in t {
            used[v as usize] = true;
        }
    }
    let dropped_unused = used[..input_vertices.min(used.len())]
        .iter()
        .filter(|&&u| !u)
        .count();
    if used.iter().any(|&u| !u) {
        let mut remap = vec![u32::MAX; used.len()];
        let mut positions = Vec::with_capacity(used.len());
        let mut orig = Vec::with_capacity(used.len());
        for (i, &u) in used.iter().enumerate() {
            if u {
                remap[i] = positions.len() as u32;
                positions.push(work.positions[i]);
                orig.push(original[i]);
            }
        }
        for t in &mut work.triangles {
            for v in t.iter_mut() {
                *v = remap[*v as usize];
            }
        }
        work.positions = positions;
        original = orig;
        table = None;
        bbox = work.bounding_box();
    }
    scratch.give(used);
    let table = match table {
        Some(t) => t,
        None => whet_mesh::CornerTable::new(&work).map_err(Error::InvalidInput)?,
    };
    Ok(Prepared {
        table,
        bbox,
        mesh: work,
        original,
        repair: rep,
        dropped_unused,
    })
}

/// [`morton_spread`] of every byte, as 24-bit values.
fn morton_spread_bytes() -> [u32; 256] {
    std::array::from_fn(|b| morton_spread(b as u64) as u32)
}

/// Meshes under this many triangles are left in their order: their arrays stay in the
/// caches whatever the order.
const REORDER_MIN_TRIANGLES: usize = 1 << 18;

/// Consecutive triangles per window of [`scattered`].
const WINDOW: usize = 256;

/// Whether the triangles of `mesh` reference their vertices in scattered memory order: over
/// a few windows of [`WINDOW`] consecutive triangles, the median number of distinct blocks
/// of 1024 vertex numbers they touch. A mesh in file order (a scan, a subdivision, marching
/// cubes) touches a handful per window, however far apart its numbers run (a subdivision
/// reads its old vertices and its new midpoints as two streams); one in random order
/// touches nearly one block per corner. `None` when an index is out of range.
fn scattered(tris: &[[u32; 3]], nv: usize) -> Option<bool> {
    const WINDOWS: usize = 9;
    let blocks = nv.div_ceil(1024);
    let mut counts = Vec::with_capacity(WINDOWS);
    let mut seen: Vec<u32> = Vec::with_capacity(3 * WINDOW);
    for w in 0..WINDOWS {
        let first = w * (tris.len() - WINDOW) / (WINDOWS - 1);
        seen.clear();
        for t in &tris[first..first + WINDOW] {
            for &v in t {
                if v as usize >= nv {
                    return None;
                }
                seen.push(v >> 10);
            }
        }
        seen.sort_unstable();
        seen.dedup();
        counts.push(seen.len());
    }
    counts.sort_unstable();
    // Random order: about min(768, blocks) distinct blocks; file order: a few.
    Some(counts[WINDOWS / 2] > 64.min(blocks / 2).max(8))
}

/// Where each of `buckets` buckets starts in a counting sort of `keys` (each below
/// `buckets`).
fn bucket_starts(
    keys: impl Iterator<Item = usize>,
    buckets: usize,
    scratch: &mut Scratch,
) -> Vec<u32> {
    let mut start = scratch.take_filled(buckets + 1, 0u32);
    for k in keys {
        start[k + 1] += 1;
    }
    for i in 0..buckets {
        start[i + 1] += start[i];
    }
    start
}

/// `mesh` renumbered in spatial order, with the input vertex of each new vertex, when it
/// has at least `min_triangles` triangles in [`scattered`] order: vertices by the Morton
/// cell of their position (a counting sort over about one cell per four vertices), triangles
/// by their lowest new vertex (each keeps its corners' rotation). `None`
/// otherwise, or when an index is out of range (the caller reports it).
fn spatial_order(
    mesh: &Mesh,
    bbox: &whet_mesh::Aabb,
    min_triangles: usize,
    scratch: &mut Scratch,
) -> Option<(Mesh, Vec<u32>)> {
    let (nv, nt) = (mesh.positions.len(), mesh.triangles.len());
    if nt < min_triangles.max(WINDOW) || nv == 0 || !scattered(&mesh.triangles, nv)? {
        return None;
    }
    // At most 2^24 cells (64 MB of counts), from about 24M vertices on.
    let bits = ((((nv / 4).max(1) as f64).log2() / 3.0).round() as u32).clamp(1, 8);
    let cells = 1usize << (3 * bits);
    let extent = (bbox.max - bbox.min).max_element().max(f64::MIN_POSITIVE);
    let scale = ((1u32 << bits) as f64 - 1e-6) / extent;
    let top = (1i64 << bits) - 1;
    // At most 8 bits an axis: each axis spread by one lookup. The coordinates are finite
    // and at least the box's minimum, so the scaled ones are in [0, 2^bits) and the signed
    // conversion (one instruction; the unsigned one is a sequence on x86-64) is exact.
    let spread = morton_spread_bytes();
    let mut cell: Vec<u32> = scratch.take_empty(nv);
    cell.extend(mesh.positions.iter().map(|p| {
        let q = ((*p - bbox.min) * scale)
            .to_array()
            .map(|x| (x as i64).clamp(0, top) as usize);
        spread[q[0]] | spread[q[1]] << 1 | spread[q[2]] << 2
    }));
    let mut start = bucket_starts(cell.iter().map(|&c| c as usize), cells, scratch);
    // Each written once below (a permutation).
    let mut new_id = scratch.take_overwritten(nv, 0u32);
    let mut original = scratch.take_overwritten(nv, 0u32);
    let mut positions = scratch.take_overwritten(nv, whet_mesh::DVec3::ZERO);
    for (v, &c) in cell.iter().enumerate() {
        let slot = &mut start[c as usize];
        new_id[v] = *slot;
        original[*slot as usize] = v as u32;
        *slot += 1;
    }
    // Positions gathered in new order (sequential stores, independent loads): in the
    // same pass as the ids, their 24-byte scattered stores took longer.
    for (p, &o) in positions.iter_mut().zip(&original) {
        *p = mesh.positions[o as usize];
    }
    // Triangles by their lowest new vertex, a few vertices to a bucket (new numbers follow
    // the cells).
    let shift = (nv / cells).max(1).ilog2();
    let buckets = (nv >> shift) + 1;
    // An index out of range anywhere (the windows sample only some triangles) leaves the
    // mesh to the table's check, which names it.
    scratch.give(cell);
    scratch.give(start);
    // The renamed triangles and their buckets in two arrays of types later stages take
    // from the scratch again (one array of pairs would be memory nothing reuses).
    let mut renamed: Vec<[u32; 3]> = scratch.take_empty(nt);
    let mut bucket: Vec<u32> = scratch.take_empty(nt);
    for t in &mesh.triangles {
        let r = [
            *new_id.get(t[0] as usize)?,
            *new_id.get(t[1] as usize)?,
            *new_id.get(t[2] as usize)?,
        ];
        renamed.push(r);
        bucket.push(r[0].min(r[1]).min(r[2]) >> shift);
    }
    scratch.give(new_id);
    let mut first = bucket_starts(bucket.iter().map(|&b| b as usize), buckets, scratch);
    // Each written once below (a permutation).
    let mut triangles = scratch.take_overwritten(nt, [0u32; 3]);
    for (&t, &b) in renamed.iter().zip(&bucket) {
        let slot = &mut first[b as usize];
        triangles[*slot as usize] = t;
        *slot += 1;
    }
    scratch.give(renamed);
    scratch.give(bucket);
    scratch.give(first);
    Some((Mesh::new(positions, triangles), original))
}

#[cfg(test)]
mod tests {
    use super::{scattered, spatial_order};
    use whet_testkit::meshes::{icosphere, shuffle};

    #[test]
    fn random_order_is_told_from_file_order() {
        let ico = icosphere(5);
        let nv = ico.positions.len();
        assert_eq!(scattered(&ico.triangles, nv), Some(false));
        assert_eq!(scattered(&shuffle(&ico, 1).triangles, nv), Some(true));
        let mut bad = ico.triangles.clone();
        bad[0][1] = nv as u32;
        assert_eq!(scattered(&bad, nv), None);
    }

    #[test]
    fn an_index_out_of_range_is_left_to_the_table() {
        // In a triangle no window samples: the renumbering must refuse, not panic.
        let mut mesh = shuffle(&icosphere(5), 4);
        let nv = mesh.positions.len() as u32;
        mesh.triangles[300][2] = nv + 7;
        assert!(spatial_order(
            &mesh,
            &mesh.bounding_box(),
            0,
            &mut whet_mesh::Scratch::new()
        )
        .is_none());
        // Without repair the encoder names the index; with it (the default) it cuts the
        // triangle and reports that, as it always did.
        let strict = crate::EncodeOptions::DEFAULT.with_repair(false);
        assert!(crate::encode(&mesh, &strict).is_err());
        let repaired = crate::encode(&mesh, &crate::EncodeOptions::DEFAULT).unwrap();
        assert_eq!(repaired.report.triangles, mesh.triangles.len() - 1);
    }

    #[test]
    fn the_spatial_order_is_a_renumbering() {
        let mesh = shuffle(&icosphere(5), 2);
        assert!(
            spatial_order(
                &mesh,
                &mesh.bounding_box(),
                1 << 30,
                &mut whet_mesh::Scratch::new()
            )
            .is_none(),
            "under the size bound"
        );
        let (m, original) = spatial_order(
            &mesh,
            &mesh.bounding_box(),
            0,
            &mut whet_mesh::Scratch::new(),
        )
        .expect("a shuffled mesh is reordered");
        let mut seen = vec![false; mesh.positions.len()];
        for (new, &old) in original.iter().enumerate() {
            assert!(!std::mem::replace(&mut seen[old as usize], true));
            assert_eq!(m.positions[new], mesh.positions[old as usize]);
        }
        assert!(seen.iter().all(|&s| s));
        // The same triangles, each with its corners' rotation.
        let mut want = mesh.triangles.clone();
        let mut got: Vec<[u32; 3]> = m
            .triangles
            .iter()
            .map(|t| t.map(|v| original[v as usize]))
            .collect();
        want.sort_unstable();
        got.sort_unstable();
        assert_eq!(got, want);
        // In spatial order: consecutive triangles' lowest vertices are close.
        let lowest = |t: &[u32; 3]| t[0].min(t[1]).min(t[2]);
        let far = m
            .triangles
            .windows(2)
            .filter(|w| lowest(&w[0]).abs_diff(lowest(&w[1])) > 64)
            .count();
        assert!(far * 20 < m.triangles.len(), "{far} far jumps");
        assert_eq!(scattered(&m.triangles, m.positions.len()), Some(false));
    }
}
