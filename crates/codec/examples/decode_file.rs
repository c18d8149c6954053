//! Decodes a `.whet` file repeatedly and prints the fastest and the median decode (a
//! profiling aid for any mode: `cargo run --release -p whet-codec --example decode_file --
//! <file.whet> [decodes]`, under `perf record` for a profile of decoding alone).
//! `WHET_NO_SURFACE_FILTER=1` decodes swing streams without their surface filter.
#![allow(clippy::unwrap_used)] // a measurement tool

use std::time::Instant;
use whet_codec::{decode, DecodeOptions};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let path = args
        .first()
        .expect("usage: decode_file <file.whet> [decodes]");
    let n: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(20);
    let bytes = std::fs::read(path).unwrap();
    let opts = DecodeOptions::DEFAULT
        .with_surface_filter(std::env::var_os("WHET_NO_SURFACE_FILTER").is_none());
    let mut times = Vec::with_capacity(n);
    let mut triangles = 0;
    for _ in 0..n.max(1) {
        let t = Instant::now();
        let m = decode(&bytes, &opts).unwrap();
        times.push(t.elapsed().as_secs_f64());
        triangles = m.triangles.len();
    }
    times.sort_by(f64::total_cmp);
    let (best, median) = (times[0], times[times.len() / 2]);
    println!(
        "{triangles} triangles: best {:.3} ms ({:.1} M triangles/s), median {:.3} ms ({:.1} M/s)",
        best * 1e3,
        triangles as f64 / best / 1e6,
        median * 1e3,
        triangles as f64 / median / 1e6
    );
}
