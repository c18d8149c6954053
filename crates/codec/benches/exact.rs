//! Exact-mode encode and decode throughput on a ~1M-triangle mesh (issue target: decode at
//! 20 M triangles/s, encode at 5 M triangles/s on one core), with the default prediction,
//! the traversal prediction (`*_traversal`) and the traversal prediction with the static
//! codes (`*_traversal_static`); `*_reusing` encodes with one set of [`EncodeBuffers`] or
//! decodes with one set of [`DecodeBuffers`] throughout, as a server coding mesh after mesh
//! would.
#![allow(clippy::unwrap_used)] // benches may panic on their own setup

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use whet_codec::{
    decode, decode_reusing, encode, DecodeBuffers, DecodeOptions, EncodeBuffers, EncodeOptions,
    Encoder, ExactPrediction,
};
use whet_testkit::meshes::{icosphere, shuffle};

fn bench(c: &mut Criterion) {
    // Icosphere level 7: 327,680 triangles; level 8: 1,310,720.
    let mesh = shuffle(&icosphere(8), 1);
    let opts = EncodeOptions::DEFAULT.with_quant_bits(14);
    let enc = encode(&mesh, &opts).unwrap();
    eprintln!(
        "icosphere(8): {} triangles, {} bytes ({:.3} bpt connectivity)",
        mesh.triangles.len(),
        enc.bytes.len(),
        enc.report.connectivity_bits as f64 / mesh.triangles.len() as f64
    );
    let mut g = c.benchmark_group("exact");
    g.sample_size(10);
    g.throughput(Throughput::Elements(mesh.triangles.len() as u64));
    g.bench_function("encode_1.3M", |b| {
        b.iter(|| black_box(encode(&mesh, &opts).unwrap()))
    });
    g.bench_function("decode_1.3M", |b| {
        b.iter(|| black_box(decode(&enc.bytes, &DecodeOptions::DEFAULT).unwrap()))
    });
    let fast = opts.with_prediction(ExactPrediction::Traversal);
    let enc_fast = encode(&mesh, &fast).unwrap();
    eprintln!("traversal prediction: {} bytes", enc_fast.bytes.len());
    g.bench_function("encode_1.3M_traversal", |b| {
        b.iter(|| black_box(encode(&mesh, &fast).unwrap()))
    });
    g.bench_function("decode_1.3M_traversal", |b| {
        b.iter(|| black_box(decode(&enc_fast.bytes, &DecodeOptions::DEFAULT).unwrap()))
    });
    // The traversal order with the static residual and label codes.
    let fastest = opts.with_prediction(ExactPrediction::TraversalStatic);
    let enc_fastest = encode(&mesh, &fastest).unwrap();
    eprintln!(
        "traversal prediction, static codes: {} bytes",
        enc_fastest.bytes.len()
    );
    g.bench_function("encode_1.3M_traversal_static", |b| {
        b.iter(|| black_box(encode(&mesh, &fastest).unwrap()))
    });
    g.bench_function("decode_1.3M_traversal_static", |b| {
        b.iter(|| black_box(decode(&enc_fastest.bytes, &DecodeOptions::DEFAULT).unwrap()))
    });
    // An encoder that encodes one mesh after another keeps its buffers
    // (`Encoder::encode_reusing`), as a decoder that decodes one stream after another keeps
    // its own and gives each mesh back when done with it (`decode_reusing`): no fresh
    // memory to fault in.
    for (name, o) in [
        ("encode_1.3M_reusing", opts),
        ("encode_1.3M_traversal_reusing", fast),
        ("encode_1.3M_traversal_static_reusing", fastest),
    ] {
        let encoder = Encoder::new(o);
        let mut buffers = EncodeBuffers::new();
        g.bench_function(name, |b| {
            b.iter(|| black_box(encoder.encode_reusing(&mesh, &mut buffers).unwrap()))
        });
    }
    for (name, bytes) in [
        ("decode_1.3M_reusing", &enc.bytes),
        ("decode_1.3M_traversal_reusing", &enc_fast.bytes),
        ("decode_1.3M_traversal_static_reusing", &enc_fastest.bytes),
    ] {
        let mut buffers = DecodeBuffers::new();
        g.bench_function(name, |b| {
            b.iter(|| {
                let mesh = decode_reusing(bytes, &DecodeOptions::DEFAULT, &mut buffers).unwrap();
                buffers.recycle(black_box(mesh));
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
