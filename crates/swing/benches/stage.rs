//! The decode-then-sharpen stage as `whet decode --sharpen` runs it, in memory (no file
//! read or written): decoding a swing stream without its surface filter, the sharpening it
//! states with its vetoes replayed, its filter for after sharpening and its projections
//! (`StatedSharpening::apply_with`, which `whet::decode_sharpened_with` calls). The streams
//! are encoded in the setup from the shared fixtures with `--optimize-for sharpened` at 6
//! angle bits: fandisk at 2.6 bpv and cad_box_hole at 3.1 bpv (14 032 and 63 446 retiled
//! triangles), rows of docs/results.md's swing table. Throughput in decoded triangles;
//! `decode_*` is the plain decode for comparison. Run with `cargo bench -p whet-swing --bench
//! stage`; the projections use rayon's threads, the sharpener one.
#![allow(clippy::unwrap_used)] // benches may panic on their own setup

use criterion::{black_box, criterion_group, criterion_main, Criterion, Throughput};
use whet_codec::{decode, DecodeOptions};
use whet_sharpen::EdgeSharpener;
use whet_swing::{encode, ErrorOf, Rate, StatedSharpening, SwingOptions};

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("stage");
    g.sample_size(20);
    for (name, fixture, bpv) in [
        ("fandisk_2.6bpv", "fandisk.off", 2.6),
        ("cad_box_hole_3.1bpv", "cad_box_hole.off", 3.1),
    ] {
        let original = whet_io::read_path(&whet_testkit::shared_fixture(fixture), None).unwrap();
        let opts = SwingOptions::DEFAULT
            .with_rate(Rate::BitsPerVertex(bpv))
            .with_angle_bits(6)
            .with_error_of(ErrorOf::Sharpened);
        let bytes = encode(&original, &opts).unwrap().bytes;
        let header = whet_format::parse(&bytes, &whet_format::Limits::DEFAULT)
            .unwrap()
            .header;
        let stated = StatedSharpening::of(&header).unwrap();
        assert!(
            !stated.is_unsharpened(),
            "{fixture} at {bpv} bpv: the encoder stated no sharpening"
        );
        // What `--sharpen` decodes: the stream without its surface filter (the filter for
        // after sharpening replaces it).
        let raw_opts = DecodeOptions::DEFAULT.with_surface_filter(false);
        let triangles = decode(&bytes, &raw_opts).unwrap().triangles.len();
        eprintln!(
            "{fixture} at {bpv} bpv: {} bytes, {triangles} triangles",
            bytes.len()
        );
        g.throughput(Throughput::Elements(triangles as u64));
        g.bench_function(format!("decode_{name}"), |b| {
            b.iter(|| black_box(decode(&bytes, &DecodeOptions::DEFAULT).unwrap()))
        });
        let mut engine = EdgeSharpener::new(stated.options());
        g.bench_function(format!("decode_sharpen_{name}"), |b| {
            b.iter(|| {
                let raw = decode(&bytes, &raw_opts).unwrap();
                let out = stated.apply_with(&raw, &mut engine).unwrap().unwrap();
                engine.recycle(out.sharpened);
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
