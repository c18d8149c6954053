//! Retiles fixtures and prints one row per run: sizes, label statistics, error, timings.
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_table -- [--bpv R | --fraction F | --bytes N]
//!     [--angle-bits B] [--samples S] [--valence-bias DEG] [--no-surface-filter] mesh.off...
//! ```
//! Mesh names without a slash are looked up in the shared fixtures.
#![allow(clippy::unwrap_used)] // a measurement tool: a failure is a crash with a message

use std::time::Instant;
use whet_codec::{decode, DecodeOptions};
use whet_metro::{metro, MetroOptions};
use whet_swing::{encode, Rate, SwingOptions};

fn main() {
    let mut args = std::env::args().skip(1);
    let mut rate = Rate::BitsPerVertex(0.8);
    let mut bits = SwingOptions::DEFAULT_ANGLE_BITS;
    let mut filter = true;
    let mut samples = 1_000_000usize;
    let mut meshes = Vec::new();
    let mut tuning = whet_swing::RetileTuning::DEFAULT;
    while let Some(a) = args.next() {
        match a.as_str() {
            "--bpv" => rate = Rate::BitsPerVertex(args.next().unwrap().parse().unwrap()),
            "--fraction" => rate = Rate::EdgeLength(args.next().unwrap().parse().unwrap()),
            "--bytes" => rate = Rate::TargetBytes(args.next().unwrap().parse().unwrap()),
            "--max-error" => rate = Rate::MaxError(args.next().unwrap().parse().unwrap()),
            "--angle-bits" => bits = args.next().unwrap().parse().unwrap(),
            "--samples" => samples = args.next().unwrap().parse().unwrap(),
            "--close" => {
                tuning = tuning
                    .with_close_angle(args.next().unwrap().parse::<f64>().unwrap().to_radians())
            }
            "--off-surface" => {
                tuning = tuning.with_off_surface(args.next().unwrap().parse().unwrap())
            }
            "--valence-bias" => {
                tuning = tuning
                    .with_valence_bias(args.next().unwrap().parse::<f64>().unwrap().to_radians())
            }
            "--snap" => tuning = tuning.with_snap(args.next().unwrap().parse().unwrap()),
            "--no-surface-filter" => filter = false,
            m => meshes.push(m.to_string()),
        }
    }
    println!(
        "| mesh | V | L/diag | T' | bytes | bpv(orig) | conn bpt' | geom bpv' | C+R | val6 | RMS % | max % | enc ms | dec ms | fallbacks | geometry |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for name in meshes {
        let path = if name.contains('/') {
            std::path::PathBuf::from(&name)
        } else {
            whet_testkit::shared_fixture(&name)
        };
        let mesh = whet_io::read_path(&path, None).unwrap();
        let opts = SwingOptions::DEFAULT
            .with_rate(rate)
            .with_angle_bits(bits)
            .with_metro_samples(samples.min(300_000))
            .with_surface_filter(filter)
            .with_tuning(tuning);
        let t0 = Instant::now();
        let out = match encode(&mesh, &opts) {
            Ok(o) => o,
            Err(e) => {
                println!("| {name} | error: {e} |");
                continue;
            }
        };
        let enc_ms = t0.elapsed().as_secs_f64() * 1e3;
        eprintln!("{name}: search (L/diag, bytes) {:?}", out.search);
        let t1 = Instant::now();
        let back = decode(&out.bytes, &DecodeOptions::DEFAULT).unwrap();
        let dec_ms = t1.elapsed().as_secs_f64() * 1e3;
        assert_eq!(
            back, out.retiled,
            "{name}: decode differs from the encoder's M'"
        );
        let r = metro(&mesh, &back, &MetroOptions::DEFAULT.with_samples(samples)).unwrap();
        let h = out.report.clers_histogram;
        let t = out.report.triangles as f64;
        let v = out.report.vertices as f64;
        println!(
            "| {} | {} | {:.5} | {} | {} | {:.3} | {:.3} | {:.2} | {:.3} | {:.3} | {:.4} | {:.3} | {:.0} | {:.1} | {}/{}/{} | {:?} |",
            name.trim_end_matches(".off"),
            mesh.positions.len(),
            out.edge_length_fraction,
            out.report.triangles,
            out.bytes.len(),
            out.bits_per_original_vertex(),
            out.report.connectivity_bits as f64 / t,
            out.report.geometry_bits as f64 / v,
            (h[0] + h[3]) as f64 / t,
            out.valence6_fraction(),
            r.symmetric.rms_pct,
            r.symmetric.max_pct,
            enc_ms,
            dec_ms,
            out.stats.fallbacks,
            out.stats.forced,
            out.stats.covered_hits,
            out.geometry,
        );
    }
}
