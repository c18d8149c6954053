//! Retile, encode, decode: the decoder must rebuild the encoder's retiled mesh bit for bit.

use whet_codec::{decode, DecodeOptions, SwingGeometry};
use whet_mesh::Mesh;
use whet_swing::{encode, Rate, SwingOptions};
use whet_testkit::meshes::{icosphere, torus};

fn bits(m: &Mesh) -> Vec<[u64; 3]> {
    m.positions
        .iter()
        .map(|p| [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()])
        .collect()
}

fn round_trip(mesh: &Mesh, fraction: f64) -> whet_swing::SwingOutput {
    let out = encode(
        mesh,
        &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(fraction)),
    )
    .unwrap();
    assert_eq!(out.geometry, SwingGeometry::Swing, "{:?}", out.stats);
    let back = decode(&out.bytes, &DecodeOptions::DEFAULT).unwrap();
    assert_eq!(back.triangles, out.retiled.triangles);
    assert_eq!(bits(&back), bits(&out.retiled));
    let report = back.topology_report();
    assert!(report.manifold, "{report:?}");
    out
}

#[test]
fn sphere_round_trips_bit_exactly() {
    let out = round_trip(&icosphere(4), 0.06);
    let h = out.report.clers_histogram;
    let t = out.report.triangles as f64;
    eprintln!(
        "sphere: {} triangles, hist {:?}, C+R {:.3}, val6 {:.3}, conn {:.3} bpt, stats {:?}",
        out.report.triangles,
        h,
        (h[0] + h[3]) as f64 / t,
        out.valence6_fraction(),
        out.report.connectivity_bits as f64 / t,
        out.stats
    );
    assert_eq!(out.retiled.topology_report().genus, Some(0));
}

#[test]
fn torus_round_trips_bit_exactly() {
    let out = round_trip(&torus(60, 30), 0.04);
    eprintln!(
        "torus: {} triangles, hist {:?}, stats {:?}",
        out.report.triangles, out.report.clers_histogram, out.stats
    );
    assert_eq!(out.retiled.topology_report().genus, Some(1));
}
