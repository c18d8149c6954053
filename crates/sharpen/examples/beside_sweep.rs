//! The one-sided quadric projection beside creases on the swing-decoded CAD fixtures of
//! `sharpen_figures`: for each stream that names a sharpening, `whet decode --sharpen`'s
//! output without the one-sided projection (the other projections as the stream states
//! them), then with `project_beside_creases_onto_local_quadrics` in its place (after the
//! planar and quadric projections, before the crease one) at the given move limit (angle
//! steps `2 pi / 2^angle_bits`, in mean edge lengths, as a stream states it) and reach (mean
//! edge lengths); both measured with Metro against the original (symmetric RMS and max,
//! 300 000 samples a direction).
//!
//! ```text
//! cargo run --release -p whet-sharpen --example beside_sweep -- [factor 0.25] [rings 3] [normal angle 30] [crease angle 30] [fixture ...]
//! ```
#![allow(clippy::unwrap_used)] // a measurement tool

mod support;
mod swing_inputs;

use whet_sharpen::{
    project_beside_creases_onto_local_quadrics, project_creases_onto_local_quadrics, BesideOptions,
    CreaseOptions,
};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, default: f64| {
        args.get(i).map_or(default, |a| {
            a.parse().unwrap_or_else(|e| panic!("{a}: {e}"))
        })
    };
    let (factor, rings) = (arg(1, 0.25), arg(2, 3.0) as usize);
    let (normal_angle, crease_angle) = (arg(3, 30.0), arg(4, 30.0));
    let only: Vec<&String> = args.iter().skip(5).collect();
    println!("| stream | input RMS % | without: RMS %, max % (RMS gain) | with the projection | moved / beside |");
    println!("|---|---|---|---|---|");
    let (mut log_gain, mut rows, mut max_worse) = (0.0, 0, 0);
    for (name, bpv, angles, s) in swing_inputs::every_swing_input() {
        if s.sharpen_hint == Some(whet_codec::SharpenHint::Unsharpened)
            || !(only.is_empty() || only.iter().any(|o| name.starts_with(o.as_str())))
        {
            continue;
        }
        let mut base = s.decode_sharpen_through(swing_inputs::Projections::Quadric);
        let mut fitted = base.clone();
        let opts = BesideOptions::for_swing(s.angle_bits, factor)
            .with_rings(rings)
            .with_max_normal_angle_degrees(normal_angle)
            .with_crease_angle_degrees(crease_angle);
        let report = project_beside_creases_onto_local_quadrics(&mut fitted, &opts)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        if s.crease {
            // The crease projection as the encoder states it (`whet_swing::CREASE_MOVE`).
            let crease = CreaseOptions::DEFAULT.with_max_move(whet_swing::CREASE_MOVE);
            for m in [&mut base, &mut fitted] {
                project_creases_onto_local_quadrics(m, &crease).unwrap();
            }
        }
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
            report.moved_vertices,
            report.beside_vertices
        );
    }
    println!(
        "\nRMS gain of the projection, geometric mean over {rows} rows: {:.2} %; max raised on {max_worse}",
        100.0 * ((log_gain / rows.max(1) as f64).exp() - 1.0)
    );
}
