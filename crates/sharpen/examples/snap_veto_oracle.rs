//! What snap vetoes gain on one decoded mesh: sharpens it as it is, then judged against the
//! original as `whet encode` judges it (`whet_swing::snap_judge`), and measures both with
//! Metro.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example snap_veto_oracle -- <original.off> <decoded.off> [extended|papers] [factor]
//! ```
//! `decoded.off` is `whet decode --no-surface-filter` output (sharpening's input).
#![allow(clippy::unwrap_used)] // a measurement tool

use std::sync::OnceLock;
use whet_metro::{metro, MetroOptions};
use whet_sharpen::{Method, SharpenOptions};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let read = |p: &String| whet_io::read_path(std::path::Path::new(p), None).unwrap();
    let (original, decoded) = (read(&args[0]), read(&args[1]));
    let method = match args.get(2).map(String::as_str) {
        Some("papers") => Method::Papers,
        _ => Method::Extended,
    };
    let factor = args.get(3).map_or(2.0, |f| f.parse().unwrap());
    let opts = SharpenOptions::DEFAULT
        .with_method(method)
        .with_smooth_factor(factor);
    let plain = whet_sharpen::sharpen(&decoded, &opts).unwrap();
    let bvh = OnceLock::new();
    let (judged, vetoes) = whet_swing::snap_judge::sharpen_judged(&original, &bvh, &decoded, &opts);
    let figures = |m: &whet_mesh::Mesh| {
        let r = metro(&original, m, &MetroOptions::default())
            .unwrap()
            .symmetric;
        format!("RMS {:.4} % max {:.3} %", r.rms_pct, r.max_pct)
    };
    println!(
        "decoded {} | sharpened {} | vetoed {} ({} of {} snaps)",
        figures(&decoded),
        figures(&plain.mesh),
        figures(&judged.unwrap().mesh),
        vetoes.vetoed(),
        vetoes.judged()
    );
}
