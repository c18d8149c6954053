//! How much of a swing-decoded mesh's error after sharpening lies on the vertices the
//! sharpener left alone (the quantization noise on flat faces): sharpens the decoded mesh,
//! then moves every untouched vertex onto its closest point of the original (an oracle no
//! decoder has) and measures both with Metro.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example sharpen_oracle -- <original.off> <decoded.off>
//! ```
//! `decoded.off` is `whet decode --no-surface-filter` output (sharpening's input).
#![allow(clippy::unwrap_used)] // a measurement tool

use whet_metro::{metro, Bvh, MetroOptions};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let read = |p: &String| whet_io::read_path(std::path::Path::new(p), None).unwrap();
    let (original, decoded) = (read(&args[0]), read(&args[1]));
    let sharp = whet_sharpen::sharpen(&decoded, &whet_sharpen::SharpenOptions::DEFAULT).unwrap();
    let free = whet_codec::untouched_by_sharpening(&decoded, &sharp.mesh);
    let bvh = Bvh::new(&original);
    let mut oracle = sharp.mesh.clone();
    for (p, _) in oracle.positions.iter_mut().zip(&free).filter(|(_, &f)| f) {
        *p = bvh.closest_point(*p).point;
    }
    let figures = |m: &whet_mesh::Mesh| {
        let r = metro(&original, m, &MetroOptions::default())
            .unwrap()
            .symmetric;
        format!("RMS {:.4} % max {:.3} %", r.rms_pct, r.max_pct)
    };
    let (d, s, o) = (figures(&decoded), figures(&sharp.mesh), figures(&oracle));
    let untouched = free.iter().filter(|&&f| f).count();
    println!("decoded {d} | sharpened {s} | untouched vertices on the original {o}");
    println!("({untouched} of {} vertices untouched)", free.len());
}
