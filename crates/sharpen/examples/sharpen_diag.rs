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
//! A synth shape takes `<shape> <resolution> <rotation 0|1|2|3> <method>`; a shared fixture
//! (`*.off`) takes `<fixture> <vertex ratio> - <method>` and uses the stand-in retiling of
//! `support::cached_stand_in`, or `<fixture> <bpv> <angle bits|auto> <method>` and uses the
//! swing-decoded fixture of `swing_inputs::swing_input` (auto: optimised for sharpening).
//! Any mesh file (a path with a `/`) takes `<input> <reference> - <method>`.
//!
//! It also counts the near-coincident input vertex pairs (marching cubes' clusters, closer
//! than 5 % of the mean edge) around the three worst places, lists every boundary edge the
//! output gained, and with `DIAG_LOCAL=1` lists the input and output triangles around the worst
//! place (the angle of each to its nearest reference face, the distance of its vertices to the
//! reference, into how many pieces it was cut) and the vertices there in the frame of the two
//! nearest reference faces; `DIAG_V=<vertex>` prints that input vertex's input and output
//! positions; `DIAG_AT=x,y,z` dumps the neighbourhood of that point instead of the worst
//! place; `DIAG_NO_WELD=1` turns off the extended method's cluster welding (`--no-weld`);
//! `DIAG_PASSES=<n>` runs EdgeSharpener in that many passes (`--passes`);
//! `DIAG_SAMPLES=<n>` sets Metro's samples a direction (300k; `0`: the default of `sharpen_figures`);
//! `DIAG_ROT=x,y,z,angle` turns a synth shape about that axis by that many radians instead.

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
        // 0 and 1: the tables' generic rotations; 2: none (creases along the grid); 3: a
        // small turn (creases drift slowly across the grid).
        // `DIAG_ROT=x,y,z,angle` (radians) overrides the rotation argument.
        let custom = std::env::var("DIAG_ROT").ok().and_then(|s| {
            let v: Vec<f64> = s.split(',').filter_map(|x| x.trim().parse().ok()).collect();
            (v.len() == 4).then(|| {
                glam::DQuat::from_axis_angle(glam::DVec3::new(v[0], v[1], v[2]).normalize(), v[3])
            })
        });
        let rotation = custom.unwrap_or_else(|| match arg::<usize>(&args, 3, 0) {
            2 => glam::DQuat::IDENTITY,
            3 => glam::DQuat::from_axis_angle(glam::DVec3::new(0.3, 0.2, 1.0).normalize(), 0.05),
            r => support::rotations()[r.min(1)],
        });
        let params = ShapeParams::default().with_rotation(rotation);
        let shape = or_die(Shape::new(kind, &params), "shape");
        (
            shape.truth_mesh(),
            or_die(marching_cubes(&shape, res), "marching cubes"),
        )
    };
    let out = or_die(
        sharpen(
            &input,
            &SharpenOptions::DEFAULT
                .with_method(method)
                .with_weld_clusters(std::env::var_os("DIAG_NO_WELD").is_none())
                .with_passes(
                    std::env::var("DIAG_PASSES")
                        .ok()
                        .and_then(|p| p.parse().ok())
                        .unwrap_or(1),
                ),
        ),
        "sharpen",
    );
    println!("{}", out.report.to_json());
    if let Some(v) = std::env::var("DIAG_V")
        .ok()
        .and_then(|x| x.parse::<usize>().ok())
    {
        println!(
            "vertex {v}: input {:.5} output {:.5}",
            input.positions[v], out.mesh.positions[v]
        );
    }
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
    if c.new_boundary_edges != 0 {
        let mut count: std::collections::HashMap<(u32, u32), Vec<usize>> = Default::default();
        for (t, tri) in out.mesh.triangles.iter().enumerate() {
            for k in 0..3 {
                let (a, b) = (tri[k], tri[(k + 1) % 3]);
                count.entry((a.min(b), a.max(b))).or_default().push(t);
            }
        }
        for ((a, b), ts) in &count {
            if ts.len() == 1 {
                let t = ts[0];
                println!(
                    "boundary edge {a}-{b} of output t{t} {:?} from input t{} {:?}",
                    out.mesh.triangles[t],
                    out.parents[t],
                    input.triangles[out.parents[t].index()]
                );
            }
        }
    }
    // 300k samples a direction unless `DIAG_SAMPLES` says otherwise (`0`: Metro's default,
    // what `sharpen_figures` measures with).
    let opts = match std::env::var("DIAG_SAMPLES")
        .ok()
        .and_then(|s| s.parse().ok())
    {
        Some(0) => MetroOptions::DEFAULT,
        Some(n) => MetroOptions::DEFAULT.with_samples(n),
        None => MetroOptions::DEFAULT.with_samples(300_000),
    };
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
        "gains: RMS {:.3}x, max {:.3}x",
        before.symmetric.rms_pct / after.symmetric.rms_pct,
        before.symmetric.max_pct / after.symmetric.max_pct
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
    // Output faces farthest from the reference (the forward max can sit inside a face, away
    // from every vertex): each face sampled on a barycentric grid of step 1/8.
    let mut faces: Vec<(f64, usize, glam::DVec3)> = out
        .mesh
        .triangles
        .iter()
        .enumerate()
        .map(|(t, tri)| {
            let [a, b, c] = tri.map(|v| out.mesh.positions[v as usize]);
            let mut worst = (0.0f64, a);
            for i in 0..=8 {
                for j in 0..=8 - i {
                    let p = a + (b - a) * (i as f64 / 8.0) + (c - a) * (j as f64 / 8.0);
                    let d = to_ref.closest_point(p).distance;
                    if d > worst.0 {
                        worst = (d, p);
                    }
                }
            }
            (worst.0, t, worst.1)
        })
        .collect();
    faces.sort_by(|a, b| b.0.total_cmp(&a.0));
    println!("output faces farthest from the reference:");
    for (d, t, p) in faces.iter().take(4) {
        println!(
            "  t{t} (from {}) {:?}: {:.3}% at {p:.4}",
            out.parents[*t].index(),
            out.mesh.triangles[*t],
            d / diag * 100.0
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
    // Near-coincident input vertex pairs (marching cubes' clusters) around the worst places.
    let h = input.mean_edge_length();
    for p in shown.iter().take(3) {
        let near: Vec<glam::DVec3> = input
            .positions
            .iter()
            .copied()
            .filter(|q| q.distance(*p) < 2.0 * h)
            .collect();
        let mut pairs = 0;
        for i in 0..near.len() {
            for j in i + 1..near.len() {
                if near[i].distance(near[j]) < 0.05 * h {
                    pairs += 1;
                }
            }
        }
        println!("  cluster pairs within 2 edges of {p:.3}: {pairs}");
    }
    // `DIAG_AT=x,y,z` dumps around that point instead of the worst place.
    let at = std::env::var("DIAG_AT").ok().and_then(|s| {
        let v: Vec<f64> = s.split(',').filter_map(|x| x.trim().parse().ok()).collect();
        (v.len() == 3).then(|| glam::DVec3::new(v[0], v[1], v[2]))
    });
    if let Some(p) = at.or(shown.first().copied()) {
        local_dump(&reference, &input, &out, p);
    }
}

/// Input and output triangles around `p`: the angle of each normal to the nearest reference
/// triangle's, the distance of its vertices to the reference, and whether it was cut.
fn local_dump(
    reference: &whet_mesh::Mesh,
    input: &whet_mesh::Mesh,
    out: &whet_sharpen::Sharpened,
    p: glam::DVec3,
) {
    if std::env::var_os("DIAG_LOCAL").is_none() {
        return;
    }
    let to_ref = Bvh::new(reference);
    let diag = reference.diagonal();
    let radius = 2.5 * input.mean_edge_length();
    let describe = |m: &whet_mesh::Mesh, t: usize| {
        let tri = m.triangles[t];
        let c = (m.positions[tri[0] as usize]
            + m.positions[tri[1] as usize]
            + m.positions[tri[2] as usize])
            / 3.0;
        let hit = to_ref.closest_point(c);
        let rn = reference.face_normal(hit.triangle as usize);
        let ang = m.face_normal(t).angle_between(rn).to_degrees();
        let d: Vec<String> = tri
            .iter()
            .map(|&v| {
                format!(
                    "{}:{:.3}",
                    v,
                    to_ref.closest_point(m.positions[v as usize]).distance / diag * 100.0
                )
            })
            .collect();
        (c, ang, d)
    };
    let mut children = vec![0usize; input.triangles.len()];
    for f in &out.parents {
        children[f.index()] += 1;
    }
    println!(
        "input triangles within 2.5 edges of {p:.3} (angle to reference normal, vertex:dist%):"
    );
    for t in 0..input.triangles.len() {
        let (c, ang, d) = describe(input, t);
        if c.distance(p) < radius {
            println!(
                "  t{t} {ang:6.1} deg  {}  pieces {}",
                d.join(" "),
                children[t]
            );
        }
    }
    // The local frame: the two reference face normals nearest p, the crease direction.
    let near = |q: glam::DVec3| reference.face_normal(to_ref.closest_point(q).triangle as usize);
    let n0 = near(p);
    let mut n1 = n0;
    for t in 0..input.triangles.len() {
        let tri = input.triangles[t];
        for &v in &tri {
            let q = input.positions[v as usize];
            if q.distance(p) < radius {
                let n = near(q);
                if n.angle_between(n0) > n1.angle_between(n0) {
                    n1 = n;
                }
            }
        }
    }
    let e = n0.cross(n1).normalize_or_zero();
    let h = input.mean_edge_length();
    println!("frame: normals {n0:.3} {n1:.3} ({:.1} deg), edge {h:.4}; vertex: along, above plane 0, above plane 1 (edges)", n0.angle_between(n1).to_degrees());
    let apex = to_ref.closest_point(p).point;
    let mut seen = std::collections::BTreeSet::new();
    for tri in &input.triangles {
        for &v in tri {
            let q = input.positions[v as usize];
            if q.distance(p) < radius && seen.insert(v) {
                let d = q - apex;
                println!(
                    "  v{v}: {:6.2} {:6.2} {:6.2}",
                    d.dot(e) / h,
                    d.dot(n0) / h,
                    d.dot(n1) / h
                );
            }
        }
    }
    for (i, q) in out
        .mesh
        .positions
        .iter()
        .enumerate()
        .skip(input.positions.len())
    {
        if q.distance(p) < radius {
            let d = *q - apex;
            println!(
                "  new v{i}: {:6.2} {:6.2} {:6.2}",
                d.dot(e) / h,
                d.dot(n0) / h,
                d.dot(n1) / h
            );
        }
    }
    println!("output triangles there:");
    for t in 0..out.mesh.triangles.len() {
        let (c, ang, d) = describe(&out.mesh, t);
        if c.distance(p) < radius {
            println!(
                "  t{t} (from {}) {ang:6.1} deg  {}",
                out.parents[t],
                d.join(" ")
            );
        }
    }
}
