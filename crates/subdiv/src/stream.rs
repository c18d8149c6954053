//! The payloads of the `subdiv` codec mode: what [`encode_subdiv`] produces and
//! [`decode_subdiv`] reads. The container plumbing (header fields, section tags) belongs to
//! whet-codec; this module gives it two byte strings and a level count.
//!
//! * **control**: a complete exact-mode `.whet` stream of the control mesh
//!   (`whet_codec::encode`), so its connectivity and positions use the exact mode's coders,
//!   limits and checksums unchanged. The decoder's vertex numbering (traversal order) is the
//!   numbering every later step uses.
//! * **sharpness** (this module's format, version 1):
//!
//! ```text
//! offset 0  u8      format version, 1
//! offset 1  u8      bits b, 1..=8: values are k / (2^b - 1)
//! offset 2  u8      semi-sharp levels (SubdivOptions::sharp_levels), 0..=MAX_LEVELS
//! offset 3  u32 LE  edge count E; must equal the decoded control mesh's edge count
//! offset 7  ...     range-coded (whet-bits) values, one per edge in canonical order
//!                   (sorted [low, high] pairs of the decoded control mesh's vertex ids):
//!                     nonzero flag, BitModel by context c
//!                     if nonzero: k - 1 with a b-bit BitTree by (c > 0)
//!                   c = min(2, coded nonzero edges sharing a vertex with this edge), so
//!                   crease lines, which continue from edge to edge, cost little.
//! ```
//!
//! Smooth control meshes code a long run of zero flags in the first context: a few bytes.

use crate::fit::{fit, FitOptions, FitReport};
use crate::sharpness::EdgeSharpness;
use crate::surface::{subdivide, subdivided_counts, SubdivOptions, MAX_LEVELS};
use crate::Error;
use whet_bits::{BitModel, BitTree, RangeDecoder, RangeEncoder};
use whet_codec::{DecodeOptions, EncodeOptions};
use whet_mesh::Mesh;

/// Version byte of the sharpness payload.
pub const SHARPNESS_FORMAT: u8 = 1;

/// Options of [`encode_subdiv`].
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct SubdivEncodeOptions {
    /// The fit (control vertex count, fitting levels, sharpness mode and bits, ...).
    pub fit: FitOptions,
    /// Quantization bits of the control positions (exact mode), 1..=30.
    pub quant_bits: u32,
    /// Levels the decoder subdivides by default (written in the header); `None`: the
    /// fitting levels.
    pub levels: Option<u32>,
}

impl SubdivEncodeOptions {
    /// The default fit, 12-bit control positions, decoding at the fitting levels.
    pub const DEFAULT: SubdivEncodeOptions = SubdivEncodeOptions {
        fit: FitOptions::DEFAULT,
        quant_bits: 12,
        levels: None,
    };

    /// Sets the fit options.
    pub const fn with_fit(mut self, fit: FitOptions) -> Self {
        self.fit = fit;
        self
    }

    /// Sets the number of control vertices.
    pub const fn with_control_vertices(mut self, n: usize) -> Self {
        self.fit = self.fit.with_control_vertices(n);
        self
    }

    /// Sets the quantization bits of the control positions.
    pub const fn with_quant_bits(mut self, bits: u32) -> Self {
        self.quant_bits = bits;
        self
    }

    /// Sets the default decoding levels.
    pub const fn with_levels(mut self, levels: u32) -> Self {
        self.levels = Some(levels);
        self
    }
}

impl Default for SubdivEncodeOptions {
    fn default() -> Self {
        Self::DEFAULT
    }
}

/// What the subdiv encoder did.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SubdivReport {
    /// The fit's report (absent when the control mesh was given, see [`encode_control`]).
    pub fit: Option<FitReport>,
    /// Control vertices.
    pub control_vertices: usize,
    /// Control triangles.
    pub control_triangles: usize,
    /// Bytes of the control stream.
    pub control_bytes: usize,
    /// Bytes of the sharpness payload.
    pub sharpness_bytes: usize,
    /// Control edges with `h > 0`.
    pub sharp_edges: usize,
    /// Vertices the decoder outputs at the default levels.
    pub decoded_vertices: u64,
    /// Triangles the decoder outputs at the default levels.
    pub decoded_triangles: u64,
}

/// The payloads of one subdiv stream.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct SubdivPayloads {
    /// Exact-mode stream of the control mesh.
    pub control: Vec<u8>,
    /// The sharpness payload (format in the module docs).
    pub sharpness: Vec<u8>,
    /// Default levels of the decoder (header field).
    pub levels: u32,
    /// What happened.
    pub report: SubdivReport,
}

/// Fits `mesh` ([`fit`]) and codes the result ([`encode_control`]).
pub fn encode_subdiv(mesh: &Mesh, opts: &SubdivEncodeOptions) -> Result<SubdivPayloads, Error> {
    let fitted = fit(mesh, &opts.fit)?;
    let levels = opts.levels.unwrap_or(opts.fit.levels);
    let mut out = encode_control(
        &fitted.control,
        &fitted.sharpness,
        opts.fit.levels,
        levels,
        opts.quant_bits,
        opts.fit.sharpness_bits,
    )?;
    out.report.fit = Some(fitted.report);
    Ok(out)
}

/// Codes a given control mesh and sharpness: `sharp_levels` semi-sharp levels (part of the
/// surface), `levels` default decoding levels, `quant_bits` for the positions and
/// `sharpness_bits` per edge.
pub fn encode_control(
    control: &Mesh,
    sharpness: &EdgeSharpness,
    sharp_levels: u32,
    levels: u32,
    quant_bits: u32,
    sharpness_bits: u32,
) -> Result<SubdivPayloads, Error> {
    if !(1..=8).contains(&sharpness_bits) {
        return Err(Error::Parameter(format!(
            "sharpness bits must be 1..=8, got {sharpness_bits}"
        )));
    }
    if sharp_levels > MAX_LEVELS || levels > MAX_LEVELS {
        return Err(Error::LimitExceeded {
            what: "subdivision levels",
            limit: MAX_LEVELS as u64,
            value: sharp_levels.max(levels) as u64,
        });
    }
    if sharpness.edges() != control.undirected_edges().as_slice() {
        return Err(Error::Parameter(
            "the sharpness was made for another mesh".into(),
        ));
    }
    let encoded = whet_codec::encode(
        control,
        &EncodeOptions::DEFAULT
            .with_quant_bits(quant_bits)
            .with_repair(false),
    )?;
    // The decoder numbers vertices in traversal order; express the sharpness on that mesh.
    // Its own stream: trusted, so without the hostile-input limits.
    let decoded = whet_codec::decode(
        &encoded.bytes,
        &DecodeOptions::DEFAULT.with_limits(whet_codec::Limits::UNLIMITED),
    )?;
    let order = &encoded.report.vertex_order;
    let edges = decoded.undirected_edges();
    let mut values = Vec::with_capacity(edges.len());
    for &[a, b] in &edges {
        let (Some(&oa), Some(&ob)) = (order.get(a as usize), order.get(b as usize)) else {
            return Err(Error::Parameter(
                "the exact coder changed the control mesh's vertices".into(),
            ));
        };
        let h = sharpness.get(oa, ob).ok_or_else(|| {
            Error::Parameter("the exact coder changed the control mesh's edges".into())
        })?;
        values.push(h);
    }
    let payload = write_sharpness(
        &edges,
        decoded.positions.len(),
        &values,
        sharpness_bits,
        sharp_levels,
    );
    let (dv, dt) = subdivided_counts(
        decoded.positions.len() as u64,
        edges.len() as u64,
        decoded.triangles.len() as u64,
        levels,
    )
    .unwrap_or((u64::MAX, u64::MAX));
    let report = SubdivReport {
        fit: None,
        control_vertices: decoded.positions.len(),
        control_triangles: decoded.triangles.len(),
        control_bytes: encoded.bytes.len(),
        sharpness_bytes: payload.len(),
        sharp_edges: values.iter().filter(|&&v| v > 0.0).count(),
        decoded_vertices: dv,
        decoded_triangles: dt,
    };
    Ok(SubdivPayloads {
        control: encoded.bytes,
        sharpness: payload,
        levels,
        report,
    })
}

/// A decoded control mesh with its sharpness.
#[derive(Clone, Debug, PartialEq)]
#[non_exhaustive]
pub struct DecodedControl {
    /// The control mesh, in the exact decoder's vertex order.
    pub mesh: Mesh,
    /// Its sharpness (dequantized).
    pub sharpness: EdgeSharpness,
    /// Semi-sharp levels of the surface.
    pub sharp_levels: u32,
}

/// Decodes the control mesh and its sharpness without subdividing.
pub fn decode_control(
    control: &[u8],
    sharpness: &[u8],
    opts: &DecodeOptions,
) -> Result<DecodedControl, Error> {
    let mesh = whet_codec::decode(control, opts)?;
    let (values, sharp_levels) = read_sharpness(sharpness, &mesh)?;
    let sharpness =
        EdgeSharpness::from_values(&mesh, values).map_err(|e| Error::Corrupt(e.to_string()))?;
    Ok(DecodedControl {
        mesh,
        sharpness,
        sharp_levels,
    })
}

/// Decodes a subdiv stream's payloads and subdivides `levels` times (0: the control mesh
/// itself), with limit positions. Refuses output larger than `opts.limits` before computing
/// it.
pub fn decode_subdiv(
    control: &[u8],
    sharpness: &[u8],
    levels: u32,
    opts: &DecodeOptions,
) -> Result<Mesh, Error> {
    if levels > MAX_LEVELS {
        return Err(Error::LimitExceeded {
            what: "subdivision levels",
            limit: MAX_LEVELS as u64,
            value: levels as u64,
        });
    }
    let c = decode_control(control, sharpness, opts)?;
    let (v, t) = subdivided_counts(
        c.mesh.positions.len() as u64,
        c.sharpness.len() as u64,
        c.mesh.triangles.len() as u64,
        levels,
    )
    .unwrap_or((u64::MAX, u64::MAX));
    for (what, limit, value) in [
        ("decoded vertices", opts.limits.max_vertices, v),
        ("decoded triangles", opts.limits.max_faces, t),
        (
            SUBDIVISION_PEAK_LIMIT,
            opts.limits.max_alloc_bytes,
            t.saturating_mul(SUBDIVISION_BYTES_PER_TRIANGLE),
        ),
    ] {
        if value > limit {
            return Err(Error::LimitExceeded { what, limit, value });
        }
    }
    subdivide(
        &c.mesh,
        &c.sharpness,
        &SubdivOptions::DEFAULT
            .with_levels(levels)
            .with_sharp_levels(c.sharp_levels),
    )
}

/// What subdividing costs per output triangle at its peak, with the output file's writer:
/// the levels' connectivity and positions and the output mesh (measured: 210 bytes per
/// triangle for `whet decode --levels 6` of the armadillo's stream, 4.1M triangles; 216 for
/// `whet subdivide bunny.off --levels 5`, 7.1M triangles, 1.50 GB maximum resident size).
/// Checked against [`whet_codec::Limits::max_alloc_bytes`] before subdividing (a stream of
/// a few kilobytes can ask for any level count up to the limit) and against `whet subdivide
/// --max-memory`; it was 160, the allocations alone, which let a run pass a budget it then
/// exceeded by a third.
pub const SUBDIVISION_BYTES_PER_TRIANGLE: u64 = 220;

/// The `what` of the [`Error::LimitExceeded`] returned when that estimate passes the byte
/// limit.
pub const SUBDIVISION_PEAK_LIMIT: &str = "bytes the subdivision allocates (estimated)";

/// Zero-flag contexts: nonzero edges already coded around this edge, 0, 1, 2+.
const CONTEXTS: usize = 3;

/// Length of the sharpness payload's fixed header.
const HEADER_LEN: usize = 7;

/// Walks the edges in canonical order with their contexts; `code(ctx)` codes (encoder) or
/// decodes (decoder) one quantized value and returns it. Shared by both sides so the
/// contexts cannot drift apart.
fn walk(edges: &[[u32; 2]], vertex_count: usize, mut code: impl FnMut(usize) -> u32) {
    let mut around = vec![0u8; vertex_count];
    for &[a, b] in edges {
        let (a, b) = (a as usize, b as usize);
        let ctx = (around[a] as usize + around[b] as usize).min(CONTEXTS - 1);
        if code(ctx) != 0 {
            around[a] = around[a].saturating_add(1);
            around[b] = around[b].saturating_add(1);
        }
    }
}

fn write_sharpness(
    edges: &[[u32; 2]],
    vertex_count: usize,
    values: &[f64],
    bits: u32,
    sharp_levels: u32,
) -> Vec<u8> {
    let top = (1u32 << bits) - 1;
    let mut out = vec![SHARPNESS_FORMAT, bits as u8, sharp_levels as u8];
    out.extend_from_slice(&(values.len() as u32).to_le_bytes());
    let mut enc = RangeEncoder::new();
    let mut flags = [BitModel::new(); CONTEXTS];
    let mut trees = [BitTree::new(bits), BitTree::new(bits)];
    let mut next = values.iter();
    walk(edges, vertex_count, |ctx| {
        let h = next.next().copied().unwrap_or(0.0);
        let k = (h.clamp(0.0, 1.0) * top as f64).round() as u32;
        enc.encode_bit(&mut flags[ctx], k != 0);
        if k != 0 {
            enc.encode_tree(&mut trees[(ctx > 0) as usize], k - 1);
        }
        k
    });
    out.extend_from_slice(&enc.finish());
    out
}

fn read_sharpness(bytes: &[u8], mesh: &Mesh) -> Result<(Vec<f64>, u32), Error> {
    if bytes.len() < HEADER_LEN {
        return Err(Error::Truncated);
    }
    if bytes[0] != SHARPNESS_FORMAT {
        return Err(Error::Corrupt(format!(
            "sharpness payload format {} (this whet reads {SHARPNESS_FORMAT})",
            bytes[0]
        )));
    }
    let bits = bytes[1] as u32;
    if !(1..=8).contains(&bits) {
        return Err(Error::Corrupt(format!(
            "sharpness bits {bits} out of 1..=8"
        )));
    }
    let sharp_levels = bytes[2] as u32;
    if sharp_levels > MAX_LEVELS {
        return Err(Error::Corrupt(format!(
            "{sharp_levels} semi-sharp levels (at most {MAX_LEVELS})"
        )));
    }
    let count = u32::from_le_bytes([bytes[3], bytes[4], bytes[5], bytes[6]]) as usize;
    let edges = mesh.undirected_edges();
    if count != edges.len() {
        return Err(Error::Corrupt(format!(
            "{count} sharpness values for a control mesh with {} edges",
            edges.len()
        )));
    }
    let top = ((1u32 << bits) - 1) as f64;
    let mut dec = RangeDecoder::new(&bytes[HEADER_LEN..]).map_err(|_| Error::Truncated)?;
    let mut flags = [BitModel::new(); CONTEXTS];
    let mut trees = [BitTree::new(bits), BitTree::new(bits)];
    let mut values = Vec::with_capacity(count);
    walk(&edges, mesh.positions.len(), |ctx| {
        let k = if dec.decode_bit(&mut flags[ctx]) {
            dec.decode_tree(&mut trees[(ctx > 0) as usize]) + 1
        } else {
            0
        };
        // k - 1 < 2^bits, so k <= 2^bits; clamp the one value above `top`.
        values.push((k as f64 / top).min(1.0));
        k
    });
    if dec.overran() {
        return Err(Error::Truncated);
    }
    dec.finish().map_err(|e| match e {
        whet_bits::Error::Truncated => Error::Truncated,
        other => Error::Corrupt(other.to_string()),
    })?;
    Ok((values, sharp_levels))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sharpness::tests::whet_testkit_free_cube;

    #[test]
    fn sharpness_payload_round_trips_and_rejects_damage() {
        let cube = whet_testkit_free_cube();
        let edges = cube.undirected_edges();
        let values: Vec<f64> = (0..edges.len())
            .map(|i| [0.0, 1.0, 3.0 / 7.0][i % 3])
            .collect();
        let bytes = write_sharpness(&edges, 8, &values, 3, 2);
        let (back, k) = read_sharpness(&bytes, &cube).unwrap();
        assert_eq!(k, 2);
        for (a, b) in values.iter().zip(&back) {
            assert!((a - b).abs() < 1e-12);
        }
        // Every truncation fails cleanly.
        for len in 0..bytes.len() {
            assert!(
                read_sharpness(&bytes[..len], &cube).is_err(),
                "length {len}"
            );
        }
        let mut bad = bytes.clone();
        bad[0] = 9;
        assert!(matches!(
            read_sharpness(&bad, &cube),
            Err(Error::Corrupt(_))
        ));
        let mut bad = bytes.clone();
        bad[3] ^= 1;
        assert!(matches!(
            read_sharpness(&bad, &cube),
            Err(Error::Corrupt(_))
        ));
    }

    #[test]
    fn smooth_sharpness_costs_a_few_bytes() {
        let cube = whet_testkit_free_cube();
        let edges = cube.undirected_edges();
        let bytes = write_sharpness(&edges, 8, &vec![0.0; edges.len()], 4, 3);
        // 18 zero flags plus the range coder's flush (measured: 6 bytes).
        assert!(bytes.len() <= HEADER_LEN + 8, "{} bytes", bytes.len());
    }
}
