//! Where the remaining error of one sharpened case sits: the report, the output checks, Metro
//! in both directions, the output vertices farthest from the reference and the reference
//! crease points farthest from the output.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example sharpen_diag -- cube 64 0 extended
//! cargo run --release -p whet-sharpen --example sharpen_diag -- cad_box_hole.off 0.5 - papers
//! cargo run --release -p whet-sharpen --example sharpen_diag -- rocker_arm.off 4 6 extended
//! ```
//!
//! A synth shape takes `<shape> <resolution> <rotation 0|1> <method>`; a shared fixture
//! (`*.off`) takes `<fixture> <vertex ratio> - <method>` and uses the stand-in retiling of
//! `support::cached_stand_in`, or `<fixture> <bpv> <angle bits|auto> <method>` and uses the
//! swing-decoded fixture of `swing_inputs::swing_input` (auto: optimised for sharpening).
//! Any mesh file (a path with a `/`) takes `<input> <reference> - <method>`.

mod support;
mod swing_inputs;

use std::fmt::Display;

use whet_metro::{metro, Bvh, MetroOptions};
use whet_sharpen::{sharpen, Method, SharpenOptions};
use whet_synth::{marching_cubes, Shape, ShapeKind, ShapeParams};

fn or_die<T, E: Display>(r: Result<T, E>, what: &str) -> T {
    r.unwrap_or_else(|e| panic!("{what}: {e}"))
}

fn arg<T: std::str::FromStr>(args: &[String], i: usize, default: T) -> T
where
    T::Err: Display,
{
    match args.get(i) {
        Some(s) => or_die(s.parse(), &format!("argument {i} ({s})")),
        None => default,
    }
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let method: Method = arg(&args, 4, Method::Extended);
    let files = args.get(1).is_some_and(|a| a.contains('/'));
    let swing = !files
        && args.get(1).is_some_and(|a| a.ends_with(".off"))
        && args.get(3).is_some_and(|a| a != "-");
    let (reference, input) = if files {
        let read = |p: &str| or_die(whet_io::read_path(std::path::Path::new(p), None), p);
        (read(&args[2]), read(&args[1]))
    } else if swing {
        let bpv: f64 = arg(&args, 2, 4.0);
        let angles = match args[3].as_str() {
            "auto" => swing_inputs::Angles::AutoSharpened,
            b => swing_inputs::Angles::Fixed(or_die(b.parse(), "angle bits")),
        };
        let s = swing_inputs::swing_input(&args[1], bpv, angles);
        println!(
            "{} at {:.2} bpv, {} angle bits",
            args[1], s.bpv, s.angle_bits
        );
        (s.original, s.decoded)
    } else if args.get(1).is_some_and(|a| a.ends_with(".off")) {
        let ratio: f64 = arg(&args, 2, 1.0);
        let (original, mesh, _) = support::cached_stand_in(&args[1], ratio);
        (original, mesh)
    } else {
        let kind: ShapeKind = arg(&args, 1, ShapeKind::Cube);
        let res: usize = arg(&args, 2, 64);
        let rot: usize = arg::<usize>(&args, 3, 0).min(1);
        let params = ShapeParams::default().with_rotation(support::rotations()[rot]);
        let shape = or_die(Shape::new(kind, &params), "shape");
        (
            shape.truth_mesh(),
            or_die(marching_cubes(&shape, res), "marching cubes"),
        )
    };
    let out = or_die(
        sharpen(&input, &SharpenOptions::DEFAULT.with_method(method)),
        "sharpen",
    );
    println!("{}", out.report.to_json());
    let c = support::check(&reference, &input, &out);
    println!(
        "manifold {}, new boundary edges {}, new triangles {}, reversed {} (input {}), \
         smallest new angle {:.2} deg",
        c.manifold,
        c.new_boundary_edges,
        c.new_triangles,
        c.reversed,
        c.input_reversed,
        c.min_new_angle
    );
    let opts = MetroOptions::DEFAULT.with_samples(300_000);
    let before = or_die(metro(&reference, &input, &opts), "metro");
    let after = or_die(metro(&reference, &out.mesh, &opts), "metro");
    println!(
        "symmetric RMS {:.4}% -> {:.4}%, max {:.3}% -> {:.3}%",
        before.symmetric.rms_pct,
        after.symmetric.rms_pct,
        before.symmetric.max_pct,
        after.symmetric.max_pct
    );
    println!(
        "after: forward (output to reference) max {:.3}%, backward max {:.3}%",
        after.forward.figures.max_pct, after.backward.figures.max_pct
    );
    let diag = reference.diagonal();
    let to_ref = Bvh::new(&reference);
    let mut far: Vec<(f64, usize)> = out
        .mesh
        .positions
        .iter()
        .enumerate()
        .map(|(i, p)| (to_ref.closest_point(*p).distance, i))
        .collect();
    far.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!("output vertices farthest from the reference:");
    for (d, i) in far.iter().take(5) {
        let kind = if *i < input.positions.len() {
            if out.mesh.positions[*i] == input.positions[*i] {
                "input"
            } else {
                "moved input"
            }
        } else {
            "new"
        };
        println!(
            "  {i} ({kind}): {:.3}% at {:.4}",
            d / diag * 100.0,
            out.mesh.positions[*i]
        );
    }
    // Reference crease points (edges of the reference) farthest from the output.
    let to_out = Bvh::new(&out.mesh);
    let step = input.mean_edge_length() * 0.05;
    let mut samples: Vec<(f64, glam::DVec3)> = Vec::new();
    for [a, b] in reference.undirected_edges() {
        let (a, b) = (
            reference.positions[a as usize],
            reference.positions[b as usize],
        );
        let n = ((a - b).length() / step).ceil().clamp(1.0, 1e4) as usize;
        for i in 0..=n {
            let p = a + (b - a) * (i as f64 / n as f64);
            samples.push((to_out.closest_point(p).distance, p));
        }
    }
    samples.sort_by(|x, y| y.0.total_cmp(&x.0));
    println!("reference edge points farthest from the output (distinct places):");
    let mut shown: Vec<glam::DVec3> = Vec::new();
    for (d, p) in samples {
        if shown.iter().any(|q| q.distance(p) < 40.0 * step) {
            continue;
        }
        let corner = reference
            .positions
            .iter()
            .map(|c| c.distance(p))
            .fold(f64::INFINITY, f64::min);
        println!(
            "  {:.3}% at {p:.3}, {:.1} edge lengths from a reference vertex",
            d / diag * 100.0,
            corner / (20.0 * step)
        );
        shown.push(p);
        if shown.len() >= 8 {
            break;
        }
    }
}
