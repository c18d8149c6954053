//! How much of a sharpened mesh's error its vertex positions could still remove (an oracle
//! no decoder has: vertices moved onto their closest point of the original), and so how much
//! needs other connectivity (more splits, other detection) instead.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example sharpen_oracle -- <original.off> <decoded.off>
//! cargo run --release -p whet-sharpen --example sharpen_oracle -- <shape> <resolution> <rotation 0|1>
//! ```
//! With two files, `decoded.off` is `whet decode --no-surface-filter` output (sharpening's
//! input), and only the vertices the sharpener left alone move (the quantization noise on
//! flat faces). With a synth shape, its marching-cubes sampling at that resolution and
//! rotation (the marching-cubes table's) is sharpened and every output vertex moves onto the
//! truth mesh.
#![allow(clippy::unwrap_used)] // a measurement tool

mod support;

use whet_metro::{metro, Bvh, MetroOptions};
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let read = |p: &String| whet_io::read_path(std::path::Path::new(p), None).unwrap();
    let synth = ShapeKind::ALL.into_iter().find(|k| k.name() == args[0]);
    let (original, input) = match synth {
        Some(kind) => {
            let (res, rot): (usize, usize) = (args[1].parse().unwrap(), args[2].parse().unwrap());
            let rotation = support::rotations()[rot];
            let shape = Shape::new(kind, &ShapeParams::default().with_rotation(rotation)).unwrap();
            let input = marching_cubes(&shape, res).unwrap();
            (shape.truth_mesh_ref().clone(), input)
        }
        None => (read(&args[0]), read(&args[1])),
    };
    let sharp = whet_sharpen::sharpen(&input, &whet_sharpen::SharpenOptions::DEFAULT).unwrap();
    // The vertices the oracle moves: those sharpening left alone, or with a synth shape all.
    let moved = match synth {
        Some(_) => vec![true; sharp.mesh.positions.len()],
        None => whet_codec::untouched_by_sharpening(&input, &sharp.mesh),
    };
    let bvh = Bvh::new(&original);
    let mut oracle = sharp.mesh.clone();
    for (p, _) in oracle.positions.iter_mut().zip(&moved).filter(|(_, &f)| f) {
        *p = bvh.closest_point(*p).point;
    }
    let figures = |m: &whet_mesh::Mesh| {
        let r = metro(&original, m, &MetroOptions::default())
            .unwrap()
            .symmetric;
        format!("RMS {:.4} % max {:.3} %", r.rms_pct, r.max_pct)
    };
    let (d, s, o) = (figures(&input), figures(&sharp.mesh), figures(&oracle));
    let what = if synth.is_some() {
        "every vertex"
    } else {
        "untouched vertices"
    };
    println!("input {d} | sharpened {s} | {what} on the original {o}");
    let count = moved.iter().filter(|&&f| f).count();
    println!("({count} of {} vertices moved by the oracle)", moved.len());
}
