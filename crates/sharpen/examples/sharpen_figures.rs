//! The EdgeSharpener figures of docs/results.md: Metro error before and after sharpening, for
//! both methods, on marching-cubes samplings of the synth shapes and on stand-in retilings of
//! the CAD fixtures.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example sharpen_figures            # everything
//! cargo run --release -p whet-sharpen --example sharpen_figures -- synth   # marching cubes only
//! cargo run --release -p whet-sharpen --example sharpen_figures -- retile  # fixtures only
//! cargo run --release -p whet-sharpen --example sharpen_figures -- synth 2 # two passes
//! cargo run --release -p whet-sharpen --example sharpen_figures -- noise   # noise sweep
//! cargo run --release -p whet-sharpen --example sharpen_figures -- swing   # swing-decoded
//! cargo run --release -p whet-sharpen --example sharpen_figures -- swing rocker  # one fixture
//! cargo run --release -p whet-sharpen --example sharpen_figures -- swing-synth  # synth shapes
//! ```
//!
//! `swing` encodes the CAD fixtures with whet-swing at three rates per fixture (about 0.5x, 1x
//! and 2x the fixture's vertex count at 6 angle bits: `swing_inputs::SWING_FIXTURES`), once with 6 angle bits
//! and once with `--angle-bits auto`, both `--optimize-for sharpened`, decodes them with
//! whet-codec (`examples/swing_inputs`) and sharpens the decoded meshes with both methods; its
//! last columns are what `whet decode --sharpen` writes: the sharpening the stream names (the
//! encoder's measured choice, docs/swing.md section 2) and the stream's filter for after
//! sharpening, or the filtered decoded mesh for "none", against the same input error. `retile`
//! is the marching-cubes stand-in measured before the swing codec existed. `swing-synth`
//! encodes the synth truth shapes the same way, at three edge lengths (shapes no constant was
//! tuned on).
//!
//! Errors are symmetric Metro figures (whet-metro, default sampling: at least 10 samples per
//! face and 1M per direction) in percent of the reference's bounding-box diagonal; the
//! reference is the synth truth mesh or the original fixture. "reversed/new": new triangles
//! facing against the reference plane they lie on, over all new triangles
//! (`support::check`); a row is flagged INVALID if the output is not a manifold with the
//! input's boundary and no new angle under 1 degree, WORSE if RMS or max grew.

mod support;
mod swing_inputs;

use std::time::Instant;

use whet_codec::SharpenHint;
use whet_mesh::Mesh;
use whet_sharpen::{sharpen, Method, SharpenOptions};
use whet_synth::{add_noise, marching_cubes, Shape, ShapeKind, ShapeParams};

use support::{cached_stand_in, check, error, rotations};
use swing_inputs::{swing_input, Angles};

/// Face samples per Metro direction: the default rule unless `SHARPEN_FIGURES_SAMPLES` is set
/// (for quick iterations; the tables in docs/results.md use the default).
fn samples() -> Option<usize> {
    std::env::var("SHARPEN_FIGURES_SAMPLES")
        .ok()
        .and_then(|s| s.parse().ok())
}

fn row(label: &str, reference: &Mesh, input: &Mesh) {
    println!("{}", row_line(label, reference, input).0);
}

/// One table row, and the `(RMS, max)` of the input and of each method's output (papers,
/// extended).
fn row_line(label: &str, reference: &Mesh, input: &Mesh) -> (String, [(f64, f64); 3]) {
    let e0 = error(reference, input, samples());
    let mut errors = [(e0.rms_pct, e0.max_pct); 3];
    let mut line = format!(
        "| {label} | {} | {:.4} | {:.3} |",
        input.positions.len(),
        e0.rms_pct,
        e0.max_pct
    );
    for (i, method) in [Method::Papers, Method::Extended].into_iter().enumerate() {
        let t = Instant::now();
        let opts = SharpenOptions::DEFAULT
            .with_method(method)
            .with_passes(passes());
        let out = sharpen(input, &opts).unwrap_or_else(|e| panic!("{label}: {e}"));
        let ms = t.elapsed().as_secs_f64() * 1e3;
        let e = error(reference, &out.mesh, samples());
        errors[i + 1] = (e.rms_pct, e.max_pct);
        let c = check(reference, input, &out);
        let valid = c.manifold && c.new_boundary_edges == 0 && c.min_new_angle >= 1.0 - 1e-9;
        let worse = e.rms_pct > e0.rms_pct * 1.0001 || e.max_pct > e0.max_pct * 1.0001;
        line += &format!(
            " {:.4} | {:.3} | {:.2}x | {:.2}x | {}/{}{}{} | {ms:.1} |",
            e.rms_pct,
            e.max_pct,
            e0.rms_pct / e.rms_pct,
            e0.max_pct / e.max_pct,
            c.reversed,
            c.new_triangles,
            if valid { "" } else { " INVALID" },
            if worse { " WORSE" } else { "" },
        );
    }
    (line, errors)
}

/// EdgeSharpener passes for the `synth` and `noise` tables: their optional second argument
/// (`synth 2`), else 1, the default.
fn passes() -> u32 {
    static PASSES: std::sync::OnceLock<u32> = std::sync::OnceLock::new();
    *PASSES.get_or_init(|| {
        let what = std::env::args().nth(1).unwrap_or_default();
        match std::env::args().nth(2) {
            Some(n) if what == "synth" || what == "noise" => n
                .parse()
                .unwrap_or_else(|_| panic!("{what} takes a number of passes, got {n:?}")),
            _ => 1,
        }
    })
}

fn header(first: &str) {
    println!(
        "| {first} | V | RMS % | max % | papers RMS % | max % | RMS gain | max gain | reversed/new | ms \
         | extended RMS % | max % | RMS gain | max gain | reversed/new | ms |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|");
}

fn synth() {
    println!("\n### Marching cubes of synth shapes (reference: the truth mesh)\n");
    if passes() != 1 {
        println!(
            "EdgeSharpener in {} passes (`SharpenOptions::passes`).\n",
            passes()
        );
    }
    header("shape, resolution, rotation");
    for kind in [ShapeKind::Cube, ShapeKind::Pyramid, ShapeKind::Fandisk] {
        for res in [32, 48, 64, 96, 128] {
            for (ri, q) in rotations().iter().enumerate() {
                let shape = Shape::new(kind, &ShapeParams::default().with_rotation(*q))
                    .unwrap_or_else(|e| panic!("{e}"));
                let input = marching_cubes(&shape, res).unwrap_or_else(|e| panic!("{e}"));
                row(
                    &format!("{} {res} r{ri}", kind.name()),
                    shape.truth_mesh_ref(),
                    &input,
                );
            }
        }
    }
}

fn retile(only: Option<String>) {
    println!("\n### Stand-in retilings of the fixtures (reference: the original fixture)\n");
    header("fixture, vertex ratio (grid)");
    for name in [
        "fandisk.off",
        "cad_box_hole.off",
        "cad_bracket.off",
        "cad_cyl_fillet.off",
        "block.off",
        "partLp.off",
        "joint.off",
    ] {
        if only.as_deref().is_some_and(|o| !name.starts_with(o)) {
            continue;
        }
        for ratio in [0.5, 1.0, 2.0] {
            let (original, input, res) = cached_stand_in(name, ratio);
            row(&format!("{name} {ratio}x ({res})"), &original, &input);
        }
    }
}

fn swing(only: Option<String>) {
    println!("\n### Swing-decoded fixtures (reference: the original fixture)\n");
    println!(
        "| fixture, bpv, angle bits (V ratio) | V | RMS % | max % | papers RMS % | max % | RMS gain \
         | max gain | reversed/new | ms | extended RMS % | max % | RMS gain | max gain | \
         reversed/new | ms | `decode --sharpen`: method | RMS % | max % | RMS gain | max gain |"
    );
    println!(
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"
    );
    for (name, rates) in swing_inputs::SWING_FIXTURES {
        if only.as_deref().is_some_and(|o| !name.starts_with(o)) {
            continue;
        }
        for angles in [Angles::Fixed(6), Angles::AutoSharpened] {
            for bpv in rates {
                let s = swing_input(name, bpv, angles);
                let ratio = s.decoded.positions.len() as f64 / s.original.positions.len() as f64;
                let bits = match angles {
                    Angles::Fixed(b) => b.to_string(),
                    Angles::AutoSharpened => format!("auto {}", s.angle_bits),
                };
                let (line, e) = row_line(
                    &format!("{name} {:.2} {bits} ({ratio:.2}x)", s.bpv),
                    &s.original,
                    &s.decoded,
                );
                // What `whet decode --sharpen` writes: the sharpening the stream names and
                // the stream's filter for after sharpening, or the filtered decoded mesh.
                let name = stated_name(&s);
                let d = error(&s.original, &s.decode_sharpen(), samples());
                println!(
                    "{line} {name} | {:.4} | {:.3} | {:.2}x | {:.2}x |",
                    d.rms_pct,
                    d.max_pct,
                    e[0].0 / d.rms_pct,
                    e[0].1 / d.max_pct
                );
            }
        }
    }
}

/// The sharpening a swing stream states, as the swing tables print it.
fn stated_name(s: &swing_inputs::SwingInput) -> String {
    match s.sharpen_hint {
        Some(SharpenHint::Unsharpened) => "none".to_string(),
        h => format!(
            "{} {}{}{}{}{}{}{}{}{}{}",
            h.map_or("extended", SharpenHint::name),
            s.smooth_factor,
            if s.gray_labels { " gray" } else { "" },
            match s.curved_walls {
                Some(w) => format!(" walls {w}"),
                None => String::new(),
            },
            if s.passes > 1 {
                format!(" x{}", s.passes)
            } else {
                String::new()
            },
            if s.planar { " + planes" } else { "" },
            if s.quadric { " + quadrics" } else { "" },
            if s.beside { " + beside" } else { "" },
            if s.crease { " + creases" } else { "" },
            if s.apex { " + apexes" } else { "" },
            if s.after_filter { "" } else { " − filter" }
        ),
    }
}

/// Shapes no constant was tuned on: the synth truth meshes (exact planes, cylinders and
/// cones; the blend's fillets and the sphere, which must not get worse; the r0 rotation of
/// the marching-cubes table, so no face is axis-aligned), swing encoded at three edge
/// lengths with 6 angle bits, and at those streams' sizes with automatic angle bits,
/// `--optimize-for sharpened`. Columns: the mesh `whet decode --sharpen` sharpens (no
/// surface filter), what `whet decode` writes (its surface filter applied), `whet sharpen`
/// with the defaults on the former, and `whet decode --sharpen`; gains over both decoded
/// meshes (docs/results.md, "Shapes no constant was tuned on").
fn swing_synth() {
    println!("\n### Swing-decoded synth shapes (reference: the truth mesh)\n");
    println!(
        "| shape, L, angle bits | V | unfiltered RMS % | max % | `whet decode` RMS % | max % \
         | `whet sharpen` RMS % | max % | `decode --sharpen`: method | RMS % | max % \
         | gain over unfiltered, RMS / max | gain over `whet decode`, RMS / max |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for (kind, l, angles, s) in swing_inputs::every_synth_swing_input(rotations()[0], "r0") {
        let bits = match angles {
            Angles::Fixed(b) => b.to_string(),
            Angles::AutoSharpened => format!("auto {}", s.angle_bits),
        };
        let u = error(&s.original, &s.decoded, samples());
        let p = error(&s.original, &s.plain(), samples());
        let extended =
            sharpen(&s.decoded, &SharpenOptions::DEFAULT).unwrap_or_else(|e| panic!("{e}"));
        let x = error(&s.original, &extended.mesh, samples());
        let d = error(&s.original, &s.decode_sharpen(), samples());
        println!(
            "| {} {l} {bits} | {} | {:.4} | {:.3} | {:.4} | {:.3} | {:.4} | {:.3} | {} \
             | {:.4} | {:.3} | {:.2}x / {:.2}x | {:.2}x / {:.2}x |",
            kind.name(),
            s.decoded.positions.len(),
            u.rms_pct,
            u.max_pct,
            p.rms_pct,
            p.max_pct,
            x.rms_pct,
            x.max_pct,
            stated_name(&s),
            d.rms_pct,
            d.max_pct,
            u.rms_pct / d.rms_pct,
            u.max_pct / d.max_pct,
            p.rms_pct / d.rms_pct,
            p.max_pct / d.max_pct,
        );
    }
}

fn noise() {
    println!("\n### Normal noise (percent of the longest edge) on marching cubes at 64\n");
    if passes() != 1 {
        println!(
            "EdgeSharpener in {} passes (`SharpenOptions::passes`).\n",
            passes()
        );
    }
    header("shape, noise");
    for kind in [ShapeKind::Cube, ShapeKind::Fandisk] {
        let shape = Shape::new(kind, &ShapeParams::default().with_rotation(rotations()[0]))
            .unwrap_or_else(|e| panic!("{e}"));
        let clean = marching_cubes(&shape, 64).unwrap_or_else(|e| panic!("{e}"));
        for amount in [0.0, 0.1, 0.25, 0.5, 1.0] {
            let input = add_noise(&clean, amount, 7);
            row(
                &format!("{} {:.0}%", kind.name(), amount * 100.0),
                shape.truth_mesh_ref(),
                &input,
            );
        }
    }
}

fn main() {
    let what = std::env::args().nth(1).unwrap_or_default();
    if what.is_empty() || what == "synth" {
        synth();
    }
    if what.is_empty() || what == "retile" {
        retile(std::env::args().nth(2));
    }
    if what.is_empty() || what == "noise" {
        noise();
    }
    if what.is_empty() || what == "swing" {
        swing(std::env::args().nth(2));
    }
    if what.is_empty() || what == "swing-synth" {
        swing_synth();
    }
}
