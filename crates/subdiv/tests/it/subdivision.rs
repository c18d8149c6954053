//! Subdivision on whole meshes.

use whet_subdiv::{subdivide, EdgeSharpness, SubdivOptions};
use whet_synth::{Shape, ShapeKind, ShapeParams};

#[test]
fn fandisk_truth_subdivides_to_a_closed_manifold() {
    let mesh = Shape::new(ShapeKind::Fandisk, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    let s = EdgeSharpness::from_dihedral_angle(&mesh, 40.0);
    let out = subdivide(&mesh, &s, &SubdivOptions::DEFAULT.with_levels(2)).unwrap();
    let r = out.topology_report();
    assert!(r.manifold && r.oriented && r.problems.is_empty());
    assert_eq!(r.genus, mesh.topology_report().genus);
}

/// Limit positions do not move under further subdivision: the limit of an old vertex computed
/// at level k equals the one computed at level k + 1 (binary rules after the semi-sharp ones).
fn limit_is_stable(mesh: &whet_mesh::Mesh, s: &EdgeSharpness, sharp_levels: u32, tol: f64) {
    let o = SubdivOptions::DEFAULT.with_sharp_levels(sharp_levels);
    let a = subdivide(mesh, s, &o.with_levels(2)).unwrap();
    let b = subdivide(mesh, s, &o.with_levels(3)).unwrap();
    let mut worst = 0.0f64;
    for v in 0..a.positions.len() {
        worst = worst.max((a.positions[v] - b.positions[v]).length());
    }
    assert!(worst < tol, "limit moved by {worst}");
}

#[test]
fn limit_masks_are_fixed_points() {
    let sphere = Shape::new(ShapeKind::Octahedron, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    limit_is_stable(&sphere, &EdgeSharpness::zeros(&sphere), 0, 1e-12);
    let cube = Shape::new(ShapeKind::Cube, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    limit_is_stable(
        &cube,
        &EdgeSharpness::from_dihedral_angle(&cube, 40.0),
        0,
        1e-12,
    );
    // Semi-sharp levels first: the limit after them is still a fixed point.
    let mut half = EdgeSharpness::from_dihedral_angle(&cube, 40.0);
    let edges = half.edges().to_vec();
    for (i, [a, b]) in edges.into_iter().enumerate() {
        if half.values()[i] > 0.0 && i % 2 == 0 {
            half.set(a, b, 0.5).unwrap();
        }
    }
    limit_is_stable(&cube, &half, 1, 1e-12);
    // Fandisk: extraordinary crease vertices, corners and darts.
    let fandisk = Shape::new(ShapeKind::Fandisk, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    let s = EdgeSharpness::from_dihedral_angle(&fandisk, 30.0);
    limit_is_stable(&fandisk, &s, 0, 1e-12 * fandisk.diagonal());
}

#[test]
fn sharpness_moves_the_surface_continuously_towards_the_creases() {
    // A cube with every cube edge at sharpness h: the distance of the subdivided corners from
    // the true corners shrinks as h grows and vanishes at h = 1.
    let cube = Shape::new(ShapeKind::Cube, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    let detected = EdgeSharpness::from_dihedral_angle(&cube, 40.0);
    let mut last = f64::INFINITY;
    for step in 0..=4 {
        let h = step as f64 / 4.0;
        let values: Vec<f64> = detected.values().iter().map(|&v| v * h).collect();
        let s = EdgeSharpness::from_values(&cube, values).unwrap();
        let out = subdivide(&cube, &s, &SubdivOptions::DEFAULT).unwrap();
        let d = (0..cube.positions.len())
            .map(|v| (out.positions[v] - cube.positions[v]).length())
            .fold(0.0, f64::max);
        assert!(
            d < last || (d == 0.0 && last == 0.0),
            "h = {h}: {d} !< {last}"
        );
        last = d;
    }
    assert!(last < 1e-12);
}
