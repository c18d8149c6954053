//! The fit on small synthetic inputs: the ordering of seed 004's Table 1 and robustness.

use whet_metro::{metro, MetroOptions};
use whet_subdiv::{fit, subdivide, FitOptions, SharpnessMode, SubdivOptions};
use whet_synth::{Shape, ShapeKind, ShapeParams};

fn fit_error(input: &whet_mesh::Mesh, opts: &FitOptions) -> (f64, f64) {
    let f = fit(input, opts).unwrap();
    let out = subdivide(
        &f.control,
        &f.sharpness,
        &SubdivOptions::DEFAULT
            .with_levels(opts.levels)
            .with_sharp_levels(opts.levels),
    )
    .unwrap();
    let r = metro(input, &out, &MetroOptions::DEFAULT.with_samples(50_000)).unwrap();
    (r.symmetric.max_pct, r.symmetric.rms_pct)
}

/// The box with rounded edges (a semi-sharp feature), sampled by marching cubes: continuous
/// sharpness fits better than Hoppe's creases, which fit better than smooth Loop.
#[test]
fn continuous_sharpness_fits_a_blend_best() {
    let shape = Shape::new(ShapeKind::Blend, &ShapeParams::default().with_radius(0.06)).unwrap();
    let input = whet_synth::marching_cubes(&shape, 24).unwrap();
    let base = FitOptions::DEFAULT
        .with_control_vertices(60)
        .with_levels(2)
        .with_iterations(6);
    let smooth = fit_error(&input, &base.with_mode(SharpnessMode::Smooth));
    let crease = fit_error(&input, &base.with_mode(SharpnessMode::Crease));
    let cont = fit_error(&input, &base.with_mode(SharpnessMode::Continuous));
    eprintln!("blend: smooth {smooth:?} crease {crease:?} continuous {cont:?}");
    assert!(cont.1 < smooth.1, "RMS: {cont:?} vs smooth {smooth:?}");
    assert!(
        cont.1 <= crease.1 * 1.02,
        "RMS: {cont:?} vs crease {crease:?}"
    );
}

#[test]
fn fit_refuses_bad_input_without_panicking() {
    let empty = whet_mesh::Mesh::default();
    assert!(fit(&empty, &FitOptions::DEFAULT).is_err());
    let shape = Shape::new(ShapeKind::Cube, &ShapeParams::default()).unwrap();
    let mut cube = shape.truth_mesh();
    assert!(fit(&cube, &FitOptions::DEFAULT.with_levels(0)).is_err());
    assert!(fit(&cube, &FitOptions::DEFAULT.with_sharpness_bits(9)).is_err());
    cube.positions[0].x = f64::NAN;
    assert!(fit(&cube, &FitOptions::DEFAULT).is_err());
    // Non-manifold: a third triangle on an edge.
    let mut nm = shape.truth_mesh();
    let extra = nm.positions.len() as u32;
    nm.positions.push(glam::DVec3::splat(3.0));
    let [a, b, _] = nm.triangles[0];
    nm.triangles.push([a, b, extra]);
    assert!(fit(&nm, &FitOptions::DEFAULT).is_err());
}

/// A target above the input's vertex count keeps the input as the control mesh.
#[test]
fn tiny_inputs_fit() {
    let cube = Shape::new(ShapeKind::Cube, &ShapeParams::default())
        .unwrap()
        .truth_mesh();
    let f = fit(
        &cube,
        &FitOptions::DEFAULT
            .with_control_vertices(1000)
            .with_iterations(3),
    )
    .unwrap();
    assert_eq!(f.control.positions.len(), cube.positions.len());
    assert!(f.report.rms_distance.is_finite());
}

/// Seed 004's Table 1 on the rocker arm (275 control points): continuous sharpness beats
/// Hoppe's creases, which beat smooth Loop, in RMS; and it has the smallest max error.
/// Figures measured with `examples/figures.rs table1` (Metro, 300k samples): Loop 0.836 % /
/// 0.1701 %, creases 1.143 % / 0.1270 %, continuous 0.788 % / 0.0971 % (max / RMS of the
/// diagonal). Tolerances: 10 % (50k samples here, and other thread counts).
#[test]
#[ignore = "about 15 s: run with --ignored"]
fn rocker_arm_table1() {
    let m = whet_io::read_path(&whet_testkit::shared_fixture("rocker_arm.off"), None).unwrap();
    let base = FitOptions::DEFAULT;
    let smooth = fit_error(&m, &base.with_mode(SharpnessMode::Smooth));
    let crease = fit_error(&m, &base.with_mode(SharpnessMode::Crease));
    let cont = fit_error(&m, &base.with_mode(SharpnessMode::Continuous));
    eprintln!("rocker arm: smooth {smooth:?} crease {crease:?} continuous {cont:?}");
    assert!(cont.1 < crease.1 && crease.1 < smooth.1);
    assert!(cont.0 < smooth.0 && cont.0 < crease.0);
    assert!((cont.1 - 0.0971).abs() < 0.1 * 0.0971, "{cont:?}");
    assert!((cont.0 - 0.788).abs() < 0.1 * 0.788, "{cont:?}");
}
