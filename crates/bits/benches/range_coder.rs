//! Throughput of the range coder on CLERS-like symbols and residual-like integers.
#![allow(clippy::unwrap_used)] // benches may panic on their own setup

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use whet_bits::{RangeDecoder, RangeEncoder, SignedIntModel, SymbolModel};

fn symbols(n: usize) -> Vec<usize> {
    let mut x = 7u32;
    (0..n)
        .map(|_| {
            x = x.wrapping_mul(1664525).wrapping_add(1013904223);
            [0, 0, 0, 1, 1, 1, 2, 3][(x >> 29) as usize]
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let n = 1_000_000;
    let syms = symbols(n);
    let mut g = c.benchmark_group("range_coder");
    g.throughput(Throughput::Elements(n as u64));
    g.bench_function("encode_symbol_ctx", |b| {
        b.iter(|| {
            let mut models: Vec<SymbolModel> = (0..5).map(|_| SymbolModel::new(5)).collect();
            let mut e = RangeEncoder::new();
            let mut prev = 0;
            for &s in &syms {
                e.encode_symbol(&mut models[prev], s);
                prev = s;
            }
            black_box(e.finish())
        })
    });
    let mut models: Vec<SymbolModel> = (0..5).map(|_| SymbolModel::new(5)).collect();
    let mut e = RangeEncoder::new();
    let mut prev = 0;
    for &s in &syms {
        e.encode_symbol(&mut models[prev], s);
        prev = s;
    }
    let bytes = e.finish();
    g.bench_function("decode_symbol_ctx", |b| {
        b.iter(|| {
            let mut models: Vec<SymbolModel> = (0..5).map(|_| SymbolModel::new(5)).collect();
            let mut d = RangeDecoder::new(&bytes).unwrap();
            let mut prev = 0;
            let mut sum = 0;
            for _ in 0..n {
                prev = d.decode_symbol(&mut models[prev]);
                sum += prev;
            }
            black_box(sum)
        })
    });
    let ints: Vec<i32> = syms.iter().map(|&s| (s as i32 - 1) * 37).collect();
    g.bench_function("encode_int", |b| {
        b.iter(|| {
            let mut m = SignedIntModel::new();
            let mut e = RangeEncoder::new();
            for &v in &ints {
                m.encode(&mut e, v);
            }
            black_box(e.finish())
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
