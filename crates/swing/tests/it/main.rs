//! Integration tests of whet-swing: bit-exact round trips on built and public meshes, rate
//! control, open and degenerate originals, corrupted streams, property tests, snap vetoes,
//! the stated projections on one corner table.
#![allow(clippy::unwrap_used)] // a panic is a test failure

mod corruption;
mod fixtures;
mod open;
mod props;
mod rate;
mod round_trip;
mod stated;
mod vetoes;

use whet_codec::{decode, DecodeOptions, SwingGeometry};
use whet_mesh::Mesh;
use whet_swing::{encode, Rate, SwingOptions, SwingOutput};

/// Bit patterns of every coordinate.
pub fn bits(m: &Mesh) -> Vec<[u64; 3]> {
    m.positions
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

/// Encodes at edge length `fraction` of the diagonal and checks that the decoder rebuilds
/// the encoder's retiled mesh bit for bit, and that it is a valid oriented manifold.
pub fn round_trip(mesh: &Mesh, fraction: f64) -> SwingOutput {
    round_trip_with(
        mesh,
        &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(fraction)),
    )
}

/// [`round_trip`] with options.
pub fn round_trip_with(mesh: &Mesh, opts: &SwingOptions) -> SwingOutput {
    let out = encode(mesh, opts).unwrap();
    if out.geometry == SwingGeometry::Swing {
        // The forward kinds (docs/format.md: 7 to 10, the even ones with deletions): the
        // connectivity is coded inside the walk; the Edgebreaker kinds are only a fallback.
        assert!(
            matches!(geometry_kind(&out.bytes), 7..=10),
            "kind {}",
            geometry_kind(&out.bytes)
        );
    }
    let back = decode(&out.bytes, &DecodeOptions::DEFAULT).unwrap();
    assert_eq!(back.triangles, out.retiled.triangles);
    assert_eq!(bits(&back), bits(&out.retiled));
    let report = back.topology_report();
    assert!(report.manifold && report.oriented, "{report:?}");
    assert!(back.validate().is_ok());
    out
}

/// The geometry kind of a swing stream (the first byte of its geometry section).
pub fn geometry_kind(bytes: &[u8]) -> u8 {
    let c = whet_format::parse(bytes, &whet_format::Limits::DEFAULT).unwrap();
    c.section(whet_format::SectionKind::GEOMETRY).unwrap()[0]
}

/// Asserts the swing geometry (not the explicit fallback) was used.
pub fn assert_swing(out: &SwingOutput) {
    assert_eq!(out.geometry, SwingGeometry::Swing, "{:?}", out.stats);
}
