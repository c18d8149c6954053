//! Where the error of one or more meshes sits relative to the creases of a reference: area
//! samples of the reference, binned by their distance to its nearest crease (an edge whose
//! triangles turn by more than 30 degrees) in mean edge lengths of the first mesh, with the
//! squared distance to each mesh summed per bin; then the creases around which the last mesh
//! keeps the most squared error (samples within half an edge of them).
//!
//! ```text
//! whet decode s.whet --no-surface-filter -o in.off
//! whet decode s.whet --sharpen -o out.off
//! cargo run --release -p whet-sharpen --example crease_error -- partLp.off in.off out.off [creases]
//! ```
//!
//! A name that is not an existing file is a shared fixture's. One direction only (reference to mesh),
//! 300 000 samples with a fixed seed; the crease search is brute force (fine for fixtures
//! with a few thousand crease edges). `[creases]`: how many crease edges to list (20).

use std::path::Path;

use whet_mesh::{DVec3, Mesh};
use whet_metro::sampling::{uniform_in_triangle, SplitMix64};
use whet_metro::{closest_point_on_segment, Bvh};

const SAMPLES: usize = 300_000;
const CREASE_DEGREES: f64 = 30.0;
/// Upper ends of the distance bins, in mean edge lengths.
const BINS: [f64; 7] = [0.25, 0.5, 1.0, 1.5, 2.0, 3.0, f64::INFINITY];

fn read(p: &str) -> Mesh {
    let path = if Path::new(p).exists() {
        Path::new(p).to_path_buf()
    } else {
        whet_testkit::shared_fixture(p)
    };
    whet_io::read_path(&path, None).unwrap_or_else(|e| panic!("{p}: {e}"))
}

fn mean_edge(m: &Mesh) -> f64 {
    let mut sum = 0.0;
    for t in &m.triangles {
        for k in 0..3 {
            sum += m.positions[t[k] as usize].distance(m.positions[t[(k + 1) % 3] as usize]);
        }
    }
    sum / (3 * m.triangles.len()).max(1) as f64
}

/// The reference's crease edges (two triangles turning by more than [`CREASE_DEGREES`]) and
/// their turns in degrees.
fn creases(r: &Mesh) -> Vec<(DVec3, DVec3, f64)> {
    let mut faces: std::collections::HashMap<(u32, u32), Vec<usize>> = Default::default();
    for (f, t) in r.triangles.iter().enumerate() {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            faces.entry((u.min(v), u.max(v))).or_default().push(f);
        }
    }
    let normal = |f: usize| r.face_normal(f);
    let mut out = Vec::new();
    for ((u, v), fs) in faces {
        if let [a, b] = fs[..] {
            let turn = normal(a)
                .dot(normal(b))
                .clamp(-1.0, 1.0)
                .acos()
                .to_degrees();
            if turn > CREASE_DEGREES {
                out.push((r.positions[u as usize], r.positions[v as usize], turn));
            }
        }
    }
    // HashMap order is not deterministic; the listing should be.
    out.sort_by(|a, b| {
        let key = |e: &(DVec3, DVec3, f64)| [e.0.x, e.0.y, e.0.z, e.1.x, e.1.y, e.1.z];
        key(a)
            .iter()
            .zip(key(b))
            .fold(std::cmp::Ordering::Equal, |o, (x, y)| {
                o.then(x.total_cmp(&y))
            })
    });
    out
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.len() < 2 {
        eprintln!("usage: crease_error <reference> <mesh>... [creases to list]");
        std::process::exit(2);
    }
    let (list, names) = match args.last().and_then(|a| a.parse::<usize>().ok()) {
        Some(n) => (n, &args[1..args.len() - 1]),
        None => (20, &args[1..]),
    };
    let reference = read(&args[0]);
    let meshes: Vec<Mesh> = names.iter().map(|p| read(p)).collect();
    let diag = reference.diagonal();
    let edge = mean_edge(&meshes[0]);
    let creases = creases(&reference);
    let bvhs: Vec<Bvh> = meshes.iter().map(Bvh::new).collect();
    let mut cumulative = Vec::with_capacity(reference.triangles.len());
    let mut area = 0.0;
    for f in 0..reference.triangles.len() {
        area += 0.5 * reference.face_cross(f).length();
        cumulative.push(area);
    }
    let mut rng = SplitMix64::new(3);
    let mut per_bin = vec![vec![0.0f64; BINS.len()]; meshes.len()];
    let mut per_crease = vec![vec![0.0f64; creases.len()]; meshes.len()];
    let mut in_bin = [0usize; BINS.len()];
    for _ in 0..SAMPLES {
        let x = rng.next_f64() * area;
        let f = cumulative
            .partition_point(|c| *c < x)
            .min(cumulative.len() - 1);
        let t = reference.triangles[f];
        let [a, b, c] = t.map(|v| reference.positions[v as usize]);
        let p = uniform_in_triangle(a, b, c, rng.next_f64(), rng.next_f64());
        let (nearest, d) = creases
            .iter()
            .enumerate()
            .map(|(i, (u, v, _))| (i, p.distance(closest_point_on_segment(p, *u, *v))))
            .fold(
                (usize::MAX, f64::INFINITY),
                |x, y| if y.1 < x.1 { y } else { x },
            );
        let d = d / edge;
        let bin = BINS.iter().position(|hi| d < *hi).unwrap_or(BINS.len() - 1);
        in_bin[bin] += 1;
        for (m, bvh) in bvhs.iter().enumerate() {
            let e2 = bvh.closest_point(p).distance.powi(2);
            per_bin[m][bin] += e2;
            if d < 0.5 && nearest != usize::MAX {
                per_crease[m][nearest] += e2;
            }
        }
    }
    println!(
        "mean edge {edge:.4} ({:.3} % of the diagonal), {} crease edges; per mesh: RMS % of \
         the bin's samples over all samples, share of the squared error",
        100.0 * edge / diag,
        creases.len()
    );
    let rms = |sum: f64| 100.0 * (sum / SAMPLES as f64).sqrt() / diag;
    for (bin, hi) in BINS.iter().enumerate() {
        print!(
            "under {hi:4} edges: area {:5.1} %",
            100.0 * in_bin[bin] as f64 / SAMPLES as f64
        );
        for sums in &per_bin {
            let total: f64 = sums.iter().sum();
            print!(
                " | {:.4} % {:5.1} %",
                rms(sums[bin]),
                100.0 * sums[bin] / total
            );
        }
        println!();
    }
    for (m, sums) in per_bin.iter().enumerate() {
        println!("{}: RMS {:.4} %", names[m], rms(sums.iter().sum()));
    }
    let last = meshes.len() - 1;
    let total: Vec<f64> = per_bin.iter().map(|s| s.iter().sum()).collect();
    let mut order: Vec<usize> = (0..creases.len()).collect();
    order.sort_by(|x, y| per_crease[last][*y].total_cmp(&per_crease[last][*x]));
    println!(
        "creases holding the most of {}'s squared error (share per mesh):",
        names[last]
    );
    for &c in order.iter().take(list) {
        let (a, b, turn) = creases[c];
        print!(
            "  [{:.3}, {:.3}, {:.3}]-[{:.3}, {:.3}, {:.3}] turn {turn:5.1}:",
            a.x, a.y, a.z, b.x, b.y, b.z
        );
        for (m, per) in per_crease.iter().enumerate() {
            print!(" {:.2} %", 100.0 * per[c] / total[m]);
        }
        println!();
    }
}
