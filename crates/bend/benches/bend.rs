//! Bender throughput in output triangles per second (issue target: at least 5 million on one
//! core; the paper: about 22 thousand).
#![allow(clippy::unwrap_used)] // benches may panic on their own setup

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use whet_bend::bend;
use whet_testkit::meshes::icosphere;

fn bench(c: &mut Criterion) {
    // Icosphere level 6: 81,920 triangles -> 327,680; level 7: 327,680 -> 1,310,720.
    for level in [6u32, 7] {
        let mesh = icosphere(level);
        // Tag a band of edges (a great circle's neighbourhood) so sharp rules run too.
        let mut tags = Vec::new();
        for t in &mesh.triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
                if pa.z.abs() < 0.02 && pb.z.abs() < 0.02 {
                    tags.push([a.min(b), a.max(b)]);
                }
            }
        }
        let mut g = c.benchmark_group("bend");
        g.sample_size(10);
        g.throughput(Throughput::Elements(4 * mesh.triangles.len() as u64));
        g.bench_function(
            format!("icosphere{level}_{}_out", 4 * mesh.triangles.len()),
            |b| b.iter(|| black_box(bend(&mesh, &tags).unwrap())),
        );
        g.finish();
    }
}

criterion_group!(benches, bench);
criterion_main!(benches);
