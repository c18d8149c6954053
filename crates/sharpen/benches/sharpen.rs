//! EdgeSharpener throughput on marching-cubes samplings of the synth fandisk (rotated, so every
//! crease is chamfered) at about 10k, 100k and 1M triangles, both methods. The target:
//! at least 5 million input triangles per second on one core, linear in size (1M triangles in
//! under 0.2 s). Run with `cargo bench -p whet-sharpen`; criterion reports the throughput in
//! elements (input triangles) per second.
//!
//! The sharpener itself is single-threaded; marching cubes (setup only) uses rayon.
//!
//! `extended_*_recycled`: the extended method with each output given back to the engine
//! before the next run (`EdgeSharpener::recycle`).
//!
//! Also the real input: fandisk and joint encoded by whet-swing (6 angle bits, at about 2x
//! their vertex count: 28k and 77k triangles) and decoded by whet-codec, named `*_swing_*`.

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use glam::{DQuat, DVec3};
use whet_sharpen::{EdgeSharpener, Method, SharpenOptions};
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

/// Marching-cubes resolutions giving about 10k, 100k and 1M triangles of the rotated fandisk.
const SIZES: [(&str, usize); 3] = [("10k", 50), ("100k", 160), ("1M", 505)];

fn bench(c: &mut Criterion) {
    let rotation = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.5);
    let shape = match Shape::new(
        ShapeKind::Fandisk,
        &ShapeParams::default().with_rotation(rotation),
    ) {
        Ok(s) => s,
        Err(e) => panic!("cannot build the fandisk: {e}"),
    };
    let mut group = c.benchmark_group("sharpen");
    group.sample_size(10);
    for (name, resolution) in SIZES {
        let mesh = match marching_cubes(&shape, resolution) {
            Ok(m) => m,
            Err(e) => panic!("marching cubes failed: {e}"),
        };
        group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
        for method in [Method::Papers, Method::Extended] {
            let mut sharpener = EdgeSharpener::new(SharpenOptions::DEFAULT.with_method(method));
            group.bench_function(format!("{}_{name}", method.name()), |b| {
                b.iter(|| sharpener.sharpen(&mesh))
            });
        }
        // Each output given back before the next run (`EdgeSharpener::recycle`), as a server
        // sharpening mesh after mesh: no memory mapped afresh per run.
        let mut sharpener = EdgeSharpener::new(SharpenOptions::DEFAULT);
        group.bench_function(format!("extended_{name}_recycled"), |b| {
            b.iter(|| match sharpener.sharpen(&mesh) {
                Ok(out) => sharpener.recycle(out),
                Err(e) => panic!("sharpening failed: {e}"),
            })
        });
    }
    for (name, fixture, bpv) in [
        ("swing_fandisk_28k", "fandisk.off", 6.4),
        ("swing_joint_77k", "joint.off", 4.3),
    ] {
        let original = match whet_io::read_path(&whet_testkit::shared_fixture(fixture), None) {
            Ok(m) => m,
            Err(e) => panic!("{fixture}: {e}"),
        };
        let opts = whet_swing::SwingOptions::DEFAULT
            .with_rate(whet_swing::Rate::BitsPerVertex(bpv))
            .with_angle_bits(6);
        let mesh = match whet_swing::encode(&original, &opts)
            .map_err(|e| e.to_string())
            .and_then(|out| {
                whet_codec::decode(
                    &out.bytes,
                    &whet_codec::DecodeOptions::DEFAULT.with_surface_filter(false),
                )
                .map_err(|e| e.to_string())
            }) {
            Ok(m) => m,
            Err(e) => panic!("{fixture}: {e}"),
        };
        group.throughput(Throughput::Elements(mesh.triangles.len() as u64));
        for method in [Method::Papers, Method::Extended] {
            let mut sharpener = EdgeSharpener::new(SharpenOptions::DEFAULT.with_method(method));
            group.bench_function(format!("{}_{name}", method.name()), |b| {
                b.iter(|| sharpener.sharpen(&mesh))
            });
        }
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
