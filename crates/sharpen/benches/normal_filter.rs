//! Normal-filter speed (issue 10) against seed 002's Table 1: the paper's 160k-face gear at
//! rho/L = 2.5 took 13.95 s (detection) + 1.84 s (filtering) + 17.58 s (updating) = 33.4 s on a
//! 2.8 GHz Pentium IV; the target is 20x faster (under about 1.6 s). Input: the synth
//! `blend` (fillet radius 0.01, 1.7 sampling steps, rotated so no feature is grid-aligned) by
//! marching cubes at 172 cells: 157k faces, 12.5k of them feature faces, rho = 2.5 mean edge
//! lengths, eta 0.1, lambda 0. (With the default radius 0.04 the fillet is 7 steps wide at this
//! resolution, wider than rho: nothing would be detected.)
//!
//! Each phase is its own criterion benchmark timed with `iter_custom` from the phase times the
//! run reports (`SharpenReport::detection_time` etc.), plus the whole run. Run with
//! `cargo bench -p whet-sharpen --bench normal_filter`.

use std::time::Duration;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{DQuat, DVec3};
use whet_sharpen::{sharpen, Method, SharpenOptions, SharpenReport};
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

/// Reads one phase's time from a report.
type Phase = fn(&SharpenReport) -> Duration;

fn bench(c: &mut Criterion) {
    let rotation = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.5);
    let shape = match Shape::new(
        ShapeKind::Blend,
        &ShapeParams::default()
            .with_rotation(rotation)
            .with_radius(0.01),
    ) {
        Ok(s) => s,
        Err(e) => panic!("cannot build the blend: {e}"),
    };
    let mesh = match marching_cubes(&shape, 172) {
        Ok(m) => m,
        Err(e) => panic!("marching cubes failed: {e}"),
    };
    let opts = SharpenOptions::DEFAULT
        .with_method(Method::NormalFilter)
        .with_rho(2.5);
    let run = || match sharpen(&mesh, &opts) {
        Ok(out) => out.report,
        Err(e) => panic!("normal filter failed: {e}"),
    };
    let r = run();
    eprintln!(
        "normal filter bench input: {} faces; {} feature faces, {} filtered, {} sweeps, {} swaps, {} collapses",
        mesh.triangles.len(),
        r.feature_faces,
        r.filtered_normals,
        r.update_iterations,
        r.swaps,
        r.collapses
    );
    let mut group = c.benchmark_group("normal_filter_160k");
    group.sample_size(10);
    let phases: [(&str, Phase); 4] = [
        ("detection", |r| r.detection_time),
        ("filtering", |r| r.filtering_time),
        ("updating", |r| r.updating_time),
        ("total", |r| r.time),
    ];
    for (name, phase) in phases {
        group.bench_function(name, |b| {
            b.iter_custom(|iters| (0..iters).map(|_| phase(&run())).sum())
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
