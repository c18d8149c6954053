//! The figures of docs/results.md "Subdivision fitting".
//!
//! ```text
//! cargo run --release -p whet-subdiv --features figures --example figures -- table1
//! RAYON_NUM_THREADS=1 cargo run --release -p whet-subdiv --features figures --example figures -- time
//! cargo run --release -p whet-subdiv --features figures --example figures -- solver
//! cargo run --release -p whet-subdiv --features figures --example figures -- rd [OUT.svg]
//! ```
//!
//! Errors are in percent of the input's bounding-box diagonal (symmetric Metro, 300k face
//! samples per direction, seed 0) and, for Table 1, also absolute.

use std::error::Error;
use std::time::Instant;
use whet_codec::DecodeOptions;
use whet_mesh::{DVec3, Mesh};
use whet_metro::{metro, MetroOptions};
use whet_subdiv::{
    decode_subdiv, encode_control, fit, subdivide, FitOptions, SharpnessMode, SharpnessSolver,
    SubdivOptions,
};

type Res<T = ()> = Result<T, Box<dyn Error>>;

fn load(name: &str) -> Res<Mesh> {
    Ok(whet_io::read_path(
        &whet_testkit::shared_fixture(name),
        None,
    )?)
}

fn surface(f: &whet_subdiv::Fitted, levels: u32) -> Res<Mesh> {
    Ok(subdivide(
        &f.control,
        &f.sharpness,
        &SubdivOptions::DEFAULT
            .with_levels(levels)
            .with_sharp_levels(levels),
    )?)
}

fn measure(reference: &Mesh, test: &Mesh) -> Res<whet_metro::MetroReport> {
    Ok(metro(
        reference,
        test,
        &MetroOptions::DEFAULT.with_samples(300_000),
    )?)
}

/// The paper's noise: Gaussian of sigma 0.1 le per coordinate on every vertex, plus 10 %
/// of the vertices moved by 0.5 le along their normal, either way (le: mean edge length).
fn noisy(mesh: &Mesh, seed: u64) -> Mesh {
    let le = mesh.mean_edge_length();
    let normals = mesh.vertex_normals();
    let mut rng = whet_metro::sampling::SplitMix64::new(seed);
    let mut gauss = || {
        let (u1, u2) = (rng.next_f64().max(1e-300), rng.next_f64());
        (-2.0 * u1.ln()).sqrt() * (2.0 * std::f64::consts::PI * u2).cos()
    };
    let mut out = mesh.clone();
    for p in out.positions.iter_mut() {
        *p += DVec3::new(gauss(), gauss(), gauss()) * 0.1 * le;
    }
    let mut rng = whet_metro::sampling::SplitMix64::new(seed ^ 0x9e37);
    for (v, p) in out.positions.iter_mut().enumerate() {
        if rng.next_f64() < 0.1 {
            let s = if rng.next_f64() < 0.5 { -0.5 } else { 0.5 };
            *p += normals[v] * s * le;
        }
    }
    out
}

fn table1() -> Res {
    println!(
        "| input | CP | surface | sharp edges | max % | RMS % | max (abs) | RMS (abs) | fit s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let cases: Vec<(&str, Mesh, Mesh, usize, u32)> = vec![
        (
            "rocker_arm",
            load("rocker_arm.off")?,
            load("rocker_arm.off")?,
            275,
            0,
        ),
        (
            "rocker_arm + noise (denoised)",
            load("rocker_arm.off")?,
            noisy(&load("rocker_arm.off")?, 1),
            275,
            2,
        ),
        (
            "fandisk",
            load("fandisk.off")?,
            load("fandisk.off")?,
            152,
            0,
        ),
        (
            "cad_cyl_fillet",
            load("cad_cyl_fillet.off")?,
            load("cad_cyl_fillet.off")?,
            150,
            0,
        ),
        (
            "screwdriver",
            load("screwdriver.off")?,
            load("screwdriver.off")?,
            200,
            0,
        ),
    ];
    for (name, clean, input, cp, denoise) in &cases {
        for mode in [
            SharpnessMode::Smooth,
            SharpnessMode::Crease,
            SharpnessMode::Continuous,
        ] {
            let opts = FitOptions::DEFAULT
                .with_control_vertices(*cp)
                .with_mode(mode)
                .with_denoise_iterations(*denoise);
            let t = Instant::now();
            let f = fit(input, &opts)?;
            let secs = t.elapsed().as_secs_f64();
            let s = surface(&f, opts.levels)?;
            // Against the clean model (the paper's ground truth).
            let r = measure(clean, &s)?;
            let label = match mode {
                SharpnessMode::Smooth => "Loop",
                SharpnessMode::Crease => "Hoppe creases",
                _ => "continuous (ours)",
            };
            println!(
                "| {name} | {} | {label} | {} | {:.3} | {:.4} | {:.5} | {:.6} | {:.1} |",
                f.control.positions.len(),
                f.report.sharp_edges,
                r.symmetric.max_pct,
                r.symmetric.rms_pct,
                r.symmetric.max,
                r.symmetric.rms,
                secs
            );
        }
    }
    Ok(())
}

fn time() -> Res {
    let m = load("rocker_arm.off")?;
    let threads = std::env::var("RAYON_NUM_THREADS").unwrap_or_else(|_| "all".into());
    for _ in 0..2 {
        let t = Instant::now();
        let f = fit(&m, &FitOptions::DEFAULT)?;
        println!(
            "rocker_arm 275 CP, threads {threads}: total {:.2} s (simplify {:.2} s, fit {:.2} s of which sharpness {:.2} s), {} outer iterations",
            t.elapsed().as_secs_f64(),
            f.report.simplify_ms / 1e3,
            f.report.fit_ms / 1e3,
            f.report.sharpness_ms / 1e3,
            f.report.iterations
        );
    }
    Ok(())
}

fn solver() -> Res {
    let m = load("rocker_arm.off")?;
    println!("| solver | iterations | sharpness s | fit s | h-objective after/before (mean) | max % | RMS % |");
    println!("|---|---|---|---|---|---|---|");
    for (solver, iters) in [
        (SharpnessSolver::CoordinateDescent, 12),
        (SharpnessSolver::ParticleSwarm, 12),
    ] {
        let opts = FitOptions::DEFAULT
            .with_solver(solver)
            .with_iterations(iters);
        let f = fit(&m, &opts)?;
        let ratio: f64 = f.report.h_objective.iter().map(|(b, a)| a / b).sum::<f64>()
            / f.report.h_objective.len().max(1) as f64;
        let r = measure(&m, &surface(&f, opts.levels)?)?;
        println!(
            "| {solver:?} | {iters} | {:.1} | {:.1} | {:.4} | {:.3} | {:.4} |",
            f.report.sharpness_ms / 1e3,
            f.report.fit_ms / 1e3,
            ratio,
            r.symmetric.max_pct,
            r.symmetric.rms_pct
        );
    }
    Ok(())
}

/// Bytes of the whole subdiv container with the proposed tags (field 12 `subdiv_levels`,
/// sections 6 `control` and 8 `sharpness`). whet-format 1.0 refuses to write tags it does not
/// know yet, so this builds the same layout with known tags of the same varint length
/// (field 4, sections 2 and 4): the byte count is identical.
fn container_bytes(p: &whet_subdiv::SubdivPayloads) -> Res<usize> {
    use whet_format::{tag, Container, Header, Mode, SectionKind};
    let header = Header::new(
        Mode::Subdiv,
        p.report.decoded_vertices,
        p.report.decoded_triangles,
    )
    .with(tag::QUANT_BITS, p.levels as u64);
    Ok(Container::new(header)
        .with_section(SectionKind::CONNECTIVITY, p.control.clone())
        .with_section(SectionKind::GEOMETRY, p.sharpness.clone())
        .to_bytes()?
        .len())
}

fn rd(svg: Option<&str>) -> Res {
    let meshes = ["spot.off", "bunny.off", "rocker_arm.off", "fandisk.off"];
    let mut curves: Vec<(String, Vec<(f64, f64)>)> = Vec::new();
    println!("| mesh | mode | parameter | bytes | bits/orig. vertex | max % | RMS % | encode s |");
    println!("|---|---|---|---|---|---|---|---|");
    for name in meshes {
        let m = load(name)?;
        let nv = m.positions.len() as f64;
        let short = name.trim_end_matches(".off");
        let mut sub = Vec::new();
        for cp in [60, 120, 250, 500] {
            let t = Instant::now();
            let opts = FitOptions::DEFAULT.with_control_vertices(cp);
            let f = fit(&m, &opts)?;
            let p = encode_control(&f.control, &f.sharpness, opts.levels, opts.levels, 12, 3)?;
            let secs = t.elapsed().as_secs_f64();
            let bytes = container_bytes(&p)?;
            let decoded =
                decode_subdiv(&p.control, &p.sharpness, p.levels, &DecodeOptions::DEFAULT)?;
            let r = measure(&m, &decoded)?;
            println!(
                "| {short} | subdiv | {cp} CP | {bytes} | {:.3} | {:.3} | {:.4} | {:.1} |",
                bytes as f64 * 8.0 / nv,
                r.symmetric.max_pct,
                r.symmetric.rms_pct,
                secs
            );
            sub.push((bytes as f64 * 8.0 / nv, r.symmetric.rms_pct));
        }
        let mut sw = Vec::new();
        for l in [0.06, 0.04, 0.03, 0.02, 0.015] {
            let t = Instant::now();
            let out = match whet_swing::encode(
                &m,
                &whet_swing::SwingOptions::DEFAULT.with_rate(whet_swing::Rate::EdgeLength(l)),
            ) {
                Ok(o) => o,
                Err(e) => {
                    println!("| {short} | swing | L = {l} | failed: {e} | | | | |");
                    continue;
                }
            };
            let secs = t.elapsed().as_secs_f64();
            let decoded = whet_codec::decode(&out.bytes, &DecodeOptions::DEFAULT)?;
            let r = measure(&m, &decoded)?;
            println!(
                "| {short} | swing | L = {l} diag | {} | {:.3} | {:.3} | {:.4} | {:.1} |",
                out.bytes.len(),
                out.bytes.len() as f64 * 8.0 / nv,
                r.symmetric.max_pct,
                r.symmetric.rms_pct,
                secs
            );
            sw.push((out.bytes.len() as f64 * 8.0 / nv, r.symmetric.rms_pct));
        }
        curves.push((format!("{short} subdiv"), sub));
        curves.push((format!("{short} swing"), sw));
    }
    if let Some(path) = svg {
        std::fs::write(path, plot(&curves))?;
        println!("wrote {path}");
    }
    Ok(())
}

/// A log-log plot of RMS error against bits per original vertex, one panel per mesh.
fn plot(curves: &[(String, Vec<(f64, f64)>)]) -> String {
    let (pw, ph, margin) = (300.0, 240.0, 50.0);
    let panels = curves.len() / 2;
    let width = panels as f64 * (pw + margin) + margin;
    let height = ph + 2.0 * margin;
    let mut s = format!(
        "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{width}\" height=\"{height}\" font-family=\"sans-serif\" font-size=\"11\">\n<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
    );
    for k in 0..panels {
        let pair = &curves[2 * k..2 * k + 2];
        let pts: Vec<(f64, f64)> = pair.iter().flat_map(|c| c.1.iter().copied()).collect();
        if pts.is_empty() {
            continue;
        }
        let lx = |x: f64| x.max(1e-6).log10();
        let (x0, x1) = pts.iter().fold((f64::MAX, f64::MIN), |a, p| {
            (a.0.min(lx(p.0)), a.1.max(lx(p.0)))
        });
        let (y0, y1) = pts.iter().fold((f64::MAX, f64::MIN), |a, p| {
            (a.0.min(lx(p.1)), a.1.max(lx(p.1)))
        });
        let (x0, x1, y0, y1) = (x0 - 0.05, x1 + 0.05, y0 - 0.05, y1 + 0.05);
        let ox = margin + k as f64 * (pw + margin);
        let oy = margin;
        let map = |p: (f64, f64)| {
            (
                ox + (lx(p.0) - x0) / (x1 - x0) * pw,
                oy + ph - (lx(p.1) - y0) / (y1 - y0) * ph,
            )
        };
        s += &format!("<rect x=\"{ox}\" y=\"{oy}\" width=\"{pw}\" height=\"{ph}\" fill=\"none\" stroke=\"black\"/>\n");
        let title = pair[0].0.trim_end_matches(" subdiv");
        s += &format!("<text x=\"{}\" y=\"{}\" text-anchor=\"middle\">{title}: RMS % diag vs bits/orig. vertex (log-log)</text>\n", ox + pw / 2.0, oy - 8.0);
        s += &format!("<text x=\"{ox}\" y=\"{}\">{:.2}</text><text x=\"{}\" y=\"{}\" text-anchor=\"end\">{:.2}</text>\n", oy + ph + 14.0, 10f64.powf(x0), ox + pw, oy + ph + 14.0, 10f64.powf(x1));
        s += &format!("<text x=\"{}\" y=\"{}\" text-anchor=\"end\">{:.3}</text><text x=\"{}\" y=\"{}\" text-anchor=\"end\">{:.3}</text>\n", ox - 3.0, oy + ph, 10f64.powf(y0), ox - 3.0, oy + 10.0, 10f64.powf(y1));
        for (c, colour) in pair.iter().zip(["#d62728", "#1f77b4"]) {
            let mut pts = c.1.clone();
            pts.sort_by(|a, b| a.0.total_cmp(&b.0));
            let path: Vec<String> = pts
                .iter()
                .map(|&p| {
                    let (x, y) = map(p);
                    format!("{x:.1},{y:.1}")
                })
                .collect();
            s += &format!(
                "<polyline points=\"{}\" fill=\"none\" stroke=\"{colour}\" stroke-width=\"2\"/>\n",
                path.join(" ")
            );
            for &p in &pts {
                let (x, y) = map(p);
                s += &format!("<circle cx=\"{x:.1}\" cy=\"{y:.1}\" r=\"3\" fill=\"{colour}\"/>\n");
            }
        }
        s += &format!("<text x=\"{}\" y=\"{}\" fill=\"#d62728\">subdiv</text><text x=\"{}\" y=\"{}\" fill=\"#1f77b4\">swing</text>\n", ox + pw - 60.0, oy + 16.0, ox + pw - 60.0, oy + 30.0);
    }
    s += "</svg>\n";
    s
}

fn main() -> Res {
    let args: Vec<String> = std::env::args().collect();
    match args.get(1).map(String::as_str) {
        Some("table1") => table1(),
        Some("time") => time(),
        Some("solver") => solver(),
        Some("rd") => rd(args.get(2).map(String::as_str)),
        _ => Err("usage: figures table1 | time | solver | rd [OUT.svg]".into()),
    }
}
