//! Entry points shared by the cargo-fuzz targets in `fuzz/` and the stable replay tests of
//! their regressions, so a crasher found by the fuzzer is re-checked by `cargo test` forever.

use crate::{decode, DecodeOptions, ExactPayloads, Quantizer};
use whet_format::{tag, Container, Header, Limits, Mode, SectionKind};

fn check_valid(mesh: &whet_mesh::Mesh) {
    let n = mesh.positions.len() as u32;
    assert!(
        mesh.triangles.iter().all(|t| t.iter().all(|&v| v < n)),
        "decoder returned an index out of range"
    );
    assert!(
        mesh.positions.iter().all(|p| p.is_finite()),
        "decoder returned a non-finite position"
    );
}

/// The whole-stream decoder on arbitrary bytes (small limits keep each run short). Panics
/// only on a decoder bug.
pub fn fuzz_decode(data: &[u8]) {
    let opts = DecodeOptions::DEFAULT.with_limits(
        Limits::DEFAULT
            .with_max_faces(1 << 20)
            .with_max_vertices(1 << 20),
    );
    if let Ok(mesh) = decode(data, &opts) {
        check_valid(&mesh);
    }
    let limits = whet_edgebreaker::ConnectivityLimits::DEFAULT.with_max_triangles(1 << 20);
    let _ = whet_edgebreaker::decode_connectivity(data, &limits);
    // Header field 33 (snap vetoes) behind the container's checks, and on the raw bytes.
    if let Ok(c) = whet_format::parse(data, &opts.limits) {
        let _ = crate::SnapVetoes::of(&c.header);
    }
    let _ = crate::SnapVetoes::from_field(data, 1 << 16);
}

/// The exact mode's payload decoders behind the container's CRCs, both geometry orders:
/// byte 0 picks the quantization bits, byte 1 where the input splits into the connectivity
/// and geometry payloads.
pub fn fuzz_exact_payloads(data: &[u8]) {
    if data.len() < 3 {
        return;
    }
    let bits = (data[0] % 30) as u32 + 1;
    let body = &data[2..];
    let split = (data[1] as usize * body.len() / 256).min(body.len());
    let (conn, geom) = body.split_at(split);
    let p = ExactPayloads {
        connectivity: conn.to_vec(),
        geometry: geom.to_vec(),
        quantizer: Quantizer {
            min: whet_mesh::DVec3::ZERO,
            step: 1.0,
            bits,
        },
        vertex_order: Vec::new(),
        components: 0,
        triangles: 0,
        clers_histogram: [0; 5],
    };
    // Every geometry order reads the same bytes (the traversal orders' payloads have no
    // strategy bit), so each input reaches every decoder.
    for prediction in [
        crate::ExactPrediction::Degree,
        crate::ExactPrediction::Traversal,
        crate::ExactPrediction::TraversalStatic,
    ] {
        let fresh = crate::decode_exact_payloads(&p, prediction);
        if let Ok(mesh) = &fresh {
            check_valid(mesh);
        }
        // Buffers kept from every earlier input of this process (left in any state by the
        // corrupt ones) decode the same.
        let reused = REUSED.with(|b| {
            let mut buffers = b.borrow_mut();
            let r = crate::exact::decode_exact(
                &p.connectivity,
                &p.geometry,
                &p.quantizer,
                &whet_edgebreaker::ConnectivityLimits::DEFAULT,
                prediction,
                &mut buffers,
            );
            if let Ok(mesh) = &r {
                buffers
                    .connectivity
                    .recycle_triangles(mesh.triangles.clone());
            }
            r
        });
        assert_eq!(
            reused.map_err(|e| e.to_string()),
            fresh.map_err(|e| e.to_string()),
            "reused buffers decode otherwise"
        );
    }
}

thread_local! {
    static REUSED: std::cell::RefCell<crate::exact::ExactBuffers> = Default::default();
}

/// Bytes before the payloads in a [`fuzz_swing_payloads`] input.
const SWING_PREFIX: usize = 67;

/// The swing decoder behind the container's CRCs: the input carries the header fields raw
/// (angle bits, quantization bits and component count as one byte each, then `L` and the
/// box as little-endian f64, the two surface filter factors as i16, the connectivity
/// length as u32) and then the connectivity and geometry payloads; the container is built
/// with valid CRCs, so every mutation reaches the swing walk, the cut flags and the surface
/// filter. [`swing_payload_seed`] turns a real stream into such an input. Returns the
/// decoded mesh, if any (checked: indices in range, positions finite).
pub fn fuzz_swing_payloads(data: &[u8]) -> Option<whet_mesh::Mesh> {
    swing_payloads_with(data, [0; 3])
}

/// [`fuzz_swing_payloads`] with the extended surface filter: the input starts with its
/// three factors (header fields 34, 36 and 38) as little-endian i16, then holds a
/// [`fuzz_swing_payloads`] input. [`swing_payload_seed_extended`] makes one from a stream.
pub fn fuzz_swing_payloads_extended(data: &[u8]) -> Option<whet_mesh::Mesh> {
    let (factors, rest) = data.split_first_chunk::<6>()?;
    let i16_at = |i: usize| i64::from(i16::from_le_bytes([factors[i], factors[i + 1]]));
    swing_payloads_with(rest, [i16_at(0), i16_at(2), i16_at(4)])
}

fn swing_payloads_with(data: &[u8], extended: [i64; 3]) -> Option<whet_mesh::Mesh> {
    if data.len() < SWING_PREFIX {
        return None;
    }
    let f64_at = |i: usize| {
        let mut b = [0u8; 8];
        b.copy_from_slice(&data[i..i + 8]);
        f64::from_le_bytes(b)
    };
    let i16_at = |i: usize| i16::from_le_bytes([data[i], data[i + 1]]) as i64;
    let bbox: Vec<f64> = (0..6).map(|k| f64_at(11 + 8 * k)).collect();
    let conn_len = u32::from_le_bytes([data[63], data[64], data[65], data[66]]) as usize;
    let body = &data[SWING_PREFIX..];
    let (conn, geom) = body.split_at(conn_len.min(body.len()));
    let mut header = Header::new(Mode::Swing, 0, 0)
        .with(tag::COMPONENT_COUNT, data[2] as u64)
        .with(tag::QUANT_BITS, data[1] as u64)
        .with(tag::EDGE_LENGTH, f64_at(3))
        .with(tag::ANGLE_BITS, data[0] as u64)
        .with(tag::FILTER_NORMAL, i16_at(59))
        .with(tag::FILTER_SMOOTHED, i16_at(61));
    if extended != [0; 3] {
        header = header
            .with(tag::FILTER_SMOOTHED2, extended[0])
            .with(tag::FILTER_QUADRATIC, extended[1])
            .with(tag::FILTER_TANGENTIAL, extended[2]);
    }
    header.set_bbox([bbox[0], bbox[1], bbox[2]], [bbox[3], bbox[4], bbox[5]]);
    let container = Container::new(header)
        .with_section(SectionKind::CONNECTIVITY, conn.to_vec())
        .with_section(SectionKind::GEOMETRY, geom.to_vec());
    let opts = DecodeOptions::DEFAULT.with_limits(
        Limits::DEFAULT
            .with_max_faces(1 << 20)
            .with_max_vertices(1 << 20),
    );
    let mesh = crate::swing::decode_swing(&container, &opts).ok()?;
    check_valid(&mesh);
    Some(mesh)
}

/// The three extended surface filter fields.
const EXTENDED_FILTER: [u64; 3] = [
    tag::FILTER_SMOOTHED2,
    tag::FILTER_QUADRATIC,
    tag::FILTER_TANGENTIAL,
];

/// The [`fuzz_swing_payloads_extended`] input of a swing stream (`None` for other streams).
pub fn swing_payload_seed_extended(stream: &[u8]) -> Option<Vec<u8>> {
    let c = whet_format::parse(stream, &Limits::DEFAULT).ok()?;
    let mut out = Vec::new();
    for t in EXTENDED_FILTER {
        let v = i16::try_from(c.header.get_i64(t).unwrap_or(0)).ok()?;
        out.extend_from_slice(&v.to_le_bytes());
    }
    out.extend(swing_payload_input(&c)?);
    Some(out)
}

/// The [`fuzz_swing_payloads`] input of a swing stream (`None` for other streams, and for
/// streams with the extended surface filter, whose three factors only
/// [`swing_payload_seed_extended`]'s input holds).
pub fn swing_payload_seed(stream: &[u8]) -> Option<Vec<u8>> {
    let c = whet_format::parse(stream, &Limits::DEFAULT).ok()?;
    if EXTENDED_FILTER
        .iter()
        .any(|&t| c.header.get_i64(t).unwrap_or(0) != 0)
    {
        return None;
    }
    swing_payload_input(&c)
}

fn swing_payload_input(c: &Container) -> Option<Vec<u8>> {
    let h = &c.header;
    if h.mode != Mode::Swing {
        return None;
    }
    let byte = |t: u64| h.get_u64(t).and_then(|v| u8::try_from(v).ok());
    let mut out = vec![
        byte(tag::ANGLE_BITS)?,
        byte(tag::QUANT_BITS)?,
        byte(tag::COMPONENT_COUNT)?,
    ];
    out.extend_from_slice(&h.get_f64(tag::EDGE_LENGTH)?.to_le_bytes());
    let (min, max) = h.bbox()?;
    for v in min.iter().chain(&max) {
        out.extend_from_slice(&v.to_le_bytes());
    }
    for t in [tag::FILTER_NORMAL, tag::FILTER_SMOOTHED] {
        let v = i16::try_from(h.get_i64(t).unwrap_or(0)).ok()?;
        out.extend_from_slice(&v.to_le_bytes());
    }
    let conn = c.section(SectionKind::CONNECTIVITY)?;
    out.extend_from_slice(&u32::try_from(conn.len()).ok()?.to_le_bytes());
    out.extend_from_slice(conn);
    out.extend_from_slice(c.section(SectionKind::GEOMETRY)?);
    Some(out)
}
