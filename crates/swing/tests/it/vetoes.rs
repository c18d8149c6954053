//! Snap vetoes (header field 33): the encoder judges `whet decode --sharpen`'s snaps against
//! the original, and a decoder replaying the stream's flags rebuilds the very mesh it judged.

use std::sync::OnceLock;

use whet_codec::{decode, DecodeOptions, SnapVetoes};
use whet_sharpen::{SharpenOptions, VetoReplay};
use whet_swing::{encode, Rate, SwingOptions};
use whet_synth::{Shape, ShapeKind, ShapeParams};

/// A box whose edges are fillets of radius 0.03, about one retiled edge at L = 0.03 of the
/// diagonal: the default sharpening snaps them into creases and corners.
fn rounded_box() -> whet_mesh::Mesh {
    Shape::new(ShapeKind::Blend, &ShapeParams::default().with_radius(0.03))
        .unwrap()
        .truth_mesh()
}

#[test]
fn the_decoder_replays_exactly_what_the_encoder_judged() {
    let original = rounded_box();
    let out = encode(
        &original,
        &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(0.03)),
    )
    .unwrap();
    let judged = out.snap_vetoes.clone().unwrap();
    // Measured 2026-12-04: 179 of 372 snaps vetoed (fewer than half, so the stream states
    // the vetoes rather than "no sharpening"); the rule is deterministic, the bounds leave
    // room for retiler changes.
    assert!(
        judged.vetoed() > 20 && 2 * judged.vetoed() <= judged.judged(),
        "{judged:?}"
    );
    assert_eq!(out.sharpen_hint, None);
    let header = whet_format::parse(&out.bytes, &whet_format::Limits::DEFAULT)
        .unwrap()
        .header;
    let stated = SnapVetoes::of(&header).unwrap().unwrap();
    assert_eq!(stated, judged);
    // The mesh the decoder sharpens, sharpened with the stream's flags, is the mesh the
    // encoder's judge made, bit for bit; without them it differs.
    let input = decode(
        &out.bytes,
        &DecodeOptions::DEFAULT.with_surface_filter(false),
    )
    .unwrap();
    let opts = SharpenOptions::DEFAULT;
    let bvh = OnceLock::new();
    let (encoder_side, again) =
        whet_swing::snap_judge::sharpen_judged(&original, &bvh, &input, &opts);
    assert_eq!(again, judged);
    let mut replay = VetoReplay::new(stated.passes().to_vec());
    let decoder_side = whet_sharpen::sharpen_judged(&input, &opts, &mut replay).unwrap();
    assert_eq!(replay.mismatched_passes(), 0);
    assert_eq!(replay.applied(), judged.vetoed());
    let encoder_side = encoder_side.unwrap();
    assert_eq!(
        crate::bits(&decoder_side.mesh),
        crate::bits(&encoder_side.mesh)
    );
    assert_eq!(decoder_side.mesh.triangles, encoder_side.mesh.triangles);
    let plain = whet_sharpen::sharpen(&input, &opts).unwrap();
    assert_ne!(plain.mesh, decoder_side.mesh);
    // `StatedSharpening::apply`, which `whet decode --sharpen`, `whet rd` and the figures
    // run, replays the flags too: the judged mesh, then the stream's filter and projections.
    let stated = whet_swing::StatedSharpening::of(&header).unwrap();
    assert!(stated.vetoes.is_some());
    let applied = stated
        .apply(&input)
        .unwrap()
        .expect("the stream states a sharpening");
    assert_eq!(applied.mismatched_veto_passes, 0);
    assert!(applied.skipped.is_empty());
    let mut expected = encoder_side.mesh.clone();
    assert!(stated.finish(&input, &mut expected).is_empty());
    assert_eq!(crate::bits(&applied.sharpened.mesh), crate::bits(&expected));
    assert_eq!(applied.sharpened.mesh.triangles, expected.triangles);
}

#[test]
fn a_part_whose_snaps_are_mostly_worse_states_no_sharpening() {
    // At L = 0.02 the fillets are a retiled edge and a half: nearly every snap is worse,
    // and two bytes of "no sharpening" replace the flags.
    let out = encode(
        &rounded_box(),
        &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(0.02)),
    )
    .unwrap();
    let judged = out.snap_vetoes.clone().unwrap();
    assert!(2 * judged.vetoed() > judged.judged(), "{judged:?}");
    assert_eq!(out.sharpen_hint, Some(whet_codec::SharpenHint::Unsharpened));
    let header = whet_format::parse(&out.bytes, &whet_format::Limits::DEFAULT)
        .unwrap()
        .header;
    assert!(SnapVetoes::of(&header).is_none());
}

#[test]
fn a_smooth_part_pays_nothing() {
    // A sphere has no chamfer: no judgement is asked, no field is written.
    let sphere = Shape::new(ShapeKind::Sphere, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    let out = encode(
        &sphere,
        &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(0.05)),
    )
    .unwrap();
    assert_eq!(out.snap_vetoes.as_ref().map(|v| v.vetoed()), Some(0));
    let header = whet_format::parse(&out.bytes, &whet_format::Limits::DEFAULT)
        .unwrap()
        .header;
    assert!(header.get(whet_format::tag::SNAP_VETOES).is_none());
    assert!(header.get(whet_format::tag::SHARPEN_METHOD).is_none());
}
