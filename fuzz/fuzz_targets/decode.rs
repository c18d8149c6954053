//! The `.whet` decoder on arbitrary bytes: it must return an error or a valid mesh, never
//! panic, hang or allocate without bound. Inputs that start like a real stream reach the
//! connectivity and geometry decoders; the rest exercise the container.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let opts = whet_codec::DecodeOptions::DEFAULT
        .with_limits(whet_format::Limits::DEFAULT.with_max_faces(1 << 20).with_max_vertices(1 << 20));
    if let Ok(mesh) = whet_codec::decode(data, &opts) {
        let n = mesh.positions.len() as u32;
        assert!(mesh.triangles.iter().all(|t| t.iter().all(|&v| v < n)));
    }
    // The connectivity payload alone, without the container's CRC in front of it.
    let limits = whet_edgebreaker::ConnectivityLimits::DEFAULT.with_max_triangles(1 << 20);
    let _ = whet_edgebreaker::decode_connectivity(data, &limits);
});
