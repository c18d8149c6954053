//! The Metro measure on a one-million-triangle pair: a finely tessellated wavy sphere and a
//! copy with every vertex pushed radially by up to ±0.1 % of the radius (about a sixth of an
//! edge), one million face samples per direction.
//!
//! Reported separately: BVH build (one mesh), query throughput (one direction, BVH
//! prebuilt; the element count is every point measured: vertices, edge and face samples)
//! and the whole `metro` call (both builds, both directions). Each on one rayon thread and
//! on two. Goal: the whole call under 2 s on one core.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use std::hint::black_box;
use std::time::Duration;
use whet_mesh::{DVec3, Mesh};
use whet_metro::sampling::SplitMix64;
use whet_metro::{metro, one_sided, Bvh, MetroOptions};

/// A UV sphere of `rings` x `segments` quads (two triangles each) with radius `r(dir, vertex)`.
fn sphere(rings: usize, segments: usize, r: impl Fn(DVec3, usize) -> f64) -> Mesh {
    let mut positions = vec![DVec3::Z * r(DVec3::Z, 0)];
    for i in 1..rings {
        let theta = std::f64::consts::PI * i as f64 / rings as f64;
        for j in 0..segments {
            let phi = std::f64::consts::TAU * j as f64 / segments as f64;
            let d = DVec3::new(
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            );
            positions.push(d * r(d, positions.len()));
        }
    }
    positions.push(-DVec3::Z * r(-DVec3::Z, positions.len()));
    let south = (positions.len() - 1) as u32;
    let ring = |i: usize, j: usize| (1 + (i - 1) * segments + j % segments) as u32;
    let mut triangles = Vec::with_capacity(2 * rings * segments);
    for j in 0..segments {
        triangles.push([0, ring(1, j), ring(1, j + 1)]);
        triangles.push([south, ring(rings - 1, j + 1), ring(rings - 1, j)]);
    }
    for i in 1..rings - 1 {
        for j in 0..segments {
            let (a, b, c, d) = (
                ring(i, j),
                ring(i, j + 1),
                ring(i + 1, j),
                ring(i + 1, j + 1),
            );
            triangles.push([a, c, d]);
            triangles.push([a, d, b]);
        }
    }
    Mesh::new(positions, triangles)
}

fn wave(d: DVec3) -> f64 {
    1.0 + 0.05 * (8.0 * d.x).sin() * (7.0 * d.y).sin() * (6.0 * d.z).cos()
}

/// The reference (998 000 triangles) and its perturbed copy.
fn pair() -> (Mesh, Mesh) {
    let reference = sphere(500, 1000, |d, _| wave(d));
    let test = sphere(500, 1000, |d, i| {
        let mut rng = SplitMix64::new(i as u64);
        wave(d) + (rng.next_f64() - 0.5) * 0.002
    });
    (reference, test)
}

const SAMPLES: usize = 1_000_000;

fn pool(threads: usize) -> rayon::ThreadPool {
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .expect("a rayon thread pool")
}

fn bench(c: &mut Criterion) {
    let (reference, test) = pair();
    let diagonal = reference.diagonal();
    let opts = MetroOptions::DEFAULT.with_samples(SAMPLES);
    let ref_bvh = Bvh::new(&reference);
    let points = one_sided(&test, &ref_bvh, SAMPLES, 1, diagonal)
        .expect("the bench meshes are valid")
        .samples;

    let mut g = c.benchmark_group("metro_1M");
    g.sample_size(10);
    g.warm_up_time(Duration::from_secs(1));
    for threads in [1, 2] {
        let pool = pool(threads);
        g.measurement_time(Duration::from_secs(4));
        g.throughput(Throughput::Elements(reference.triangles.len() as u64));
        g.bench_function(BenchmarkId::new("bvh_build", format!("{threads}t")), |b| {
            b.iter(|| pool.install(|| black_box(Bvh::new(black_box(&reference)))))
        });
        g.measurement_time(Duration::from_secs(8));
        g.throughput(Throughput::Elements(points as u64));
        g.bench_function(
            BenchmarkId::new("query_one_direction", format!("{threads}t")),
            |b| {
                b.iter(|| {
                    pool.install(|| black_box(one_sided(&test, &ref_bvh, SAMPLES, 1, diagonal)))
                })
            },
        );
        g.measurement_time(Duration::from_secs(20));
        g.throughput(Throughput::Elements(1));
        g.bench_function(
            BenchmarkId::new("metro_total", format!("{threads}t")),
            |b| b.iter(|| pool.install(|| black_box(metro(&reference, &test, &opts)))),
        );
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
