//! The entry point of the `swing_encode` cargo-fuzz target (`fuzz/`), shared with the stable
//! replay test of its corpus: the retiler and the swing encoder on arbitrary small meshes
//! (the mesh layout of `whet_sharpen::fuzz_input`: coincident vertices, zero-area and folded
//! triangles, exact coplanarity, several components), at an edge length and angle bits the
//! input picks.

use crate::{encode, Error, Rate, RetileTuning, SwingOptions};

/// Encodes the mesh `data` describes (`whet_sharpen::fuzz_input`'s layout; byte 1 also
/// picks the angle bits, byte 2 the edge length: 2 % to 50 % of the diagonal) and, when the
/// encoder accepts it, decodes the stream. Panics only on a bug: a panic inside, an
/// internal error, or a stream that does not decode bit for bit to the encoder's retiled
/// mesh (indices in range, finite positions).
pub fn fuzz_encode(data: &[u8]) {
    let Some((mesh, _, _, _)) = whet_sharpen::fuzz_input(data) else {
        return;
    };
    let bits = 3 + u32::from(data[1]) % 12;
    let fraction = 0.02 + 0.48 * f64::from(data[2]) / 255.0;
    let opts = SwingOptions::DEFAULT
        .with_rate(Rate::EdgeLength(fraction))
        .with_angle_bits(bits)
        .with_tuning(RetileTuning::DEFAULT.with_max_triangles(20_000));
    let out = match encode(&mesh, &opts) {
        Ok(out) => out,
        Err(Error::Internal(e)) => panic!("internal error: {e}"),
        // Refusals (non-manifold input the repair cannot take, a front that stalls, a
        // retiling over the triangle limit) are clean errors.
        Err(_) => return,
    };
    let decoded = whet_codec::decode(&out.bytes, &whet_codec::DecodeOptions::DEFAULT)
        .unwrap_or_else(|e| panic!("the encoder's own stream does not decode: {e}"));
    let n = decoded.positions.len() as u32;
    assert!(
        decoded.triangles.iter().flatten().all(|&v| v < n),
        "index out of range"
    );
    assert!(
        decoded.positions.iter().all(|p| p.is_finite()),
        "non-finite position"
    );
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
}
