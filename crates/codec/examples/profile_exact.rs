//! Times the stages of the exact mode on a ~1.3M-triangle icosphere (a profiling aid:
//! `cargo run --release -p whet-codec --example profile_exact`).
#![allow(clippy::unwrap_used)]

use std::time::Instant;
use whet_codec::{decode, encode, DecodeOptions, EncodeOptions};

fn main() {
    let mesh = whet_testkit::meshes::shuffle(&whet_testkit::meshes::icosphere(8), 1);
    let t = Instant::now();
    let table = whet_mesh::CornerTable::new(&mesh).unwrap();
    eprintln!("corner table: {:?}", t.elapsed());
    let t = Instant::now();
    let s = whet_edgebreaker::traverse(&table, None, |_| {}).unwrap();
    eprintln!("traverse: {:?} ({} labels)", t.elapsed(), s.labels.len());
    let t = Instant::now();
    let c = whet_edgebreaker::encode_connectivity(&mesh.triangles, mesh.positions.len()).unwrap();
    eprintln!("encode_connectivity: {:?}", t.elapsed());
    let t = Instant::now();
    let (_d, _) = whet_edgebreaker::decode_connectivity(&c.bytes, &Default::default()).unwrap();
    eprintln!("decode_connectivity: {:?}", t.elapsed());
    let t = Instant::now();
    let e = encode(&mesh, &EncodeOptions::DEFAULT).unwrap();
    eprintln!("encode: {:?}", t.elapsed());
    for _ in 0..std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(1)
    {
        let t = Instant::now();
        let m = decode(&e.bytes, &DecodeOptions::DEFAULT).unwrap();
        eprintln!(
            "decode: {:?} ({} triangles)",
            t.elapsed(),
            m.triangles.len()
        );
    }
}
