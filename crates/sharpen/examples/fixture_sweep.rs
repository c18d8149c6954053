//! "No case gets worse" on parts the synth shapes do not model: marching cubes of the signed
//! distance to the sharp shared fixtures (fandisk, block, cad_bracket, cad_box_hole,
//! cad_cyl_fillet, joint, partLp, sledge, sharp_sphere, cube), each turned by a random generic
//! rotation and sampled at a random resolution of 32 to 127 cells, sharpened and measured with
//! Metro against the turned fixture (50k samples a direction). The figure tables sample these
//! fixtures only in their own, mostly axis-aligned, orientation (`sharpen_figures retile`); a
//! part a user sends comes at any angle. A case whose RMS or max grew is measured again at
//! Metro's default sampling (1M samples a direction) and flagged WORSE if it still grew,
//! UNCONFIRMED if not (a max compared at 50k samples can flip by sampling alone); the last
//! line counts both.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example fixture_sweep -- [seed] [cases] [papers|extended] [fixture prefix]
//! ```
//!
//! Each line carries the rotation (axis and angle in radians) and the resolution, so a case
//! can be rebuilt; `FIXTURE_SWEEP_CASE=<i>` runs case `i` alone (the rotations and resolutions
//! are drawn for every case all the same) and `FIXTURE_SWEEP_WRITE=<dir>` writes each case's
//! turned fixture, input and output as OFF.
#![allow(clippy::unwrap_used)] // a measurement tool
mod support;
use glam::DQuat;
use whet_mesh::Mesh;
use whet_sharpen::{sharpen, SharpenOptions};
use whet_testkit::Lcg;

/// The shared fixtures whose creases are sharp (the organic scans and rocker_arm, whose
/// creases are blends, are left out: they are not what the sharpener is for).
const FIXTURES: [&str; 10] = [
    "fandisk.off",
    "block.off",
    "cad_bracket.off",
    "cad_box_hole.off",
    "cad_cyl_fillet.off",
    "joint.off",
    "partLp.off",
    "sledge.off",
    "sharp_sphere.off",
    "cube.off",
];

fn main() {
    let (seed, n, method, rest) = support::sweep_args(1, 20);
    let only = rest.first();
    let write_dir = std::env::var_os("FIXTURE_SWEEP_WRITE").map(std::path::PathBuf::from);
    let only_case: Option<usize> = std::env::var("FIXTURE_SWEEP_CASE")
        .ok()
        .and_then(|c| c.parse().ok());
    let names: Vec<&str> = FIXTURES
        .into_iter()
        .filter(|f| only.is_none_or(|o| f.starts_with(o.as_str())))
        .collect();
    let originals: Vec<Mesh> = names
        .iter()
        .map(|name| {
            whet_io::read_path(&whet_testkit::shared_fixture(name), None)
                .unwrap_or_else(|e| panic!("{name}: {e}"))
        })
        .collect();
    let mut rng = Lcg(seed);
    let mut worse = 0;
    let mut unconfirmed = 0;
    for i in 0..n {
        let k = i % names.len();
        let res = 32 + (rng.unit() * 96.0) as usize;
        let (axis, angle) = support::random_turn(&mut rng, 1.0);
        let q = DQuat::from_axis_angle(axis, angle);
        if only_case.is_some_and(|c| c != i) {
            continue;
        }
        let (truth, input) = match support::turned_sampling(&originals[k], q, res) {
            Ok(pair) => pair,
            Err(e) => {
                println!(
                    "FAILED {} res {res} case {i}: marching cubes: {e}",
                    names[k]
                );
                continue;
            }
        };
        let out = sharpen(&input, &SharpenOptions::DEFAULT.with_method(method)).unwrap();
        let b = support::error(&truth, &input, Some(50_000));
        let a = support::error(&truth, &out.mesh, Some(50_000));
        let verdict = support::sweep_verdict(&truth, &input, &out.mesh, &b, &a);
        worse += usize::from(verdict.worse);
        unconfirmed += usize::from(verdict.unconfirmed);
        if let Some(dir) = &write_dir {
            let stem = format!("{}-{res}-{i}", names[k].trim_end_matches(".off"));
            let opts = whet_io::WriteOptions::DEFAULT;
            whet_io::write_path(&dir.join(format!("{stem}-in.off")), &input, None, &opts).unwrap();
            whet_io::write_path(&dir.join(format!("{stem}-out.off")), &out.mesh, None, &opts)
                .unwrap();
            whet_io::write_path(&dir.join(format!("{stem}-truth.off")), &truth, None, &opts)
                .unwrap();
        }
        println!(
            "{}{} res {res} case {i} rot {},{},{},{}: {} triangles, RMS {:.4} -> {:.4} ({:.2}x), max {:.3} -> {:.3} ({:.2}x){}",
            verdict.flag(),
            names[k],
            axis.x,
            axis.y,
            axis.z,
            angle,
            input.triangles.len(),
            b.rms_pct,
            a.rms_pct,
            b.rms_pct / a.rms_pct,
            b.max_pct,
            a.max_pct,
            b.max_pct / a.max_pct,
            verdict.suffix
        );
    }
    println!("{worse} of {n} worse ({unconfirmed} more worse at 50k samples only)");
}
