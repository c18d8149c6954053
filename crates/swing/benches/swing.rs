//! Swing-mode throughput on the workload: a 1.38M-triangle original (the armadillo
//! fixture split 1-to-4 twice: the same surface, a million-triangle scan's density) retiled
//! into about 116k triangles (issue target: retile and encode in under 3 s on one core;
//! decode at 10 M retiled triangles/s or more). `swing_speed` (examples) prints the same
//! figures as one table row.
#![allow(clippy::unwrap_used)] // benches may panic on their own setup

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use whet_codec::{decode, DecodeOptions};
use whet_swing::{encode, Rate, SwingOptions};

fn bench(c: &mut Criterion) {
    let armadillo =
        whet_io::read_path(&whet_testkit::shared_fixture("armadillo.off"), None).unwrap();
    let original = whet_synth::midpoint_subdivide(&armadillo, 2);
    let opts = SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(0.0037));
    let out = encode(&original, &opts).unwrap();
    let retiled = out.report.triangles;
    eprintln!(
        "armadillo split twice: {} triangles -> {retiled} retiled triangles, {} bytes",
        original.triangles.len(),
        out.bytes.len()
    );
    let mut g = c.benchmark_group("swing");
    // Ten encodes of about 2 s each.
    g.sample_size(10)
        .measurement_time(std::time::Duration::from_secs(25));
    g.throughput(Throughput::Elements(original.triangles.len() as u64));
    g.bench_function("retile_encode_1.38M", |b| {
        b.iter(|| black_box(encode(&original, &opts).unwrap()))
    });
    // Throughput in retiled triangles: the unit of the decode target.
    g.throughput(Throughput::Elements(retiled as u64));
    g.bench_function("decode_116k", |b| {
        b.iter(|| black_box(decode(&out.bytes, &DecodeOptions::DEFAULT).unwrap()))
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
