//! The public decoders: from a slice, from any `Read`, and sans-IO chunk by chunk; all three
//! parse the container with whet-format and hand its sections to the mode's decoder.

use crate::exact::{decode_exact, ExactPrediction};
use crate::{Error, Quantizer};
use std::io::Read;
use whet_edgebreaker::ConnectivityLimits;
use whet_format::{tag, Container, HeaderInfo, Limits, Mode, Progress, SectionKind};
use whet_mesh::{Aabb, DVec3, Mesh};

/// Options of the decoders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[non_exhaustive]
pub struct DecodeOptions {
    /// Bounds on what a stream may make the decoder allocate.
    pub limits: Limits,
    /// Apply the surface filter a swing stream carries ([`crate::SurfaceFilter`]). Off, the
    /// decoder returns the retiled vertices as the swing construction placed them, on the
    /// original surface: the input EdgeSharpener expects (`whet decode --sharpen`).
    pub surface_filter: bool,
}

impl DecodeOptions {
    /// Safe default limits, the stream's surface filter applied.
    pub const DEFAULT: DecodeOptions = DecodeOptions {
        limits: Limits::DEFAULT,
        surface_filter: true,
    };

    /// Sets the limits.
    pub const fn with_limits(mut self, limits: Limits) -> Self {
        self.limits = limits;
        self
    }

    /// Applies the stream's surface filter or not.
    pub const fn with_surface_filter(mut self, on: bool) -> Self {
        self.surface_filter = on;
        self
    }
}

impl Default for DecodeOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the exact and swing decoders hold at their peak per declared triangle, and per
/// declared vertex, rounded up from measurements (`whet decode` of a 848k-triangle exact
/// stream: 58.5 MB resident; of a 1.05M-triangle swing stream: 57.8 MB; 2026-12-02; of a
/// 1.107M-triangle, 553k-vertex swing stream with the extended surface filter: 76.1 MB,
/// 2026-12-05, against the 93 MB this estimate gives). Their sum over the header's counts is
/// held against [`Limits::max_alloc_bytes`] before decoding.
pub const DECODE_BYTES_PER_TRIANGLE: u64 = 60;
/// See [`DECODE_BYTES_PER_TRIANGLE`].
pub const DECODE_BYTES_PER_VERTEX: u64 = 48;
/// The `what` of the [`whet_format::Error::LimitExceeded`] a decoder returns when that
/// estimate passes [`Limits::max_alloc_bytes`].
pub const DECODE_PEAK_LIMIT: &str = "bytes decoding allocates (estimated)";

/// Decodes a whole `.whet` stream held in memory.
pub fn decode(bytes: &[u8], opts: &DecodeOptions) -> Result<Mesh, Error> {
    let container = whet_format::parse(bytes, &opts.limits)?;
    decode_container(&container, opts)
}

/// Memory a caller keeps between decodes: the exact decoder's working arrays (its corner
/// table, the traversal's arrays, the quantized positions) and, once given back with
/// [`DecodeBuffers::recycle`], an earlier output's vertex and triangle arrays. Decoding one
/// stream after another ([`decode_reusing`]) then works in memory already mapped instead
/// of faulting fresh pages in (on a 1.3M-triangle mesh about 80 MB per decode, a third of
/// the decode's time on a virtual machine). Holds the largest sizes decoded so far until
/// dropped; the swing mode decodes as [`decode`] does.
#[derive(Debug, Default)]
pub struct DecodeBuffers {
    exact: crate::exact::ExactBuffers,
}

impl DecodeBuffers {
    /// Empty buffers.
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes back a mesh the caller is done with: the next decode writes its output in the
    /// mesh's arrays.
    pub fn recycle(&mut self, mesh: Mesh) {
        self.exact.connectivity.recycle_triangles(mesh.triangles);
        if mesh.positions.capacity() > self.exact.positions.capacity() {
            self.exact.positions = mesh.positions;
        }
    }
}

/// [`decode`] in the memory of `buffers`: the same mesh, or the same error, from the same
/// bytes.
pub fn decode_reusing(
    bytes: &[u8],
    opts: &DecodeOptions,
    buffers: &mut DecodeBuffers,
) -> Result<Mesh, Error> {
    let container = whet_format::parse(bytes, &opts.limits)?;
    decode_container_reusing(&container, opts, buffers)
}

/// Version, mode and counts of a stream, from its first bytes, without decoding.
pub fn peek_header(bytes: &[u8]) -> Result<HeaderInfo, Error> {
    Ok(whet_format::peek_header(bytes)?)
}

/// Decodes a parsed container.
pub fn decode_container(container: &Container, opts: &DecodeOptions) -> Result<Mesh, Error> {
    decode_container_reusing(container, opts, &mut DecodeBuffers::default())
}

/// [`decode_container`] in the memory of `buffers` (see [`decode_reusing`]).
pub fn decode_container_reusing(
    container: &Container,
    opts: &DecodeOptions,
    buffers: &mut DecodeBuffers,
) -> Result<Mesh, Error> {
    let h = &container.header;
    opts.limits
        .check_counts(h.vertex_count, h.triangle_count)
        .map_err(Error::Format)?;
    // What decoding will hold at its peak, from the declared counts, before any of it: a
    // stream of a few kilobytes can declare (and, with a skewed label model, code) hundreds
    // of millions of triangles. (The swing decoder also holds its walk's own triangle count
    // to the limit: it may exceed the header's.)
    let check_peak = || {
        let peak = h
            .triangle_count
            .saturating_mul(DECODE_BYTES_PER_TRIANGLE)
            .saturating_add(h.vertex_count.saturating_mul(DECODE_BYTES_PER_VERTEX));
        if peak > opts.limits.max_alloc_bytes {
            return Err(Error::Format(whet_format::Error::LimitExceeded {
                what: DECODE_PEAK_LIMIT,
                limit: opts.limits.max_alloc_bytes,
                value: peak,
            }));
        }
        Ok(())
    };
    let mesh = match h.mode {
        Mode::Exact => {
            check_peak()?;
            let bits = h
                .get_u64(tag::QUANT_BITS)
                .ok_or(Error::MissingField("quant_bits"))?;
            if !(1..=30).contains(&bits) {
                return Err(Error::Corrupt(format!(
                    "quantization bits {bits} out of range"
                )));
            }
            let (min, max) = h.bbox().ok_or(Error::MissingField("bbox"))?;
            let bbox = Aabb {
                min: DVec3::from_array(min),
                max: DVec3::from_array(max),
            };
            if !bbox.min.is_finite() || !bbox.max.is_finite() {
                return Err(Error::Corrupt("bounding box is not finite".into()));
            }
            if !bbox.size().max_element().is_finite() {
                return Err(Error::Corrupt(
                    "bounding box extent overflows (no encoder writes one)".into(),
                ));
            }
            let quantizer = Quantizer::new(&bbox, bits as u32);
            let conn = container
                .section(SectionKind::CONNECTIVITY)
                .ok_or(Error::MissingSection("connectivity"))?;
            let geom = container
                .section(SectionKind::GEOMETRY)
                .ok_or(Error::MissingSection("geometry"))?;
            // The coded triangles are the mesh's plus one dummy per boundary edge (each
            // hole is closed by a fan), and a triangle has at most three boundary edges: a
            // triangle soup codes four times its count. Also held to what the byte limit
            // allows at the decoders' peak per triangle (the check above counted the
            // header's triangles only).
            let limits = ConnectivityLimits::DEFAULT.with_max_triangles(
                h.triangle_count
                    .saturating_mul(4)
                    .saturating_add(64)
                    .min(opts.limits.max_alloc_bytes / DECODE_BYTES_PER_TRIANGLE),
            );
            let prediction = match h.get_u64(tag::EXACT_PREDICTION) {
                None => ExactPrediction::Degree,
                Some(code) => ExactPrediction::from_code(code).ok_or_else(|| {
                    Error::Corrupt(format!(
                        "unknown exact prediction {code} (this whet reads 0, 1 and 2; a newer whet may \
                         have written it)"
                    ))
                })?,
            };
            decode_exact(
                conn,
                geom,
                &quantizer,
                &limits,
                prediction,
                &mut buffers.exact,
            )?
        }
        Mode::Swing => {
            check_peak()?;
            crate::swing::decode_swing(container, opts)?
        }
        other => {
            return Err(Error::Parameter(format!(
                "mode {other} is not available in this build"
            )))
        }
    };
    if mesh.positions.len() as u64 != h.vertex_count
        || mesh.triangles.len() as u64 != h.triangle_count
    {
        return Err(Error::Corrupt(format!(
            "decoded {} vertices and {} triangles, the header says {} and {}",
            mesh.positions.len(),
            mesh.triangles.len(),
            h.vertex_count,
            h.triangle_count
        )));
    }
    Ok(mesh)
}

/// A decoder over any reader: [`Decoder::new`] then [`Decoder::decode`], which reads the
/// whole stream (the header included) and decodes it.
pub struct Decoder<R: Read> {
    reader: R,
    opts: DecodeOptions,
}

impl<R: Read> Decoder<R> {
    /// A decoder reading from `reader`.
    pub fn new(reader: R, opts: DecodeOptions) -> Self {
        Decoder { reader, opts }
    }

    /// Reads the whole stream and decodes it.
    pub fn decode(self) -> Result<Mesh, Error> {
        let container = whet_format::read_from(self.reader, &self.opts.limits)?;
        decode_container(&container, &self.opts)
    }
}

/// Sans-IO decoder for servers that receive a stream in pieces: feed chunks with
/// [`StreamingDecoder::update`]; when it reports [`Progress::Done`], [`StreamingDecoder::finish`]
/// gives the mesh. Results do not depend on the chunking.
pub struct StreamingDecoder {
    inner: whet_format::StreamingDecoder,
    opts: DecodeOptions,
}

impl StreamingDecoder {
    /// A decoder with `opts`.
    pub fn new(opts: DecodeOptions) -> Self {
        StreamingDecoder {
            inner: whet_format::StreamingDecoder::new(opts.limits),
            opts,
        }
    }

    /// Consumes a prefix of `chunk`; returns how many bytes were used and what was reached.
    /// Call again with the rest until it is empty.
    pub fn update(&mut self, chunk: &[u8]) -> Result<(usize, Progress), Error> {
        Ok(self.inner.update(chunk)?)
    }

    /// True once the end marker was read.
    pub fn is_done(&self) -> bool {
        self.inner.is_done()
    }

    /// Decodes the mesh once the stream is complete.
    pub fn finish(self) -> Result<Mesh, Error> {
        let container = self.inner.finish()?;
        decode_container(&container, &self.opts)
    }
}
