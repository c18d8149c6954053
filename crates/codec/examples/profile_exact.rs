//! Times the stages of the exact mode on a ~1.3M-triangle icosphere (a profiling aid:
//! `cargo run --release -p whet-codec --example profile_exact -- [encodes] [decodes]`,
//! e.g. `-- 0 20` to profile decoding alone). The icosphere's vertices and triangles are
//! shuffled (the worst memory order an encoder meets); `PROFILE_PREDICTION=traversal` (or `traversal-static`) codes
//! with the traversal prediction; `PROFILE_ORDER=natural` keeps the
//! generator's order, and `PROFILE_MESH=<file>` profiles that mesh in its file's order;
//! `PROFILE_REUSE=1` encodes with one [`EncodeBuffers`] and decodes with one
//! [`DecodeBuffers`] throughout.
#![allow(clippy::unwrap_used)]

use std::time::Instant;
use whet_codec::{
    decode, decode_reusing, encode, DecodeBuffers, DecodeOptions, EncodeBuffers, EncodeOptions,
    Encoder, ExactPrediction,
};

fn main() {
    let arg = |i: usize, d: usize| {
        std::env::args()
            .nth(i)
            .and_then(|a| a.parse().ok())
            .unwrap_or(d)
    };
    let (encodes, decodes) = (arg(1, 1), arg(2, 1));
    let mesh = match (
        std::env::var_os("PROFILE_MESH"),
        std::env::var("PROFILE_ORDER").as_deref(),
    ) {
        (Some(p), _) => whet_io::read_path(std::path::Path::new(&p), None).unwrap(),
        (None, Ok("natural")) => whet_testkit::meshes::icosphere(8),
        _ => whet_testkit::meshes::shuffle(&whet_testkit::meshes::icosphere(8), 1),
    };
    // The stage timings first (they build tables and traverse the input outside the encoder;
    // PROFILE_NO_STAGES=1 leaves them out of a profile of the encoder).
    if encodes > 0 && std::env::var_os("PROFILE_NO_STAGES").is_none() {
        let t = Instant::now();
        let table = whet_mesh::CornerTable::new(&mesh).unwrap();
        eprintln!("corner table: {:?}", t.elapsed());
        let t = Instant::now();
        let s = whet_edgebreaker::traverse(&table, None, |_| {}).unwrap();
        eprintln!("traverse: {:?} ({} labels)", t.elapsed(), s.labels.len());
        let t = Instant::now();
        let c =
            whet_edgebreaker::encode_connectivity(&mesh.triangles, mesh.positions.len()).unwrap();
        eprintln!("encode_connectivity: {:?}", t.elapsed());
        let t = Instant::now();
        let (_d, _) = whet_edgebreaker::decode_connectivity(&c.bytes, &Default::default()).unwrap();
        eprintln!("decode_connectivity: {:?}", t.elapsed());
    }
    let opts = match std::env::var("PROFILE_PREDICTION").as_deref() {
        Ok("traversal") => EncodeOptions::DEFAULT.with_prediction(ExactPrediction::Traversal),
        Ok("traversal-static") => {
            EncodeOptions::DEFAULT.with_prediction(ExactPrediction::TraversalStatic)
        }
        _ => EncodeOptions::DEFAULT,
    };
    // PROFILE_REUSE=1: one set of buffers for every encode and every decode.
    let reuse = std::env::var_os("PROFILE_REUSE").is_some();
    let encoder = Encoder::new(opts);
    let mut encode_buffers = EncodeBuffers::new();
    let mut e = None;
    for _ in 0..encodes.max(1) {
        let t = Instant::now();
        e = Some(if reuse {
            encoder.encode_reusing(&mesh, &mut encode_buffers).unwrap()
        } else {
            encode(&mesh, &opts).unwrap()
        });
        if encodes > 0 {
            eprintln!("encode: {:?}", t.elapsed());
        }
    }
    let e = e.unwrap();
    eprintln!("stream: {} bytes", e.bytes.len());
    let mut buffers = DecodeBuffers::new();
    for _ in 0..decodes {
        let t = Instant::now();
        let m = if reuse {
            decode_reusing(&e.bytes, &DecodeOptions::DEFAULT, &mut buffers).unwrap()
        } else {
            decode(&e.bytes, &DecodeOptions::DEFAULT).unwrap()
        };
        eprintln!(
            "decode: {:?} ({} triangles)",
            t.elapsed(),
            m.triangles.len()
        );
        if reuse {
            buffers.recycle(m);
        }
    }
}
