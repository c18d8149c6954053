//! `whet synth`: ground-truth shapes and their feature-insensitive samplings.

use super::{write_mesh, CliResult, Failure};
use clap::Args;
use glam::{DQuat, DVec3};
use std::path::PathBuf;
use whet_synth::{add_noise, marching_cubes, Shape, ShapeKind, ShapeParams};

#[derive(Args, Debug)]
pub struct SynthArgs {
    /// Shape name (see --list).
    #[arg(required_unless_present = "list")]
    shape: Option<String>,
    /// Output: the shape's SDF sampled by marching cubes.
    #[arg(short, long, required_unless_present = "list")]
    output: Option<PathBuf>,
    /// Also write the exact ground-truth mesh here.
    #[arg(long)]
    truth: Option<PathBuf>,
    /// Marching-cubes cells along the longest axis.
    #[arg(long, default_value_t = 64)]
    resolution: usize,
    /// Displace vertices along their normals by uniform noise of this fraction of the
    /// maximum edge length.
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Seed of the noise.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Fillet radius of `blend`.
    #[arg(long)]
    radius: Option<f64>,
    /// Rotate the shape before sampling: "x,y,z,degrees" (axis and angle), so creases are not
    /// aligned with the grid.
    #[arg(long, value_name = "X,Y,Z,DEG")]
    rotate: Option<String>,
    /// List the shapes and exit.
    #[arg(long)]
    list: bool,
}

fn parse_rotation(s: &str) -> Result<DQuat, Failure> {
    let parts: Result<Vec<f64>, _> = s.split(',').map(|p| p.trim().parse::<f64>()).collect();
    match parts.as_deref() {
        Ok([x, y, z, deg]) => {
            let axis = DVec3::new(*x, *y, *z);
            if !axis.is_finite() || axis.length() == 0.0 || !deg.is_finite() {
                return Err(Failure::input(anyhow::anyhow!(
                    "--rotate needs a non-zero finite axis and a finite angle, got {s:?}"
                )));
            }
            Ok(DQuat::from_axis_angle(axis.normalize(), deg.to_radians()))
        }
        _ => Err(Failure::input(anyhow::anyhow!(
            "--rotate takes \"x,y,z,degrees\", got {s:?}"
        ))),
    }
}

pub fn run(args: &SynthArgs) -> CliResult {
    if args.list {
        for kind in ShapeKind::ALL {
            outln!("{:<12} {}", kind.name(), kind.description());
        }
        return Ok(());
    }
    let (Some(name), Some(output)) = (&args.shape, &args.output) else {
        return Err(Failure::input(anyhow::anyhow!(
            "a shape and -o are required (see --list)"
        )));
    };
    let kind: ShapeKind = name.parse().map_err(Failure::input)?;
    if !(args.noise.is_finite() && args.noise >= 0.0) {
        return Err(Failure::input(anyhow::anyhow!(
            "--noise must be a finite non-negative number"
        )));
    }
    let mut params = ShapeParams::default();
    if let Some(r) = args.radius {
        params = params.with_radius(r);
    }
    if let Some(rot) = &args.rotate {
        params = params.with_rotation(parse_rotation(rot)?);
    }
    let shape = Shape::new(kind, &params).map_err(Failure::input)?;
    let mut mesh = marching_cubes(&shape, args.resolution).map_err(Failure::input)?;
    if args.noise > 0.0 {
        mesh = add_noise(&mesh, args.noise, args.seed);
    }
    let opts = whet::io::WriteOptions::DEFAULT;
    write_mesh(output, &mesh, None, &opts)?;
    if let Some(t) = &args.truth {
        write_mesh(t, &shape.truth_mesh(), None, &opts)?;
    }
    eprintln!(
        "{}: {} vertices, {} triangles (resolution {}), truth {} triangles",
        kind.name(),
        mesh.positions.len(),
        mesh.triangles.len(),
        args.resolution,
        shape.truth_mesh_ref().triangles.len()
    );
    Ok(())
}
