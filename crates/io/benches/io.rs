//! Read and write speed of the formats whet reads most: a ~1M-triangle grid mesh as binary
//! little-endian PLY, as ascii OFF and (reading) as OBJ, all held in memory. Writing the text
//! formats prints every coordinate in shortest round-trip form (`write_f64`: zmij's digits).

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use whet_io::{read, write, Format, PlyEncoding, WriteOptions};
use whet_mesh::{DVec3, Mesh};

/// A wavy height-field grid of `n` x `n` vertices and `2 (n-1)^2` triangles.
fn grid(n: u32) -> Mesh {
    let mut positions = Vec::with_capacity((n * n) as usize);
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (f64::from(i) / f64::from(n), f64::from(j) / f64::from(n));
            positions.push(DVec3::new(x, y, 0.05 * (7.0 * x).sin() * (5.0 * y).cos()));
        }
    }
    let mut triangles = Vec::with_capacity(2 * ((n - 1) * (n - 1)) as usize);
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = j * n + i;
            triangles.push([v, v + 1, v + n + 1]);
            triangles.push([v, v + n + 1, v + n]);
        }
    }
    Mesh::new(positions, triangles)
}

fn bench_read(c: &mut Criterion) {
    let mesh = grid(708);
    let mut group = c.benchmark_group("read_1m_triangles");
    group.sample_size(10);

    let mut ply = Vec::new();
    let opts = WriteOptions::DEFAULT.with_ply(PlyEncoding::BinaryLittleEndian);
    write(&mut ply, &mesh, Format::Ply, &opts).expect("writing to memory cannot fail");
    group.throughput(Throughput::Bytes(ply.len() as u64));
    group.bench_function("ply_binary_le", |b| {
        b.iter_batched(
            || (),
            |()| read(&ply[..], Format::Ply).expect("valid PLY"),
            BatchSize::PerIteration,
        )
    });

    // The text formats, read in blocks parsed on rayon's threads.
    for (name, format) in [("off_ascii", Format::Off), ("obj", Format::Obj)] {
        let mut text = Vec::new();
        write(&mut text, &mesh, format, &opts).expect("writing to memory cannot fail");
        group.throughput(Throughput::Bytes(text.len() as u64));
        group.bench_function(name, |b| {
            b.iter_batched(
                || (),
                |()| read(&text[..], format).expect("a file whet wrote"),
                BatchSize::PerIteration,
            )
        });
    }
    group.finish();
}

fn bench_write(c: &mut Criterion) {
    let mesh = grid(708);
    let mut group = c.benchmark_group("write_1m_triangles");
    group.sample_size(10);
    for (name, format, opts) in [
        (
            "ply_binary_le",
            Format::Ply,
            WriteOptions::DEFAULT.with_ply(PlyEncoding::BinaryLittleEndian),
        ),
        ("off_ascii", Format::Off, WriteOptions::DEFAULT),
    ] {
        let mut out = Vec::new();
        write(&mut out, &mesh, format, &opts).expect("writing to memory cannot fail");
        group.throughput(Throughput::Bytes(out.len() as u64));
        group.bench_function(name, |b| {
            b.iter(|| {
                out.clear();
                write(&mut out, &mesh, format, &opts).expect("writing to memory cannot fail");
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_read, bench_write);
criterion_main!(benches);
