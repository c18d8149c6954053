//! Entry points shared by the cargo-fuzz targets in `fuzz/` and the stable replay tests of
//! their regressions, so a crasher found by the fuzzer is re-checked by `cargo test` forever.

use crate::{decode, DecodeOptions, ExactPayloads, Quantizer};
use whet_format::Limits;

fn check_valid(mesh: &whet_mesh::Mesh) {
    let n = mesh.positions.len() as u32;
    assert!(
        mesh.triangles.iter().all(|t| t.iter().all(|&v| v < n)),
        "decoder returned an index out of range"
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
}

/// The exact mode's payload decoders behind the container's CRCs: byte 0 picks the
/// quantization bits, byte 1 where the input splits into the connectivity and geometry
/// payloads.
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
    if let Ok(mesh) = crate::decode_exact_payloads(&p) {
        check_valid(&mesh);
    }
}
