//! The local quadric projection's move limit, rings and normal angle on the swing-decoded
//! CAD fixtures of `sharpen_figures`: for each stream that names a sharpening, `whet decode
//! --sharpen`'s output without the quadric projection (the planar one as the stream states
//! it), then with `project_onto_local_quadrics` at the given move limit (in angle steps),
//! rings and angle, both measured with Metro against the original (symmetric RMS and max).
//!
//! ```text
//! cargo run --release -p whet-sharpen --example quadric_sweep -- [factor 0.25] [rings 3] [degrees 30]
//! ```

mod support;
mod swing_inputs;

use whet_metro::{metro, MetroOptions};
use whet_sharpen::{project_onto_local_quadrics, QuadricOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, default: f64| {
        args.get(i).map_or(default, |a| {
            a.parse().unwrap_or_else(|e| panic!("{a}: {e}"))
        })
    };
    let (factor, rings, degrees) = (arg(1, 0.25), arg(2, 3.0) as usize, arg(3, 30.0));
    let metro_opts = MetroOptions::DEFAULT.with_samples(300_000);
    println!("| stream | input RMS % | without: RMS %, max % (RMS gain) | with the projection | moved / vertices |");
    println!("|---|---|---|---|---|");
    let (mut log_gain, mut rows) = (0.0, 0);
    for (name, rates) in swing_inputs::SWING_FIXTURES {
        for bpv in rates {
            for angles in [
                swing_inputs::Angles::Fixed(6),
                swing_inputs::Angles::AutoSharpened,
            ] {
                let s = swing_inputs::swing_input(name, bpv, angles);
                if s.sharpen_hint == Some(whet_codec::SharpenHint::Unsharpened) {
                    continue;
                }
                let base = s.decode_sharpen_through(swing_inputs::Projections::Planar);
                let mut fitted = base.clone();
                let opts = QuadricOptions::for_swing(s.angle_bits, factor)
                    .with_rings(rings)
                    .with_max_normal_angle_degrees(degrees);
                let report = project_onto_local_quadrics(&mut fitted, &opts)
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                let e = |m| {
                    let r = metro(&s.original, m, &metro_opts)
                        .unwrap_or_else(|e| panic!("{name}: {e}"))
                        .symmetric;
                    (r.rms_pct, r.max_pct)
                };
                let (input, b, f) = (e(&s.decoded).0, e(&base), e(&fitted));
                log_gain += (b.0 / f.0).ln();
                rows += 1;
                println!(
                    "| {name} {bpv} {} | {input:.4} | {:.4}, {:.3} ({:.2}x) | {:.4}, {:.3} ({:.2}x) | {} / {} |",
                    angles.tag(),
                    b.0,
                    b.1,
                    input / b.0,
                    f.0,
                    f.1,
                    input / f.0,
                    report.moved_vertices,
                    fitted.positions.len()
                );
            }
        }
    }
    println!(
        "\nRMS gain of the projection, geometric mean over {rows} rows: {:.2} %",
        100.0 * ((log_gain / rows.max(1) as f64).exp() - 1.0)
    );
}
