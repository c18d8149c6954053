//! The crease projection's move limit, reach and crease angle on the swing-decoded CAD
//! fixtures of `sharpen_figures`: for each stream that names a sharpening, `whet decode
//! --sharpen`'s output without the crease projection (the planar, quadric and one-sided
//! ones as the stream states them), then with `project_creases_onto_local_quadrics` at the
//! given move limit (mean edge lengths), reach (mean edge lengths) and crease angle, both
//! measured with Metro against the original (symmetric RMS and max, 300 000 samples a
//! direction). With `corners` after the three numbers, the baseline is the projection
//! without its corner moves instead, and the last column counts corners; with `strips`, the
//! baseline is the projection that does not leave strips of chamfer out of corners, and the
//! last column counts the corners moved and the strips left out; with `meeting`, the
//! baseline is the projection that leaves a corner whose arcs meet, and the last column
//! counts the corners moved and the sides merged from meeting arcs. A further `synth` runs
//! on the swing-synth table's streams (shapes no constant was tuned on) instead.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example crease_sweep -- [max move 0.5] [rings 3] [degrees 30] [corners|strips|meeting|-] [synth]
//! ```

mod support;
mod swing_inputs;

use whet_sharpen::{project_creases_onto_local_quadrics, CreaseOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, default: f64| {
        args.get(i).map_or(default, |a| {
            a.parse().unwrap_or_else(|e| panic!("{a}: {e}"))
        })
    };
    let opts = CreaseOptions::DEFAULT
        .with_max_move(arg(1, 0.5))
        .with_rings(arg(2, 3.0) as usize)
        .with_crease_angle_degrees(arg(3, 30.0));
    // The baseline: no crease projection, or with `corners`, `strips` or `meeting` the
    // projection without that step.
    let mode = args.get(4).map_or("", String::as_str);
    let baseline = match mode {
        "corners" => Some(opts.with_corners(false)),
        "strips" => Some(opts.with_strips(false)),
        "meeting" => Some(opts.with_meeting_arcs(false)),
        _ => None,
    };
    println!("| stream | input RMS % | without: RMS %, max % (RMS gain) | with the projection | moved / crease vertices |");
    println!("|---|---|---|---|---|");
    let (mut log_gain, mut rows, mut max_worse) = (0.0, 0, 0);
    // `synth` after the mode: the swing-synth table's streams instead of the fixtures'.
    let synth = args.get(5).is_some_and(|a| a == "synth");
    let inputs: Box<dyn Iterator<Item = (String, f64, swing_inputs::Angles, _)>> = if synth {
        Box::new(
            swing_inputs::every_synth_swing_input(support::rotations()[0], "r0")
                .map(|(kind, l, angles, s)| (kind.name().to_string(), l, angles, s)),
        )
    } else {
        Box::new(
            swing_inputs::every_swing_input()
                .map(|(name, bpv, angles, s)| (name.to_string(), bpv, angles, s)),
        )
    };
    for (name, bpv, angles, s) in inputs {
        if s.sharpen_hint == Some(whet_codec::SharpenHint::Unsharpened) {
            continue;
        }
        let before = s.decode_sharpen_through(swing_inputs::Projections::Beside);
        let mut fitted = before.clone();
        let mut base = before;
        if let Some(b) = baseline {
            project_creases_onto_local_quadrics(&mut base, &b)
                .unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let report = project_creases_onto_local_quadrics(&mut fitted, &opts)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        let e = |m| support::error(&s.original, m, Some(300_000));
        let (input, b, f) = (e(&s.decoded).rms_pct, e(&base), e(&fitted));
        log_gain += (b.rms_pct / f.rms_pct).ln();
        rows += 1;
        max_worse += usize::from(f.max_pct > b.max_pct);
        println!(
            "| {name} {bpv} {} | {input:.4} | {:.4}, {:.3} ({:.2}x) | {:.4}, {:.3} ({:.2}x) | {} / {} |",
            angles.tag(),
            b.rms_pct,
            b.max_pct,
            input / b.rms_pct,
            f.rms_pct,
            f.max_pct,
            input / f.rms_pct,
            match mode {
                "corners" | "strips" | "meeting" => report.moved_corners,
                _ => report.moved_vertices,
            },
            match mode {
                "strips" => report.strips_left_out,
                "meeting" => report.merged_sides,
                "corners" => report.corner_vertices,
                _ => report.crease_vertices,
            }
        );
    }
    println!(
        "\nRMS gain of the projection, geometric mean over {rows} rows: {:.2} %; max raised on {max_worse}",
        100.0 * ((log_gain / rows.max(1) as f64).exp() - 1.0)
    );
}
