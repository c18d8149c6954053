//! Swing-decoded inputs of the EdgeSharpener figures: a shared fixture encoded by whet-swing
//! (the SwingWrapper retiler) at a rate in bits per original vertex, with fixed or automatic
//! angle bits, optimised for the sharpened output (so the stream also names the sharpening
//! its encoder measured best), and decoded by whet-codec without its surface filter, exactly
//! what `whet encode --bpv R --angle-bits B|auto --optimize-for sharpened` then `whet decode
//! --no-surface-filter` produce (the mesh `whet decode --sharpen` sharpens).
//!
//! whet-swing depends on whet-sharpen (its automatic angle-bit choice measures the sharpened
//! output), so it is a dev-dependency of whet-sharpen: a cycle cargo allows, and which keeps
//! the figures a library call (no dependence on a CLI binary being built and current).
//! Encodings are cached under `target/sharpen-swing/`: a rate search runs several retilings.
//! With automatic angle bits optimised for the sharpened output, the encoder measures with the
//! sharpener it was linked with, so the choice can change with the sharpener: delete the cache
//! to re-run it.
#![allow(dead_code)]

use whet_mesh::Mesh;
use whet_swing::{ErrorOf, Rate, SwingOptions};

/// The CAD fixtures of the swing table of `sharpen_figures` and the CAD rows of
/// `swing_sweep` (rocker_arm, the last entry: mostly smooth blends, a case that must not
/// get worse) and their rates in bits per original vertex: about 0.5x, 1x and 2x the
/// fixture's vertex count at 6 angle bits (re-chosen 2026-12-02 for the current encoder by a
/// log-log fit of the vertex ratio against the rate from a run at the previous rates: a
/// retiled vertex now costs 1.6-3.3 bits at 1x, a little more at 0.5x and less at 2x).
pub const SWING_FIXTURES: [(&str, [f64; 3]); 8] = [
    ("fandisk.off", [1.6, 2.6, 4.4]),
    ("cad_box_hole.off", [1.1, 1.9, 3.1]),
    ("cad_bracket.off", [1.2, 2.0, 3.5]),
    ("cad_cyl_fillet.off", [0.9, 1.6, 2.8]),
    ("block.off", [1.7, 2.8, 4.6]),
    ("partLp.off", [2.0, 3.3, 5.2]),
    ("joint.off", [1.0, 1.8, 3.3]),
    ("rocker_arm.off", [1.6, 2.8, 4.8]),
];

/// The angle quantization of a swing input.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Angles {
    /// Fixed angle bits (`--angle-bits B`).
    Fixed(u32),
    /// `--angle-bits auto --optimize-for sharpened`.
    AutoSharpened,
}

impl Angles {
    pub fn tag(self) -> String {
        match self {
            Angles::Fixed(b) => b.to_string(),
            Angles::AutoSharpened => "auto".to_string(),
        }
    }
}

/// One swing-decoded input and how it was made.
pub struct SwingInput {
    /// The fixture.
    pub original: Mesh,
    /// The decoded mesh.
    pub decoded: Mesh,
    /// Whole-stream bits per original vertex.
    pub bpv: f64,
    /// Angle bits the stream uses.
    pub angle_bits: u32,
    /// The sharpening the stream names for `whet decode --sharpen` (the encoder's choice).
    pub sharpen_hint: Option<whet_codec::SharpenHint>,
}

/// Encodes the shared fixture `name` at `bpv` bits per original vertex and decodes it.
pub fn swing_input(name: &str, bpv: f64, angles: Angles) -> SwingInput {
    let original = whet_io::read_path(&whet_testkit::shared_fixture(name), None)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    let dir = whet_testkit::workspace_root().join("target/sharpen-swing");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("v2-{name}-{bpv}-{}.off", angles.tag()));
    let meta = path.with_extension("meta");
    if let (Ok(decoded), Ok(m)) = (
        whet_io::read_path(&path, None),
        std::fs::read_to_string(&meta),
    ) {
        let mut w = m.split_whitespace();
        let got_bpv = w.next().and_then(|s| s.parse().ok());
        let bits = w.next().and_then(|s| s.parse().ok());
        let hint = w.next().and_then(|s| s.parse().ok());
        if let (Some(bpv), Some(angle_bits), Some(hint)) = (got_bpv, bits, hint) {
            return SwingInput {
                original,
                decoded,
                bpv,
                angle_bits,
                sharpen_hint: whet_codec::SharpenHint::from_code(hint),
            };
        }
    }
    let mut opts = SwingOptions::DEFAULT
        .with_rate(Rate::BitsPerVertex(bpv))
        .with_error_of(ErrorOf::Sharpened);
    opts = match angles {
        Angles::Fixed(b) => opts.with_angle_bits(b),
        Angles::AutoSharpened => opts.with_auto_angle_bits(true),
    };
    let out = whet_swing::encode(&original, &opts)
        .unwrap_or_else(|e| panic!("{name} at {bpv} bpv: encode: {e}"));
    let decoded = whet_codec::decode(
        &out.bytes,
        &whet_codec::DecodeOptions::DEFAULT.with_surface_filter(false),
    )
    .unwrap_or_else(|e| panic!("{name} at {bpv} bpv: decode: {e}"));
    let got = out.bits_per_original_vertex();
    let _ = whet_io::write_path(&path, &decoded, None, &whet_io::WriteOptions::DEFAULT);
    // The hint's code, or one no hint has.
    let hint = out.sharpen_hint.map_or(u64::MAX, |h| h.code());
    let _ = std::fs::write(&meta, format!("{got} {} {hint}\n", out.angle_bits));
    SwingInput {
        original,
        decoded,
        bpv: got,
        angle_bits: out.angle_bits,
        sharpen_hint: out.sharpen_hint,
    }
}
