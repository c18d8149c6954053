//! Speed of the swing codec on a large original (issue target: retile and encode a
//! 1M-triangle original into about 100k retiled triangles in under 3 s on one core; decode at
//! 10 M retiled triangles/s or more).
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_speed [-- mesh.off [fraction]]
//! ```
//! Without arguments: armadillo split 1-to-4 twice (1.38 M triangles), L chosen for about
//! 100 k retiled triangles (`WHET_NO_SURFACE_FILTER=1`: without the surface filter). With
//! `SWING_SPEED_STREAM=<path>` the stream is also written there,
//! for `cargo run --release -p whet-codec --example decode_file -- <path>`.
#![allow(clippy::unwrap_used)] // a measurement tool

use std::time::Instant;
use whet_codec::{decode, DecodeOptions};
use whet_swing::{encode, Rate, SwingOptions};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (mesh, fraction) = match args.first() {
        Some(p) => (
            whet_io::read_path(std::path::Path::new(p), None).unwrap(),
            args.get(1).map_or(0.004, |f| f.parse().unwrap()),
        ),
        None => {
            let a =
                whet_io::read_path(&whet_testkit::shared_fixture("armadillo.off"), None).unwrap();
            (whet_synth::midpoint_subdivide(&a, 2), 0.0037)
        }
    };
    eprintln!(
        "original: {} vertices, {} triangles",
        mesh.positions.len(),
        mesh.triangles.len()
    );
    let opts = SwingOptions::DEFAULT
        .with_rate(Rate::EdgeLength(fraction))
        .with_surface_filter(std::env::var_os("WHET_NO_SURFACE_FILTER").is_none());
    let mut best_enc = f64::MAX;
    let mut out = None;
    for _ in 0..3 {
        let t = Instant::now();
        let o = encode(&mesh, &opts).unwrap();
        best_enc = best_enc.min(t.elapsed().as_secs_f64());
        out = Some(o);
    }
    let out = out.unwrap();
    if let Ok(path) = std::env::var("SWING_SPEED_STREAM") {
        // Keep the stream for `whet-codec`'s decode_file example (a decode-only profile).
        std::fs::write(path, &out.bytes).unwrap();
    }
    let tris = out.report.triangles;
    let mut best_dec = f64::MAX;
    for _ in 0..10 {
        let t = Instant::now();
        let m = decode(&out.bytes, &DecodeOptions::DEFAULT).unwrap();
        best_dec = best_dec.min(t.elapsed().as_secs_f64());
        assert_eq!(m.triangles.len(), tris);
    }
    println!(
        "| {} | {} | {:.4} | {} | {} | {:.3} | {:.3} | {:.1} |",
        mesh.triangles.len(),
        mesh.positions.len(),
        fraction,
        tris,
        out.bytes.len(),
        best_enc,
        best_dec * 1e3,
        tris as f64 / best_dec / 1e6
    );
    println!("(original triangles | vertices | L/diag | retiled triangles | bytes | encode s | decode ms | decode M tri/s)");
}
