//! `whet subdivide`: semi-sharp Loop subdivision of a control mesh (seed 004).

use super::{print_json, read_mesh, write_mesh, CliResult, Failure};
use clap::Args;
use std::path::{Path, PathBuf};
use whet_subdiv::{subdivide, EdgeSharpness, SubdivOptions, MAX_LEVELS};

#[derive(Args, Debug)]
pub struct SubdivideArgs {
    /// Control mesh (an oriented manifold triangle mesh; boundaries allowed).
    control: PathBuf,
    /// Output mesh.
    #[arg(short, long)]
    output: PathBuf,
    /// Number of 1-to-4 splits (0 writes the control mesh).
    #[arg(long, default_value_t = 3)]
    levels: u32,
    /// Edge sharpness: a text file of lines "a b h" (0-based vertex indices of a control
    /// edge and its sharpness in [0, 1]; `#` starts a comment). Unlisted edges are smooth.
    #[arg(long, value_name = "FILE", conflicts_with = "crease_angle")]
    sharpness: Option<PathBuf>,
    /// Instead of a file: sharpness 1 on edges whose dihedral angle exceeds this many
    /// degrees (Hoppe et al.'s crease detection), 0 elsewhere.
    #[arg(long, value_name = "DEGREES")]
    crease_angle: Option<f64>,
    /// Levels using the continuous (semi-sharp) rules before Hoppe's binary ones
    /// (default: all of them).
    #[arg(long)]
    sharp_levels: Option<u32>,
    /// Keep the last level's vertices where subdivision puts them instead of moving them to
    /// the limit surface.
    #[arg(long)]
    no_limit: bool,
    /// Print one JSON object with the counts.
    #[arg(long)]
    json: bool,
    /// Refuse to start when the output would need more than this many bytes (estimated from
    /// the output's triangle count).
    #[arg(long, value_name = "BYTES", default_value_t = super::DEFAULT_MAX_MEMORY)]
    max_memory: u64,
}

pub fn run(args: &SubdivideArgs) -> CliResult {
    if args.levels > MAX_LEVELS {
        return Err(Failure::input(anyhow::anyhow!(
            "--levels must be at most {MAX_LEVELS}, got {}",
            args.levels
        )));
    }
    let control = super::manifold(read_mesh(&args.control, None)?);
    super::check_memory(
        &format!("{} levels of subdivision", args.levels),
        super::split_triangles(control.triangles.len(), args.levels),
        whet_subdiv::SUBDIVISION_BYTES_PER_TRIANGLE,
        args.max_memory,
    )?;
    let sharpness = match (&args.sharpness, args.crease_angle) {
        (Some(path), _) => read_sharpness(path, &control)?,
        (None, Some(deg)) => {
            if !deg.is_finite() {
                return Err(Failure::input(anyhow::anyhow!(
                    "--crease-angle must be a finite number of degrees"
                )));
            }
            EdgeSharpness::from_dihedral_angle(&control, deg)
        }
        (None, None) => EdgeSharpness::zeros(&control),
    };
    let opts = SubdivOptions::DEFAULT
        .with_levels(args.levels)
        .with_sharp_levels(args.sharp_levels.unwrap_or(args.levels))
        .with_limit(!args.no_limit);
    let start = std::time::Instant::now();
    let out = subdivide(&control, &sharpness, &opts).map_err(|e| match e {
        whet_subdiv::Error::InvalidInput(_) | whet_subdiv::Error::Parameter(_) => Failure::input(
            anyhow::Error::new(e).context(format!("cannot subdivide {}", args.control.display())),
        ),
        other => Failure::other(other),
    })?;
    let ms = start.elapsed().as_secs_f64() * 1e3;
    write_mesh(&args.output, &out, None, &whet::io::WriteOptions::default())?;
    if args.json {
        print_json(&serde_json::json!({
            "control_vertices": control.positions.len(),
            "control_triangles": control.triangles.len(),
            "sharp_edges": sharpness.sharp_count(),
            "levels": args.levels,
            "sharp_levels": opts.sharp_levels,
            "limit": opts.limit,
            "vertices": out.positions.len(),
            "triangles": out.triangles.len(),
            "ms": ms,
        }));
    } else {
        outln!(
            "{} -> {}: {} levels ({} semi-sharp), {} of {} edges sharp, {} vertices, {} triangles, {:.1} ms",
            args.control.display(),
            args.output.display(),
            args.levels,
            opts.sharp_levels,
            sharpness.sharp_count(),
            sharpness.len(),
            out.positions.len(),
            out.triangles.len(),
            ms
        );
    }
    Ok(())
}

/// Reads "a b h" lines into the sharpness of `control`'s edges.
fn read_sharpness(path: &Path, control: &whet::Mesh) -> CliResult<EdgeSharpness> {
    let text = std::fs::read_to_string(path).map_err(|e| {
        Failure::input(anyhow::Error::new(e).context(format!("cannot read {}", path.display())))
    })?;
    let mut s = EdgeSharpness::zeros(control);
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let bad = |what: &str| {
            Failure::input(anyhow::anyhow!(
                "{}:{}: {what} (expected \"a b h\")",
                path.display(),
                n + 1
            ))
        };
        let fields: Vec<&str> = line.split_whitespace().collect();
        let [a, b, h] = fields.as_slice() else {
            return Err(bad("three fields needed"));
        };
        let a: u32 = a.parse().map_err(|_| bad("bad vertex index"))?;
        let b: u32 = b.parse().map_err(|_| bad("bad vertex index"))?;
        let h: f64 = h.parse().map_err(|_| bad("bad sharpness"))?;
        if !(0.0..=1.0).contains(&h) {
            return Err(bad("sharpness outside [0, 1]"));
        }
        s.set(a, b, h)
            .map_err(|_| bad(&format!("({a}, {b}) is not an edge of the control mesh")))?;
    }
    Ok(s)
}
