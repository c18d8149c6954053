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
//! Streams are cached under `target/sharpen-swing/`: a rate search runs several retilings.
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
    /// The decoded mesh without its surface filter: what `whet decode --sharpen` sharpens.
    pub decoded: Mesh,
    /// Whole-stream bits per original vertex.
    pub bpv: f64,
    /// Angle bits the stream uses.
    pub angle_bits: u32,
    /// The sharpening the stream names for `whet decode --sharpen` (the encoder's choice).
    pub sharpen_hint: Option<whet_codec::SharpenHint>,
    /// Its smooth factor (2 when the stream names none).
    pub smooth_factor: f64,
    /// Its curved-wall factor (field 27; `None`: the method's own).
    pub curved_walls: Option<f64>,
    /// Its EdgeSharpener passes (field 29; 1 without it).
    pub passes: u32,
    /// The stream states the planar-region projection after sharpening (field 25).
    pub planar: bool,
    /// The stream states the local quadric projection after sharpening (field 31).
    pub quadric: bool,
    /// The stream states the one-sided quadric projection beside creases (field 37).
    pub beside: bool,
    /// The stream states the crease projection (field 35).
    pub crease: bool,
    /// The stream states the apex restoration (field 39).
    pub apex: bool,
    /// The stream states gray-vertex labels on surface samplings (field 41).
    pub gray_labels: bool,
    /// The stream carries a filter for after sharpening (fields 17 and 19).
    pub after_filter: bool,
    /// The stream.
    pub bytes: Vec<u8>,
}

/// How far along the projections after sharpening [`SwingInput::decode_sharpen_through`]
/// goes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Projections {
    None,
    Planar,
    Quadric,
    Beside,
    All,
}

impl SwingInput {
    /// What `whet decode --sharpen` writes for this stream: `whet_swing::StatedSharpening`,
    /// the code the CLI runs (the sharpening the stream states with its snap vetoes
    /// replayed, then its filter for after sharpening on the vertices the sharpener left
    /// alone, then the projections it states); for a stream stating no sharpening, the plain
    /// decoded mesh with its surface filter.
    pub fn decode_sharpen(&self) -> Mesh {
        match self.stated().apply(&self.decoded) {
            Ok(Some(out)) => {
                assert_eq!(out.mismatched_veto_passes, 0, "vetoes out of step");
                assert!(out.skipped.is_empty(), "{:?}", out.skipped);
                out.sharpened.mesh
            }
            Ok(None) => self.plain(),
            Err(e) => panic!("{e}"),
        }
    }

    /// [`Self::decode_sharpen`] with the stream's projections up to and including `last`
    /// (the sweeps of one projection measure it on what the ones before it left).
    pub fn decode_sharpen_through(&self, last: Projections) -> Mesh {
        let stated = self.stated();
        if stated.is_unsharpened() {
            return self.plain();
        }
        let mut m = self.decode_sharpen_unprojected();
        let rank = |p: &whet_swing::StatedProjection| match p {
            whet_swing::StatedProjection::Planar { .. } => Projections::Planar,
            whet_swing::StatedProjection::Quadric { .. } => Projections::Quadric,
            whet_swing::StatedProjection::Beside { .. } => Projections::Beside,
            whet_swing::StatedProjection::Crease { .. }
            | whet_swing::StatedProjection::Apex { .. } => Projections::All,
        };
        for p in stated.projections.iter().filter(|p| rank(p) <= last) {
            p.apply(&mut m).unwrap_or_else(|e| panic!("{e}"));
        }
        m
    }

    /// [`Self::decode_sharpen`] without the projections.
    pub fn decode_sharpen_unprojected(&self) -> Mesh {
        let stated = self.stated();
        if stated.is_unsharpened() {
            return self.plain();
        }
        let mut replay = stated.veto_replay();
        let opts = stated.options();
        let mut s = match replay.as_mut() {
            Some(r) => whet_sharpen::sharpen_judged(&self.decoded, &opts, r),
            None => whet_sharpen::sharpen(&self.decoded, &opts),
        }
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            replay.map_or(0, |r| r.mismatched_passes()),
            0,
            "vetoes out of step"
        );
        stated
            .after_filter
            .apply_after_sharpening(&self.decoded, &mut s.mesh);
        s.mesh
    }

    /// What the stream's header states about sharpening.
    fn stated(&self) -> whet_swing::StatedSharpening {
        let header = whet_format::parse(&self.bytes, &whet_format::Limits::UNLIMITED)
            .unwrap_or_else(|e| panic!("{e}"))
            .header;
        whet_swing::StatedSharpening::of(&header).unwrap_or_else(|e| panic!("{e}"))
    }

    /// The plain decoded mesh, its surface filter included (what `whet decode` writes).
    pub fn plain(&self) -> Mesh {
        whet_codec::decode(&self.bytes, &whet_codec::DecodeOptions::DEFAULT)
            .unwrap_or_else(|e| panic!("{e}"))
    }
}

/// Every input of the swing table, in its order: each fixture of [`SWING_FIXTURES`] at each
/// of its rates, with 6 angle bits and with automatic ones, as (fixture, rate, angles,
/// input).
pub fn every_swing_input() -> impl Iterator<Item = (&'static str, f64, Angles, SwingInput)> {
    SWING_FIXTURES.into_iter().flat_map(|(name, rates)| {
        rates.into_iter().flat_map(move |bpv| {
            [Angles::Fixed(6), Angles::AutoSharpened]
                .into_iter()
                .map(move |angles| (name, bpv, angles, swing_input(name, bpv, angles)))
        })
    })
}

/// The synth shapes of the swing-synth table (shapes no constant was tuned on), in its order.
pub const SYNTH_SHAPES: [whet_synth::ShapeKind; 10] = {
    use whet_synth::ShapeKind::*;
    [
        Box, Pyramid, Octahedron, Cylinder, Cone, Fandisk, ThinFace, TorusBox, Blend, Sphere,
    ]
};

/// Every input of the swing-synth table, in its order: each of [`SYNTH_SHAPES`] turned by
/// `rotation` (named `rotation_name` in the cache: the table's is the first of
/// `support::rotations`, "r0"), at edge lengths 1, 1.5 and 2 % with 6 angle bits, then at
/// those streams' sizes with automatic angle bits; as (shape, edge length, angles, input).
pub fn every_synth_swing_input(
    rotation: glam::DQuat,
    rotation_name: &'static str,
) -> impl Iterator<Item = (whet_synth::ShapeKind, f64, Angles, SwingInput)> {
    SYNTH_SHAPES.into_iter().flat_map(move |kind| {
        let shape = whet_synth::Shape::new(
            kind,
            &whet_synth::ShapeParams::default().with_rotation(rotation),
        )
        .unwrap_or_else(|e| panic!("{e}"));
        // Automatic angle bits need a size target: the 6-bit stream's size at each length.
        let mut sizes = Vec::new();
        let mut rows = Vec::new();
        for angles in [Angles::Fixed(6), Angles::AutoSharpened] {
            for (i, l) in [0.01, 0.015, 0.02].into_iter().enumerate() {
                let rate = match angles {
                    Angles::Fixed(_) => Rate::EdgeLength(l),
                    Angles::AutoSharpened => Rate::TargetBytes(sizes[i]),
                };
                let s = swing_input_of(
                    shape.truth_mesh_ref().clone(),
                    &format!("synth-{}-{rotation_name}-{l}", kind.name()),
                    rate,
                    angles,
                );
                sizes.push(s.bytes.len());
                rows.push((kind, l, angles, s));
            }
        }
        rows
    })
}

/// Encodes the shared fixture `name` at `bpv` bits per original vertex and decodes it.
pub fn swing_input(name: &str, bpv: f64, angles: Angles) -> SwingInput {
    let original = whet_io::read_path(&whet_testkit::shared_fixture(name), None)
        .unwrap_or_else(|e| panic!("{name}: {e}"));
    swing_input_of(
        original,
        &format!("{name}-{bpv}"),
        Rate::BitsPerVertex(bpv),
        angles,
    )
}

/// Encodes `original` at `rate` and decodes it; `key` names the stream in the cache
/// (`target/sharpen-swing/v47-<key>-<angles>.whet`).
pub fn swing_input_of(original: Mesh, key: &str, rate: Rate, angles: Angles) -> SwingInput {
    let dir = whet_testkit::workspace_root().join("target/sharpen-swing");
    let _ = std::fs::create_dir_all(&dir);
    let path = dir.join(format!("v49-{key}-{}.whet", angles.tag()));
    let bytes = match std::fs::read(&path) {
        Ok(b) => b,
        Err(_) => {
            let mut opts = SwingOptions::DEFAULT
                .with_rate(rate)
                .with_error_of(ErrorOf::Sharpened);
            opts = match angles {
                Angles::Fixed(b) => opts.with_angle_bits(b),
                Angles::AutoSharpened => opts.with_auto_angle_bits(true),
            };
            let out = whet_swing::encode(&original, &opts)
                .unwrap_or_else(|e| panic!("{key}: encode: {e}"));
            let _ = std::fs::write(&path, &out.bytes);
            out.bytes
        }
    };
    let decoded = whet_codec::decode(
        &bytes,
        &whet_codec::DecodeOptions::DEFAULT.with_surface_filter(false),
    )
    .unwrap_or_else(|e| panic!("{key}: decode: {e}"));
    let header = whet_format::parse(&bytes, &whet_format::Limits::UNLIMITED)
        .unwrap_or_else(|e| panic!("{key}: {e}"))
        .header;
    SwingInput {
        bpv: bytes.len() as f64 * 8.0 / original.positions.len() as f64,
        angle_bits: header
            .get_u64(whet_format::tag::ANGLE_BITS)
            .map_or(0, |b| b as u32),
        sharpen_hint: whet_codec::SharpenHint::stated(&header).map(|s| s.0),
        smooth_factor: whet_codec::SharpenHint::stated(&header).map_or(2.0, |s| s.1),
        curved_walls: whet_codec::SharpenHint::curved_walls_of(&header),
        passes: whet_codec::SharpenHint::passes_of(&header).unwrap_or(1),
        after_filter: !whet_codec::SurfaceFilter::after_sharpening_of(&header).is_none(),
        planar: whet_codec::SharpenHint::planar_of(&header).is_some(),
        quadric: whet_codec::SharpenHint::quadric_of(&header).is_some(),
        beside: whet_codec::SharpenHint::beside_of(&header).is_some(),
        crease: whet_codec::SharpenHint::crease_of(&header).is_some(),
        apex: whet_codec::SharpenHint::apex_of(&header).is_some(),
        gray_labels: whet_codec::SharpenHint::gray_labels_of(&header),
        original,
        decoded,
        bytes,
    }
}
