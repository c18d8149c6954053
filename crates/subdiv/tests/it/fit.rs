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

/// The demo's kind of input at a test-sized scale: whet-synth's polyhedral fandisk,
/// midpoint-subdivided twice (10,784 triangles of long needles on the cylindrical strips) and
/// jittered within its facets and along its creases.
fn needle_fandisk(jitter: bool) -> whet_mesh::Mesh {
    let shape = Shape::new(ShapeKind::Fandisk, &ShapeParams::default()).unwrap();
    let dense = whet_synth::midpoint_subdivide(shape.truth_mesh_ref(), 2);
    if jitter {
        whet_synth::jitter_within_surface(&dense, 0.3, 1)
    } else {
        dense
    }
}

/// Regression: the simplification refused every collapse leaving a needle, so inputs whose
/// own triangles are needles stalled far above the target (the demo mesh: 1,758 of 200
/// vertices) with a folded control mesh. It must reach the target and stay on the surface.
#[test]
fn needle_rich_input_simplifies_to_the_target() {
    for jitter in [false, true] {
        let input = needle_fandisk(jitter);
        for target in [100, 200] {
            let s = whet_subdiv::simplify(
                &input,
                &whet_subdiv::SimplifyOptions::DEFAULT.with_target_vertices(target),
            )
            .unwrap();
            let n = s.mesh.positions.len();
            let r = s.mesh.topology_report();
            assert!(r.manifold && r.oriented && r.genus == Some(0), "{r:?}");
            let e = metro(&input, &s.mesh, &MetroOptions::DEFAULT.with_samples(30_000)).unwrap();
            eprintln!(
                "jitter {jitter} target {target}: {n} vertices, max {:.4} % rms {:.5} %",
                e.symmetric.max_pct, e.symmetric.rms_pct
            );
            assert!(n <= target + target / 20, "{n} vertices for {target}");
            // The truth is polyhedral with 339 vertices: 100 control vertices already follow
            // it closely (measured: max below 0.3 %, RMS below 0.03 %; the stalled, folded
            // control meshes were at several percent).
            assert!(e.symmetric.max_pct < 1.0, "{e:?}");
            assert!(e.symmetric.rms_pct < 0.1, "{e:?}");
        }
    }
}

/// Regression: the fit on that input must be sane, and never worse than its control mesh
/// (the safeguard returns the best surface it measured, the control mesh included).
#[test]
fn needle_rich_input_fits_no_worse_than_its_control_mesh() {
    let input = needle_fandisk(true);
    let opts = FitOptions::DEFAULT
        .with_control_vertices(150)
        .with_levels(2)
        .with_iterations(6);
    let f = fit(&input, &opts).unwrap();
    assert_eq!(f.report.control_vertices, 150);
    let out = subdivide(
        &f.control,
        &f.sharpness,
        &SubdivOptions::DEFAULT.with_levels(2).with_sharp_levels(2),
    )
    .unwrap();
    let mo = MetroOptions::DEFAULT.with_samples(30_000);
    let fitted = metro(&input, &out, &mo).unwrap();
    let control = metro(&input, &f.control, &mo).unwrap();
    eprintln!(
        "fit {:?}: max {:.4} % rms {:.5} %",
        f.report.fallback, fitted.symmetric.max_pct, fitted.symmetric.rms_pct
    );
    assert!(fitted.symmetric.max_pct < 1.0, "{fitted:?}");
    assert!(fitted.symmetric.rms_pct < 0.1, "{fitted:?}");
    assert!(
        fitted.symmetric.rms_pct <= 1.5 * control.symmetric.rms_pct.max(0.01),
        "fit {fitted:?} control {control:?}"
    );
    // The report's own measure agrees with Metro's order of magnitude.
    let d = input.diagonal();
    assert!(f.report.max_distance / d < 0.01 && f.report.reverse_max_distance / d < 0.01);
}

/// The safeguard in every mode: the report says which measured surface was returned; only the
/// continuous mode may fall back to the all-sharp control mesh (it does on this polyhedral
/// input), and the smooth mode stays smooth.
#[test]
fn fit_reports_its_fallback() {
    let input = needle_fandisk(false);
    let opts = FitOptions::DEFAULT
        .with_control_vertices(80)
        .with_levels(2)
        .with_iterations(3);
    for mode in [
        SharpnessMode::Smooth,
        SharpnessMode::Crease,
        SharpnessMode::Continuous,
    ] {
        let f = fit(&input, &opts.with_mode(mode)).unwrap();
        eprintln!("{mode:?}: {:?}", f.report.fallback);
        assert!(f.report.rms_distance.is_finite() && f.report.reverse_rms_distance.is_finite());
        if mode != SharpnessMode::Continuous {
            assert_ne!(f.report.fallback, whet_subdiv::FitFallback::Polyhedral);
        }
        if mode == SharpnessMode::Smooth {
            assert_eq!(f.report.sharp_edges, 0);
        }
    }
}
