//! `whet demo`: the main job on a mesh whet makes itself — the synthetic fandisk, densely
//! tessellated with its creases exact, swept through the codec at a default set of rates.

use super::rd::{check_samples, run_plan, Plan, DEFAULT_SWING_RATES};
use super::{write_mesh, CliResult, Failure};
use clap::Args;
use std::path::PathBuf;
use whet_synth::{jitter_within_surface, midpoint_subdivide, Shape, ShapeKind, ShapeParams};

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder (the mesh, rd.csv, rd.json, rd.md and the plot).
    #[arg(long, default_value = "whet-demo")]
    out: PathBuf,
    /// Metro face samples per direction.
    #[arg(long, default_value_t = 300_000)]
    samples: usize,
}

pub fn run(args: &DemoArgs) -> CliResult {
    // Before the mesh is written.
    check_samples(args.samples)?;
    let shape = Shape::new(ShapeKind::Fandisk, &ShapeParams::default())
        .map_err(|e| Failure::other(anyhow::Error::new(e)))?;
    // 674 truth triangles x 4^3 = 43k triangles, each vertex then jittered within its facet
    // or along its crease: the surface stays exact, the tessellation is as irregular as a
    // real mesher's (a plain subdivision grid would flatter the parallelogram predictor).
    let original = jitter_within_surface(&midpoint_subdivide(shape.truth_mesh_ref(), 3), 0.3, 1);
    std::fs::create_dir_all(&args.out).map_err(|e| {
        Failure::other(
            anyhow::Error::new(e).context(format!("cannot create {}", args.out.display())),
        )
    })?;
    let mesh_path = args.out.join("synth-fandisk.off");
    write_mesh(
        &mesh_path,
        &original,
        None,
        &whet::io::WriteOptions::DEFAULT,
    )?;
    eprintln!(
        "whet demo: synthetic fandisk, {} vertices, {} triangles -> {}",
        original.positions.len(),
        original.triangles.len(),
        mesh_path.display()
    );
    let plan = Plan {
        // swing is the main codec; exact (Draco's job) is the baseline curve.
        modes: vec!["swing".into(), "exact".into()],
        rates: DEFAULT_SWING_RATES.to_vec(),
        angle_bits: super::encode::AngleBits::Auto,
        exact_bits: vec![6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 14.0],
        subdiv_control: vec![100.0, 200.0, 400.0],
        stages: vec!["decoded".into(), "sharpened".into(), "bent".into()],
        // The baseline is dense and already sharp: sharpening and Bender are for retilings.
        exact_stages: Some(vec!["decoded".into()]),
        out: args.out.clone(),
        samples: args.samples,
        seed: 0,
        draco: None,
    };
    let (_, md) = run_plan(vec![("synth-fandisk".into(), original)], &plan)?;
    out!("{md}");
    eprintln!(
        "plot: {}  tables: {}/rd.csv, rd.json, rd.md",
        args.out.join("synth-fandisk.svg").display(),
        args.out.display()
    );
    Ok(())
}
