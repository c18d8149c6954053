//! The planar-region projection's tolerance and curvature test on the swing-decoded CAD
//! fixtures of `sharpen_figures`: for each stream, `whet decode --sharpen`'s output without
//! the projection, then with `flatten_planar_regions` at the given tolerance (in angle
//! steps) and curvature ratio, both measured with Metro against the original.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example planar_sweep -- [factor 2] [curvature ratio 0.1]
//! ```

mod support;
mod swing_inputs;

use whet_metro::{metro, MetroOptions};
use whet_sharpen::{flatten_planar_regions, PlanarOptions};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, default: f64| {
        args.get(i).map_or(default, |a| {
            a.parse().unwrap_or_else(|e| panic!("{a}: {e}"))
        })
    };
    let (factor, ratio) = (arg(1, 2.0), arg(2, 0.1));
    let metro_opts = MetroOptions::DEFAULT.with_samples(300_000);
    println!("| stream | input RMS % | decode --sharpen RMS % (gain) | with the projection (gain) | moved / vertices |");
    println!("|---|---|---|---|---|");
    for (name, rates) in swing_inputs::SWING_FIXTURES {
        for bpv in rates {
            for angles in [
                swing_inputs::Angles::Fixed(6),
                swing_inputs::Angles::AutoSharpened,
            ] {
                let s = swing_inputs::swing_input(name, bpv, angles);
                let base = s.decode_sharpen_unprojected();
                let mut flat = base.clone();
                let opts =
                    PlanarOptions::for_swing(s.angle_bits, factor).with_curvature_ratio(ratio);
                let report = flatten_planar_regions(&mut flat, &opts)
                    .unwrap_or_else(|e| panic!("{name}: {e}"));
                let e = |m| {
                    metro(&s.original, m, &metro_opts)
                        .unwrap_or_else(|e| panic!("{name}: {e}"))
                        .symmetric
                        .rms_pct
                };
                let (input, b, f) = (e(&s.decoded), e(&base), e(&flat));
                println!(
                    "| {name} {bpv} {} | {input:.4} | {b:.4} ({:.2}x) | {f:.4} ({:.2}x) | {} / {} |",
                    angles.tag(),
                    input / b,
                    input / f,
                    report.moved_vertices,
                    flat.positions.len()
                );
            }
        }
    }
}
