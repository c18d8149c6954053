//! Times EdgeSharpener alone on the bench's input, the rotated synth fandisk sampled by
//! marching cubes (a profiling aid beside `cargo bench -p whet-sharpen`, whose setup also
//! encodes swing inputs): `cargo run --release -p whet-sharpen --example sharpen_speed --
//! [resolution] [runs] [papers|extended] [out.off|-] [recycle]`; resolution 50, 160 and 505
//! give about 10k, 100k and 1M triangles. Prints the fastest and the median run; with
//! `out.off` it also writes the sharpened mesh (a refactoring aid: a change meant to keep the
//! output must keep the file byte for byte). With `recycle` each output is given back to the
//! engine (`EdgeSharpener::recycle`) before the next run, as a server sharpening mesh after
//! mesh would. A mesh file in place of the resolution (any argument that is not a number, such
//! as a `whet decode` output) times that input instead.
#![allow(clippy::unwrap_used)] // a measurement tool

use glam::{DQuat, DVec3};
use std::time::Instant;
use whet_sharpen::{EdgeSharpener, Method, SharpenOptions};
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let method = match args.get(2).map(String::as_str) {
        Some("papers") => Method::Papers,
        _ => Method::Extended,
    };
    let mesh = match args.first() {
        Some(path) if path.parse::<usize>().is_err() => {
            whet_io::read_path(std::path::Path::new(path), None).unwrap()
        }
        resolution => {
            let resolution = resolution.and_then(|a| a.parse().ok()).unwrap_or(50);
            // The bench's rotation, so every crease is chamfered.
            let rotation = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.5);
            let shape = Shape::new(
                ShapeKind::Fandisk,
                &ShapeParams::default().with_rotation(rotation),
            )
            .unwrap();
            marching_cubes(&shape, resolution).unwrap()
        }
    };
    let runs: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(20);
    let mut sharpener = EdgeSharpener::new(SharpenOptions::DEFAULT.with_method(method));
    let mut times = Vec::with_capacity(runs);
    let recycle = args.get(4).is_some_and(|a| a == "recycle");
    let mut last = None;
    for _ in 0..runs.max(1) {
        if recycle {
            if let Some(out) = last.take() {
                sharpener.recycle(out);
            }
        }
        let t = Instant::now();
        let out = sharpener.sharpen(&mesh).unwrap();
        times.push(t.elapsed().as_secs_f64());
        last = Some(std::hint::black_box(out));
    }
    if let (Some(path), Some(out)) = (args.get(3).filter(|p| p.as_str() != "-"), last) {
        let opts = whet_io::WriteOptions::default();
        whet_io::write_path(std::path::Path::new(path), &out.mesh, None, &opts).unwrap();
    }
    times.sort_by(f64::total_cmp);
    let t = mesh.triangles.len() as f64;
    println!(
        "{}{} {} triangles: best {:.3} ms ({:.2} M/s), median {:.3} ms ({:.2} M/s)",
        method.name(),
        if recycle { " (recycled)" } else { "" },
        mesh.triangles.len(),
        times[0] * 1e3,
        t / times[0] / 1e6,
        times[times.len() / 2] * 1e3,
        t / times[times.len() / 2] / 1e6
    );
}
