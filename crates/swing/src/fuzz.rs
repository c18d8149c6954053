//! The entry points of the `swing_encode` and `decode` cargo-fuzz targets (`fuzz/`), shared
//! with the stable replay tests of their corpora: the retiler and the swing encoder on
//! arbitrary small meshes (the mesh layout of `whet_sharpen::fuzz_input`: coincident
//! vertices, zero-area and folded triangles, exact coplanarity, several components), at an
//! edge length and angle bits the input picks; and `whet decode --sharpen` on arbitrary
//! bytes.

use crate::{encode, Error, ErrorOf, Rate, RetileTuning, StatedSharpening, SwingOptions};

/// Most triangles a decoded stream may have for [`fuzz_decode_sharpen`] to sharpen it (the
/// decoder's fuzzing runs to a million; sharpening that many per input would starve the
/// fuzzer).
const MAX_SHARPENED_TRIANGLES: u64 = 1 << 14;

/// `whet decode --sharpen` on arbitrary bytes: `whet_codec::fuzz_decode`, then, for a
/// stream that decodes to a small mesh, the sharpening its header states
/// ([`StatedSharpening::apply`]: hostile hints, smooth factors, passes, vetoes and
/// projections included). Panics only on a bug: a panic inside, or an output with an index
/// out of range or a non-finite position.
pub fn fuzz_decode_sharpen(data: &[u8]) {
    whet_codec::fuzz_decode(data);
    let limits = whet_format::Limits::DEFAULT
        .with_max_faces(MAX_SHARPENED_TRIANGLES)
        .with_max_vertices(MAX_SHARPENED_TRIANGLES);
    let Ok(container) = whet_format::parse(data, &limits) else {
        return;
    };
    // A malformed veto field is bad input, refused as `whet decode --sharpen` refuses it.
    let Ok(stated) = StatedSharpening::of(&container.header) else {
        return;
    };
    let opts = whet_codec::DecodeOptions::DEFAULT
        .with_limits(limits)
        .with_surface_filter(false);
    let Ok(mesh) = whet_codec::decode(data, &opts) else {
        return;
    };
    if let Ok(Some(out)) = stated.apply(&mesh) {
        check_mesh(&out.sharpened.mesh, "the stated sharpening");
    }
}

/// Panics when `mesh` has an index out of range or a non-finite position.
fn check_mesh(mesh: &whet_mesh::Mesh, what: &str) {
    let n = mesh.positions.len() as u32;
    assert!(
        mesh.triangles.iter().flatten().all(|&v| v < n),
        "{what}: index out of range"
    );
    assert!(
        mesh.positions.iter().all(|p| p.is_finite()),
        "{what}: non-finite position"
    );
}

/// Metro samples a direction of [`fuzz_encode`]'s sharpened encodes: each measures some 40
/// sharpenings, which at the encoder's default (300 000) would starve the fuzzer; the
/// choice, not its precision, is what is fuzzed.
const SHARPENED_METRO_SAMPLES: usize = 2_000;

/// Smallest stream size [`fuzz_encode`] asks of the automatic angle bits.
const AUTO_MIN_BYTES: usize = 60;

/// Most retiled triangles of [`fuzz_encode`]'s automatic angle bits: every quantization
/// runs its own size search, so a tenth of the fixed-bits limit keeps an input within a
/// few seconds.
const AUTO_MAX_TRIANGLES: usize = 2_000;

/// Encodes the mesh `data` describes (`whet_sharpen::fuzz_input`'s layout; byte 1 also
/// picks the angle bits, byte 2 the edge length: 2 % to 50 % of the diagonal, and a last
/// byte ending in two set bits `--optimize-for sharpened` (a quarter of the inputs), the
/// encoder's choice of sharpening with its vetoes, projections and runner-up, measured with
/// [`SHARPENED_METRO_SAMPLES`]; ending in four set bits, a sixteenth of the inputs, the
/// automatic angle bits with a finalist instead of byte 1's, at a size target of
/// [`AUTO_MIN_BYTES`] plus byte 2 instead of its edge length) and, when the
/// encoder accepts it, decodes the stream. Panics only on a bug: a panic inside, an
/// internal error, or a stream that does not decode bit for bit to the encoder's retiled
/// mesh (indices in range, finite positions).
pub fn fuzz_encode(data: &[u8]) {
    let Some((mesh, _, _, _)) = whet_sharpen::fuzz_input(data) else {
        return;
    };
    let bits = 3 + u32::from(data[1]) % 12;
    let fraction = 0.02 + 0.48 * f64::from(data[2]) / 255.0;
    let mut opts = SwingOptions::DEFAULT
        .with_rate(Rate::EdgeLength(fraction))
        .with_angle_bits(bits)
        .with_tuning(RetileTuning::DEFAULT.with_max_triangles(20_000));
    if data.last().is_some_and(|b| b & 3 == 3) {
        opts = opts
            .with_error_of(ErrorOf::Sharpened)
            .with_metro_samples(SHARPENED_METRO_SAMPLES);
    }
    if data.last().is_some_and(|b| b & 15 == 15) {
        // The automatic angle bits need a size target: each quantization gets its own size
        // search, and a finalist its own choice of sharpening.
        opts = opts
            .with_rate(Rate::TargetBytes(AUTO_MIN_BYTES + usize::from(data[2])))
            .with_auto_angle_bits(true)
            .with_tuning(RetileTuning::DEFAULT.with_max_triangles(AUTO_MAX_TRIANGLES));
    }
    let out = match encode(&mesh, &opts) {
        Ok(out) => out,
        Err(Error::Internal(e)) => panic!("internal error: {e}"),
        // Refusals (non-manifold input the repair cannot take, a front that stalls, a
        // retiling over the triangle limit) are clean errors.
        Err(_) => return,
    };
    let decoded = whet_codec::decode(&out.bytes, &whet_codec::DecodeOptions::DEFAULT)
        .unwrap_or_else(|e| panic!("the encoder's own stream does not decode: {e}"));
    check_mesh(&decoded, "the decoded stream");
    assert_eq!(
        decoded.triangles, out.retiled.triangles,
        "the decoder rebuilt other triangles than the encoder's"
    );
    let same = decoded
        .positions
        .iter()
        .zip(&out.retiled.positions)
        .all(|(a, b)| a.to_array().map(f64::to_bits) == b.to_array().map(f64::to_bits));
    assert!(
        same && decoded.positions.len() == out.retiled.positions.len(),
        "the decoder rebuilt other positions than the encoder's"
    );
    // What `whet decode --sharpen` makes of the stream: the encoder's snap vetoes must fit
    // the decoder's run pass for pass (they were judged on that very run).
    let header = whet_format::parse(&out.bytes, &whet_format::Limits::DEFAULT)
        .unwrap_or_else(|e| panic!("the encoder's own stream does not parse: {e}"))
        .header;
    let stated = StatedSharpening::of(&header)
        .unwrap_or_else(|e| panic!("the encoder's own veto field is refused: {e}"));
    let raw = whet_codec::decode(
        &out.bytes,
        &whet_codec::DecodeOptions::DEFAULT.with_surface_filter(false),
    )
    .unwrap_or_else(|e| panic!("the encoder's own stream does not decode: {e}"));
    if let Ok(Some(sharpened)) = stated.apply(&raw) {
        assert_eq!(
            sharpened.mismatched_veto_passes, 0,
            "the encoder's snap vetoes do not fit the decoder's sharpening"
        );
        check_mesh(&sharpened.sharpened.mesh, "the stated sharpening");
    }
}
