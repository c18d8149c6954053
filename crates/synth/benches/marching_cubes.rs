//! Marching cubes of the fandisk at resolutions 128 and 256 (the speed target: a 256^3
//! sampling of any shape in under a second in release).

use criterion::{criterion_group, criterion_main, Criterion};
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

fn bench(c: &mut Criterion) {
    let shape = match Shape::new(ShapeKind::Fandisk, &ShapeParams::default()) {
        Ok(s) => s,
        Err(e) => panic!("cannot build the fandisk: {e}"),
    };
    let mut group = c.benchmark_group("marching_cubes");
    group.sample_size(10);
    for resolution in [128, 256] {
        group.bench_function(format!("fandisk_{resolution}"), |b| {
            b.iter(|| marching_cubes(&shape, resolution))
        });
    }
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
