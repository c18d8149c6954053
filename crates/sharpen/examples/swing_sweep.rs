//! The extended method on swing-decoded fixtures, smooth and CAD, with the issue's checks:
//! no row worse (RMS or max), and on the CAD rows the RMS and max ratios.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example swing_sweep -- [smooth|cad|all] [6|auto|both]
//! ```
//!
//! Smooth fixtures (spot, fertility, armadillo, bunny, rocker_arm) at 2, 4, 6 and 8 bits per
//! original vertex, the rates of `whet rd --rates 2,4,6,8`; CAD fixtures at the rates of
//! `sharpen_figures -- swing` (about 0.5x, 1x and 2x the vertex count). Inputs come from
//! `swing_inputs` (cached under `target/sharpen-swing/`; with `auto` the encoder's choice
//! depends on the sharpener it was linked with: delete the cache to re-run it). Errors are
//! symmetric Metro RMS / max in 1e-4 of the original's diagonal; `SHARPEN_FIGURES_SAMPLES`
//! sets the face samples per direction (default: whet-metro's).

mod support;
mod swing_inputs;

use std::sync::Mutex;

use whet_sharpen::{sharpen, SharpenOptions};

use support::error;
use swing_inputs::{swing_input, Angles};

const SMOOTH: [(&str, [f64; 4]); 5] = [
    ("spot.off", [2.0, 4.0, 6.0, 8.0]),
    ("fertility.off", [2.0, 4.0, 6.0, 8.0]),
    ("armadillo.off", [2.0, 4.0, 6.0, 8.0]),
    ("bunny.off", [2.0, 4.0, 6.0, 8.0]),
    ("rocker_arm.off", [2.0, 4.0, 6.0, 8.0]),
];

fn samples() -> Option<usize> {
    std::env::var("SHARPEN_FIGURES_SAMPLES")
        .ok()
        .and_then(|s| s.parse().ok())
}

struct Row {
    order: usize,
    cad: bool,
    fandisk: bool,
    line: String,
    worse: bool,
    rms_gain: f64,
    max_gain: f64,
}

fn main() {
    let set = std::env::args().nth(1).unwrap_or_else(|| "all".into());
    let bits = std::env::args().nth(2).unwrap_or_else(|| "6".into());
    let angles: Vec<Angles> = match bits.as_str() {
        "auto" => vec![Angles::AutoSharpened],
        "both" => vec![Angles::Fixed(6), Angles::AutoSharpened],
        b => vec![Angles::Fixed(b.parse().expect("angle bits"))],
    };
    let mut jobs: Vec<(String, f64, Angles, bool)> = Vec::new();
    for &a in &angles {
        if set == "smooth" || set == "all" {
            for (name, rates) in SMOOTH {
                for r in rates {
                    jobs.push((name.to_string(), r, a, false));
                }
            }
        }
        if set == "cad" || set == "all" {
            // The CAD rows of the swing table (rocker_arm, without a crease, is a smooth row).
            for &(name, rates) in swing_inputs::SWING_FIXTURES
                .iter()
                .filter(|(name, _)| *name != "rocker_arm.off")
            {
                for r in rates {
                    jobs.push((name.to_string(), r, a, true));
                }
            }
        }
    }
    let next = Mutex::new(0usize);
    let rows = Mutex::new(Vec::<Row>::new());
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get().min(4));
    std::thread::scope(|sc| {
        for _ in 0..threads {
            sc.spawn(|| loop {
                let i = {
                    let mut n = next.lock().expect("lock");
                    let i = *n;
                    *n += 1;
                    i
                };
                let Some((name, rate, a, cad)) = jobs.get(i) else {
                    break;
                };
                let s = swing_input(name, *rate, *a);
                let out = sharpen(&s.decoded, &SharpenOptions::DEFAULT)
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                let e0 = error(&s.original, &s.decoded, samples());
                let e1 = error(&s.original, &out.mesh, samples());
                let worse = e1.rms_pct > e0.rms_pct * 1.0001 || e1.max_pct > e0.max_pct * 1.0001;
                let r = &out.report;
                let line = format!(
                    "| {name} | {rate} | {:.2} | {} | {} | {:.3} | {:.3} | {:.1} | {:.1} | {:.2}x | {:.2}x | {} | {} |{}",
                    s.bpv,
                    s.angle_bits,
                    s.decoded.positions.len(),
                    e0.rms_pct * 100.0,
                    e1.rms_pct * 100.0,
                    e0.max_pct * 100.0,
                    e1.max_pct * 100.0,
                    e0.rms_pct / e1.rms_pct,
                    e0.max_pct / e1.max_pct,
                    out.mesh.positions.len() - s.decoded.positions.len(),
                    r.moved_input_vertices,
                    if worse { " WORSE" } else { "" }
                );
                rows.lock().expect("lock").push(Row {
                    order: i,
                    cad: *cad,
                    fandisk: name.starts_with("fandisk"),
                    line,
                    worse,
                    rms_gain: e0.rms_pct / e1.rms_pct,
                    max_gain: e0.max_pct / e1.max_pct,
                });
            });
        }
    });
    let mut rows = rows.into_inner().expect("lock");
    rows.sort_by_key(|r| r.order);
    println!("| mesh | rate | bpv | bits | V | RMS dec | RMS sharp | max dec | max sharp | RMS gain | max gain | new V | moved |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for r in &rows {
        println!("{}", r.line);
    }
    let worse = rows.iter().filter(|r| r.worse).count();
    let cad: Vec<&Row> = rows.iter().filter(|r| r.cad).collect();
    println!(
        "\nrows worse: {worse}/{}; CAD rows RMS >= 2.5x: {}/{}, max >= 1.25x: {}/{}, both: {}/{}; fandisk RMS >= 4x: {}/{}",
        rows.len(),
        cad.iter().filter(|r| r.rms_gain >= 2.5).count(),
        cad.len(),
        cad.iter().filter(|r| r.max_gain >= 1.25).count(),
        cad.len(),
        cad.iter()
            .filter(|r| r.rms_gain >= 2.5 && r.max_gain >= 1.25)
            .count(),
        cad.len(),
        cad.iter().filter(|r| r.fandisk && r.rms_gain >= 4.0).count(),
        cad.iter().filter(|r| r.fandisk).count(),
    );
}
