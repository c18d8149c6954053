//! `whet metro`: the Metro error between two surfaces.

use super::{print_json, read_mesh, CliResult, Failure};
use clap::Args;
use std::path::PathBuf;
use whet_metro::{error_ramp, metro, vertex_distances, Bvh, MetroOptions};

#[derive(Args, Debug)]
pub struct MetroArgs {
    /// Reference mesh (the original); its bounding-box diagonal is the unit of the % figures.
    reference: PathBuf,
    /// Test mesh (e.g. a decoded one).
    test: PathBuf,
    /// Area-uniform face samples per direction (default: max(10 x faces, 1,000,000)).
    #[arg(long)]
    samples: Option<usize>,
    /// Seed of the sampling; the same seed gives the same figures.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Write the test mesh as PLY with each vertex's distance to the reference as `quality`
    /// and a blue-green-red colour ramp.
    #[arg(long, value_name = "OUT.ply")]
    colorize: Option<PathBuf>,
}

pub fn run(args: &MetroArgs) -> CliResult {
    let reference = read_mesh(&args.reference, None)?;
    let test = read_mesh(&args.test, None)?;
    let mut opts = MetroOptions::DEFAULT.with_seed(args.seed);
    if let Some(n) = args.samples {
        if n == 0 {
            return Err(Failure::input(anyhow::anyhow!(
                "--samples must be at least 1"
            )));
        }
        opts = opts.with_samples(n);
    }
    // Meshes that cannot be measured (no triangles, bad indices) are input errors.
    let report = metro(&reference, &test, &opts).map_err(Failure::input)?;
    if let Some(path) = &args.colorize {
        let bvh = Bvh::try_new(&reference).map_err(Failure::input)?;
        let d = vertex_distances(&test, &bvh);
        let max = d.iter().copied().fold(0.0f64, f64::max);
        let colors: Vec<[u8; 3]> = d.iter().map(|&x| error_ramp(x, max)).collect();
        let file = std::fs::File::create(path).map_err(|e| {
            Failure::other(
                anyhow::Error::new(e).context(format!("cannot write {}", path.display())),
            )
        })?;
        whet::io::write_ply_with_quality(
            std::io::BufWriter::new(file),
            &test,
            &d,
            &colors,
            whet::io::PlyEncoding::BinaryLittleEndian,
        )
        .map_err(|e| {
            Failure::other(
                anyhow::Error::new(e).context(format!("cannot write {}", path.display())),
            )
        })?;
    }
    if args.json {
        let value: serde_json::Value = serde_json::from_str(&report.to_json())
            .map_err(|e| Failure::other(anyhow::Error::new(e).context("metro report JSON")))?;
        print_json(&value);
    } else {
        outln!(
            "reference {}  test {}",
            args.reference.display(),
            args.test.display()
        );
        outln!(
            "diagonal {}  face samples per direction {}",
            report.diagonal,
            report.samples
        );
        outln!(
            "{:<10} {:>14} {:>14} {:>14} {:>10} {:>10} {:>10}",
            "",
            "max",
            "mean",
            "rms",
            "max %",
            "mean %",
            "rms %"
        );
        for (name, f) in [
            ("forward", &report.forward.figures),
            ("backward", &report.backward.figures),
            ("symmetric", &report.symmetric),
        ] {
            outln!(
                "{:<10} {:>14.6e} {:>14.6e} {:>14.6e} {:>10.5} {:>10.5} {:>10.5}",
                name,
                f.max,
                f.mean,
                f.rms,
                f.max_pct,
                f.mean_pct,
                f.rms_pct
            );
        }
        outln!("(forward: test sampled against reference; backward: the reverse)");
    }
    Ok(())
}
