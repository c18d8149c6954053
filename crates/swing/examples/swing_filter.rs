//! The surface filter's effect: each mesh encoded with the filter off and on at one rate,
//! the decoded and the sharpened outputs measured against the original.
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_filter -- [--bpv R | --bytes N]
//!     [--angle-bits B] [--samples S] mesh.off...
//! ```
//! Mesh names without a slash are looked up in the shared fixtures.
#![allow(clippy::unwrap_used)] // a measurement tool: a failure is a crash with a message

use whet_codec::{decode, DecodeOptions};
use whet_metro::{metro, MetroOptions};
use whet_swing::{encode, Rate, SwingOptions};

fn main() {
    let mut args = std::env::args().skip(1);
    let mut rate = Rate::BitsPerVertex(0.8);
    let mut bits = SwingOptions::DEFAULT_ANGLE_BITS;
    let mut samples = 1_000_000usize;
    let mut meshes = Vec::new();
    while let Some(a) = args.next() {
        match a.as_str() {
            "--bpv" => rate = Rate::BitsPerVertex(args.next().unwrap().parse().unwrap()),
            "--bytes" => rate = Rate::TargetBytes(args.next().unwrap().parse().unwrap()),
            "--angle-bits" => bits = args.next().unwrap().parse().unwrap(),
            "--samples" => samples = args.next().unwrap().parse().unwrap(),
            m => meshes.push(m.to_string()),
        }
    }
    println!(
        "| mesh | filter | factors | bytes | decoded RMS % | max % | sharpened RMS % | max % |"
    );
    println!("|---|---|---|---|---|---|---|---|");
    for name in meshes {
        let path = if name.contains('/') {
            std::path::PathBuf::from(&name)
        } else {
            whet_testkit::shared_fixture(&name)
        };
        let mesh = whet_io::read_path(&path, None).unwrap();
        for on in [false, true] {
            let opts = SwingOptions::DEFAULT
                .with_rate(rate)
                .with_angle_bits(bits)
                .with_surface_filter(on);
            let out = encode(&mesh, &opts).unwrap();
            let back = decode(&out.bytes, &DecodeOptions::DEFAULT).unwrap();
            assert_eq!(
                back, out.retiled,
                "{name}: decode differs from the encoder's M'"
            );
            let m = MetroOptions::DEFAULT.with_samples(samples);
            let d = metro(&mesh, &back, &m).unwrap().symmetric;
            let sharp = whet_sharpen::sharpen(&back, &whet_sharpen::SharpenOptions::DEFAULT)
                .unwrap()
                .mesh;
            let s = metro(&mesh, &sharp, &m).unwrap().symmetric;
            let (a, b) = out.surface_filter.factors();
            println!(
                "| {} | {} | {a:.3}, {b:.3} | {} | {:.4} | {:.3} | {:.4} | {:.3} |",
                name.trim_end_matches(".off"),
                if on { "on" } else { "off" },
                out.bytes.len(),
                d.rms_pct,
                d.max_pct,
                s.rms_pct,
                s.max_pct
            );
        }
    }
}
