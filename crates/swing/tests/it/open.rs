//! Originals with boundaries: their holes are capped for retiling, the retiled triangles over
//! the caps are deleted by the decoder, and the geometry stays swing-coded.

use crate::{assert_swing, encode, round_trip};
use whet_metro::{metro, MetroOptions};
use whet_swing::{Rate, SwingOptions};
use whet_testkit::meshes::{grid, icosphere, punch, union};

#[test]
fn an_open_grid_stays_open_and_close_to_the_original() {
    let mut g = grid(20, 20);
    for p in &mut g.positions {
        p.z = 0.1 * (p.x * 0.3).sin() * (p.y * 0.2).cos();
    }
    let out = round_trip(&g, 0.04);
    assert_swing(&out);
    let report = out.retiled.topology_report();
    // One border loop (plus, at worst, a pinhole where the border approximation pinches).
    assert!((1..=2).contains(&report.boundary_loops), "{report:?}");
    assert_eq!(report.components, 1, "{report:?}");
    assert!(out.stats.deleted_triangles > 0);
    let r = metro(
        &g,
        &out.retiled,
        &MetroOptions::DEFAULT.with_samples(50_000),
    )
    .unwrap();
    // The retiled border follows the original border to within one or two L (corners of
    // the border are cut): at this coarse L (4 % of the diagonal) that is what dominates.
    assert!(r.symmetric.max < 2.5 * out.edge_length, "{r:?}");
    assert!(r.forward.figures.max < 1.5 * out.edge_length, "{r:?}");
    assert!(r.symmetric.rms_pct < 1.2, "{}", r.symmetric.rms_pct);
}

#[test]
fn a_sphere_with_holes_round_trips() {
    let m = punch(&icosphere(4), |t| t % 97 < 6);
    let out = round_trip(&m, 0.05);
    assert_swing(&out);
}

#[test]
fn closed_and_open_components_together() {
    let m = union(icosphere(3), &grid(10, 10), 3.0);
    let out = round_trip(&m, 0.03);
    assert_eq!(out.report.components, 2);
}

/// A band of `n` quads around a circle of radius 1, width 0.6: a Möbius strip with
/// `half_twist`, else a cylinder of height 0.6.
fn band(n: usize, half_twist: bool) -> whet_mesh::Mesh {
    use whet_mesh::DVec3;
    let mut positions = Vec::new();
    for i in 0..n {
        let u = std::f64::consts::TAU * i as f64 / n as f64;
        for s in [-0.3, 0.3] {
            let (r, z) = if half_twist {
                (1.0 + s * (u / 2.0).cos(), s * (u / 2.0).sin())
            } else {
                (1.0, s)
            };
            positions.push(DVec3::new(r * u.cos(), r * u.sin(), z));
        }
    }
    let n = n as u32;
    let mut triangles = Vec::new();
    for i in 0..n {
        let (a, b) = (2 * i, 2 * i + 1);
        // The last quad closes on the first rung, reversed after a half twist.
        let (c, d) = match (i + 1 < n, half_twist) {
            (true, _) => (a + 2, a + 3),
            (false, true) => (1, 0),
            (false, false) => (0, 1),
        };
        triangles.push([a, c, b]);
        triangles.push([b, c, d]);
    }
    whet_mesh::Mesh::new(positions, triangles)
}

#[test]
fn a_mobius_strip_is_refused_as_not_orientable() {
    // The repair orients it by cutting one edge, whose two sides still touch: the retiler
    // follows the surface across that seam onto the side facing the other way and stalls.
    // The error says why and what codes it instead, rather than only that it got stuck.
    let m = band(40, true);
    let err = encode(&m, &SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(0.03))).unwrap_err();
    assert!(
        matches!(&err, whet_swing::Error::InvalidInput(why) if why.contains("not orientable")),
        "{err}"
    );
    // The exact mode codes it (cut, and the cut reported).
    let exact = whet_codec::encode(&m, &whet_codec::EncodeOptions::DEFAULT).unwrap();
    assert!(
        exact.report.repair.cut_edges >= 1,
        "{:?}",
        exact.report.repair
    );
}

#[test]
fn the_same_band_without_the_twist_retiles() {
    // A cylinder built the same way: nothing to cut, so it retiles (two border loops).
    let out = round_trip(&band(40, false), 0.03);
    assert_swing(&out);
    assert_eq!(out.retiled.topology_report().boundary_loops, 2);
}
