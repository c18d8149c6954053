//! Where each stage of `whet decode --sharpen` moves chosen vertices of a swing stream: the
//! decoding without the surface filter (what sharpening starts from), EdgeSharpener with the
//! stream's options and snap vetoes, the stream's filter for after sharpening, then each
//! projection the header states, in order ([`whet_swing::StatedSharpening`], the code path
//! the decoder runs). A tracing aid: when a sharpened output is worse than the plain decoding
//! somewhere, it tells which stage put the vertices there.
//!
//! ```text
//! cargo run --release -p whet-swing --example stated_stages -- <stream.whet> <v,v,...> [out.off]
//! ```
//!
//! Vertex indices are those of the decoded mesh (the sharpener keeps them and appends its
//! new vertices). With `out.off` it writes the final mesh, which is `whet decode --sharpen`'s
//! output byte for byte.
#![allow(clippy::unwrap_used, clippy::expect_used)] // a tracing tool

use whet_mesh::Mesh;
use whet_swing::StatedSharpening;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.len() < 3 {
        eprintln!("usage: stated_stages <stream.whet> <v,v,...> [out.off]");
        std::process::exit(2);
    }
    let bytes = std::fs::read(&args[1]).expect("read the stream");
    let header = whet_format::parse(&bytes, &whet_format::Limits::DEFAULT)
        .expect("parse the stream")
        .header;
    let stated = StatedSharpening::of(&header).expect("the stream's sharpening fields");
    let raw = whet_codec::decode(
        &bytes,
        &whet_codec::DecodeOptions::DEFAULT.with_surface_filter(false),
    )
    .expect("decode the stream");
    let vertices: Vec<usize> = args[2]
        .split(',')
        .map(|s| s.trim().parse().expect("a vertex index"))
        .collect();
    let show = |stage: &str, mesh: &Mesh| {
        for &v in &vertices {
            match mesh.positions.get(v) {
                Some(p) => println!("{stage:>22}  v{v}  {:.5} {:.5} {:.5}", p.x, p.y, p.z),
                None => println!("{stage:>22}  v{v}  (no such vertex)"),
            }
        }
    };
    show("decoded, unfiltered", &raw);
    if stated.is_unsharpened() {
        println!("the stream states no sharpening: its output is the plain decoding");
        return;
    }
    let opts = stated.options();
    println!(
        "sharpening: {} smooth factor {} passes {} curved walls {:?}, vetoes {}; projections {:?}",
        opts.method.name(),
        opts.smooth_factor,
        stated.passes,
        stated.curved_walls,
        stated.vetoes.is_some(),
        stated.projections
    );
    let mut replay = stated.veto_replay();
    let mut sharpened = match replay.as_mut() {
        Some(r) => whet_sharpen::sharpen_judged(&raw, &opts, r),
        None => whet_sharpen::sharpen(&raw, &opts),
    }
    .expect("sharpen the decoding");
    show("sharpened", &sharpened.mesh);
    stated
        .after_filter
        .apply_after_sharpening(&raw, &mut sharpened.mesh);
    show("filter after sharpening", &sharpened.mesh);
    for projection in &stated.projections {
        if let Err(e) = projection.apply(&mut sharpened.mesh) {
            println!("the {} projection was skipped: {e}", projection.name());
        }
        show(projection.name(), &sharpened.mesh);
    }
    if let Some(path) = args.get(3) {
        whet_io::write_path(
            std::path::Path::new(path),
            &sharpened.mesh,
            None,
            &whet_io::WriteOptions::default(),
        )
        .expect("write the mesh");
    }
}
