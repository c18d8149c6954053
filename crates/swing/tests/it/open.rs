//! Originals with boundaries: their holes are capped for retiling, the retiled triangles over
//! the caps are deleted by the decoder, and the geometry stays swing-coded.

use crate::{assert_swing, round_trip};
use whet_metro::{metro, MetroOptions};
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
