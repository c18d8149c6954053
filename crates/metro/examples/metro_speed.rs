//! Times one [`whet_metro::metro`] call on a pair of mesh files, the files read once: `cargo
//! run --release -p whet-metro --example metro_speed -- <reference> <test> [samples] [runs]`
//! (300 000 face samples per direction, the swing encoder's own count, and 10 runs by default).
//! Prints the fastest and the median run and the symmetric figures, which must not change
//! with a change meant only for speed. Pin it to one core (`taskset -c 1`) to measure the
//! single-core cost, as the encoder's many measurements on a two-core machine see it.
#![allow(clippy::unwrap_used)] // a measurement tool

use std::time::Instant;
use whet_metro::{metro, MetroOptions};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let (Some(reference), Some(test)) = (args.first(), args.get(1)) else {
        eprintln!("usage: metro_speed <reference> <test> [samples] [runs]");
        std::process::exit(2);
    };
    let read = |p: &str| whet_io::read_path(std::path::Path::new(p), None).unwrap();
    let (reference, test) = (read(reference), read(test));
    let samples: usize = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(300_000);
    let runs: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(10);
    let opts = MetroOptions::DEFAULT.with_samples(samples);
    let mut times = Vec::with_capacity(runs);
    let mut last = None;
    for _ in 0..runs.max(1) {
        let t = Instant::now();
        let r = metro(&reference, &test, &opts).unwrap();
        times.push(t.elapsed().as_secs_f64());
        last = Some(r);
    }
    times.sort_by(f64::total_cmp);
    let r = last.unwrap();
    println!(
        "{} samples: best {:.2} ms, median {:.2} ms; rms {:e}, max {:e}, mean {:e}",
        samples,
        times[0] * 1e3,
        times[times.len() / 2] * 1e3,
        r.symmetric.rms,
        r.symmetric.max,
        r.symmetric.mean
    );
}
