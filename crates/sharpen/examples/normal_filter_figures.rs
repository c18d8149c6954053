//! The normal-filter figures of docs/results.md ("Normal-filter sharpener"): Metro error to the
//! sharp `box` truth before and after sharpening, for the normal filter and both EdgeSharpener
//! methods, on the issue's inputs: the synth `blend` (its exact mesh and marching-cubes
//! samplings with the fillet 2-4 sampling steps wide), marching-cubes samplings of `box`
//! (chamfered), and the same with `--noise 0.3`.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example normal_filter_figures
//! SHARPEN_FIGURES_SAMPLES=200000 cargo run ...   # fewer Metro samples, for quick iterations
//! SHARPEN_FIGURES_ONLY=noise cargo run ...        # only the rows whose label contains "noise"
//! ```
//!
//! Errors are symmetric Metro figures (whet-metro, default sampling unless the variable is set)
//! in percent of the truth's bounding-box diagonal. "flip": output triangles facing against
//! the input triangle they come from (`parents`), plus (after the slash) triangles with a moved
//! vertex facing against the truth surface they lie on (`support::check`, as for
//! EdgeSharpener); "ok" means an oriented manifold with the input's boundary edge count.
//! "refused": the method returned its non-uniform-sampling error (the exact blend mesh).

mod support;

use std::time::Instant;

use glam::DQuat;
use whet_mesh::Mesh;
use whet_sharpen::{sharpen, Method, SharpenOptions, Sharpened};
use whet_synth::{add_noise, marching_cubes, Shape, ShapeKind, ShapeParams};

use support::{check, error, rotations};

fn samples() -> Option<usize> {
    std::env::var("SHARPEN_FIGURES_SAMPLES")
        .ok()
        .and_then(|s| s.parse().ok())
}

/// One input of the table.
pub struct Case {
    pub label: String,
    pub input: Mesh,
    pub truth: Mesh,
}

fn shape(kind: ShapeKind, radius: Option<f64>, rot: DQuat) -> Shape {
    let mut p = ShapeParams::default().with_rotation(rot);
    if let Some(r) = radius {
        p = p.with_radius(r);
    }
    Shape::new(kind, &p).unwrap_or_else(|e| panic!("{e}"))
}

/// The issue's inputs.
pub fn cases() -> Vec<Case> {
    let rots = rotations();
    let mut v = Vec::new();
    for (ri, &rot) in rots.iter().enumerate() {
        let truth = shape(ShapeKind::Box, None, rot).truth_mesh();
        // Blend, exact mesh: fillet radius 0.04 (default) and 0.06.
        for r in [0.04, 0.06] {
            v.push(Case {
                label: format!("blend r={r} exact r{ri}"),
                input: shape(ShapeKind::Blend, Some(r), rot).truth_mesh(),
                truth: truth.clone(),
            });
        }
        // Blend, marching cubes: radius in sampling steps (1/resolution).
        for (r, res) in [(0.04, 64), (0.04, 96), (0.06, 64)] {
            let s = shape(ShapeKind::Blend, Some(r), rot);
            v.push(Case {
                label: format!("blend r={r} mc {res} ({:.1} steps) r{ri}", r * res as f64),
                input: marching_cubes(&s, res).unwrap_or_else(|e| panic!("{e}")),
                truth: truth.clone(),
            });
        }
        let b = shape(ShapeKind::Box, None, rot);
        for res in [32, 64] {
            v.push(Case {
                label: format!("box mc {res} (chamfered) r{ri}"),
                input: marching_cubes(&b, res).unwrap_or_else(|e| panic!("{e}")),
                truth: truth.clone(),
            });
        }
        for res in [32, 64] {
            let mc = marching_cubes(&b, res).unwrap_or_else(|e| panic!("{e}"));
            v.push(Case {
                label: format!("box mc {res} noise 0.3 r{ri}"),
                input: add_noise(&mc, 0.3, 7),
                truth: truth.clone(),
            });
        }
    }
    v
}

/// Output triangles facing against their input parent.
pub fn flipped_against_parents(input: &Mesh, out: &Sharpened) -> usize {
    let n_in = input.face_normals();
    (0..out.mesh.triangles.len())
        .filter(|&t| out.mesh.face_cross(t).dot(n_in[out.parents[t].index()]) <= 0.0)
        .count()
}

fn main() {
    let methods = [
        (
            "normal-filter",
            SharpenOptions::DEFAULT.with_method(Method::NormalFilter),
        ),
        ("extended", SharpenOptions::DEFAULT),
        ("papers", SharpenOptions::PAPERS),
    ];
    print!("| input | F | RMS % | max % |");
    for (name, _) in &methods {
        print!(" {name} RMS % | max % | RMS gain | flip | ms |");
    }
    println!();
    println!(
        "|---|---|---|---|{}",
        "---|---|---|---|---|".repeat(methods.len())
    );
    let only = std::env::var("SHARPEN_FIGURES_ONLY").unwrap_or_default();
    for case in cases().into_iter().filter(|c| c.label.contains(&only)) {
        let e0 = error(&case.truth, &case.input, samples());
        let mut line = format!(
            "| {} | {} | {:.4} | {:.3} |",
            case.label,
            case.input.triangles.len(),
            e0.rms_pct,
            e0.max_pct
        );
        for (_, opts) in &methods {
            let t = Instant::now();
            let out = match sharpen(&case.input, opts) {
                Ok(out) => out,
                // The normal filter refuses non-uniform samplings (the exact blend mesh).
                Err(whet_sharpen::Error::Parameter(e)) if e.contains("uniform sampling") => {
                    line += " refused | | | | |";
                    continue;
                }
                Err(e) => panic!("{}: {e}", case.label),
            };
            let ms = t.elapsed().as_secs_f64() * 1e3;
            let e = error(&case.truth, &out.mesh, samples());
            let c = check(&case.truth, &case.input, &out);
            let ok = c.manifold && c.new_boundary_edges == 0;
            line += &format!(
                " {:.4} | {:.3} | {:.2}x | {}/{}{} | {ms:.0} |",
                e.rms_pct,
                e.max_pct,
                e0.rms_pct / e.rms_pct,
                flipped_against_parents(&case.input, &out),
                c.reversed,
                if ok { "" } else { " NOT MANIFOLD" },
            );
        }
        println!("{line}");
    }
}
