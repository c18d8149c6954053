//! `whet demo`: the main job on a mesh whet makes itself — the synthetic fandisk, densely
//! tessellated with its creases exact, swept through the codec at a default set of rates.

use super::rd::{run_plan, Plan};
use super::{write_mesh, CliResult, Failure};
use clap::Args;
use std::path::PathBuf;
use whet::Mesh;
use whet_rd::to_markdown;
use whet_synth::{Shape, ShapeKind, ShapeParams};

#[derive(Args, Debug)]
pub struct DemoArgs {
    /// Output folder (the mesh, rd.csv, rd.json, rd.md and the plot).
    #[arg(long, default_value = "whet-demo")]
    out: PathBuf,
    /// Metro face samples per direction.
    #[arg(long, default_value_t = 300_000)]
    samples: usize,
}

/// Splits every triangle into four at its edge midpoints (shared midpoints), `levels` times:
/// the surface is unchanged, so creases stay exact.
fn midpoint_subdivide(mesh: &Mesh, levels: u32) -> Mesh {
    let mut m = mesh.clone();
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut tris = Vec::with_capacity(m.triangles.len() * 4);
        let mut pos = m.positions.clone();
        let mut midpoint = |a: u32, b: u32, pos: &mut Vec<whet::DVec3>| -> u32 {
            *mid.entry((a.min(b), a.max(b))).or_insert_with(|| {
                pos.push((pos[a as usize] + pos[b as usize]) * 0.5);
                (pos.len() - 1) as u32
            })
        };
        for &[a, b, c] in &m.triangles {
            let ab = midpoint(a, b, &mut pos);
            let bc = midpoint(b, c, &mut pos);
            let ca = midpoint(c, a, &mut pos);
            tris.extend_from_slice(&[[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]);
        }
        m = Mesh::new(pos, tris);
    }
    m
}

pub fn run(args: &DemoArgs) -> CliResult {
    let shape = Shape::new(ShapeKind::Fandisk, &ShapeParams::default())
        .map_err(|e| Failure::other(anyhow::Error::new(e)))?;
    // 674 truth triangles x 4^3 = 43k triangles.
    let original = midpoint_subdivide(shape.truth_mesh_ref(), 3);
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
        modes: vec!["exact".into()],
        rates: None,
        exact_bits: vec![6.0, 7.0, 8.0, 9.0, 10.0, 11.0, 12.0, 14.0],
        subdiv_control: vec![100.0, 200.0, 400.0],
        stages: vec!["decoded".into(), "sharpened".into()],
        out: args.out.clone(),
        samples: args.samples,
        seed: 0,
        draco: None,
    };
    let points = run_plan(vec![("synth-fandisk".into(), original)], &plan)?;
    out!("{}", to_markdown(&points));
    eprintln!(
        "plot: {}  tables: {}/rd.csv, rd.json, rd.md",
        args.out.join("synth-fandisk.svg").display(),
        args.out.display()
    );
    Ok(())
}
