//! `whet rd` and `whet demo`: rate-distortion sweeps with whet-rd.

use super::{read_mesh, CliResult, Failure};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use whet::Mesh;
use whet_rd::{
    job_count, parse_draco_anchors, svg_plot, sweep, to_csv, to_json, to_markdown, Codec,
    CodecSweep, Point, Stage, SweepOptions,
};

/// The exact mode as an rd codec; the rate is the quantization bits.
struct ExactCodec;

impl Codec for ExactCodec {
    fn name(&self) -> String {
        "exact".into()
    }
    fn encode(&self, mesh: &Mesh, rate: f64) -> Result<Vec<u8>, String> {
        if rate.fract() != 0.0 || !(1.0..=30.0).contains(&rate) {
            return Err(format!(
                "exact mode rates are quantization bits 1..=30, got {rate}"
            ));
        }
        let opts = whet_codec::EncodeOptions::DEFAULT.with_quant_bits(rate as u32);
        whet_codec::encode(mesh, &opts)
            .map(|e| e.bytes)
            .map_err(|e| e.to_string())
    }
    fn decode(&self, bytes: &[u8]) -> Result<Mesh, String> {
        whet_codec::decode(bytes, &whet_codec::DecodeOptions::DEFAULT).map_err(|e| e.to_string())
    }
}

#[derive(Args, Debug)]
pub struct RdArgs {
    /// Meshes to sweep.
    #[arg(required = true)]
    meshes: Vec<PathBuf>,
    /// Rates of the lossy modes, comma separated (swing: bits per original vertex).
    #[arg(long, value_delimiter = ',')]
    rates: Option<Vec<f64>>,
    /// Quantization bits of the exact mode's baseline curve, comma separated.
    #[arg(
        long,
        value_delimiter = ',',
        default_value = "8,9,10,11,12,13,14,15,16"
    )]
    exact_bits: Vec<f64>,
    /// Control vertex counts of the subdiv mode's curve, comma separated.
    #[arg(long, value_delimiter = ',', default_value = "100,200,400,800")]
    subdiv_control: Vec<f64>,
    /// Codec modes to sweep.
    #[arg(long, value_delimiter = ',', default_value = "exact")]
    modes: Vec<String>,
    /// Post-processing stages to measure after decoding.
    #[arg(long, value_delimiter = ',', default_value = "decoded")]
    stages: Vec<String>,
    /// Output folder for rd.csv, rd.json, rd.md and one SVG per mesh.
    #[arg(long, default_value = "rd-out")]
    out: PathBuf,
    /// Metro face samples per direction.
    #[arg(long, default_value_t = 300_000)]
    samples: usize,
    /// Metro seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Draco's anchors (a markdown table as in ../shared/anchors/draco.md) to draw as the
    /// baseline for meshes of the same name.
    #[arg(long)]
    draco: Option<PathBuf>,
}

/// What a sweep needs besides the meshes.
pub struct Plan {
    pub modes: Vec<String>,
    pub rates: Option<Vec<f64>>,
    pub exact_bits: Vec<f64>,
    pub subdiv_control: Vec<f64>,
    pub stages: Vec<String>,
    pub out: PathBuf,
    pub samples: usize,
    pub seed: u64,
    pub draco: Option<PathBuf>,
}

/// The subdiv mode as an rd codec; the rate is the number of control vertices.
struct SubdivCodec;

impl Codec for SubdivCodec {
    fn name(&self) -> String {
        "subdiv".into()
    }
    fn encode(&self, mesh: &Mesh, rate: f64) -> Result<Vec<u8>, String> {
        if rate.fract() != 0.0 || rate < 4.0 {
            return Err(format!(
                "subdiv rates are control vertex counts (>= 4), got {rate}"
            ));
        }
        let opts = whet_subdiv::SubdivEncodeOptions::DEFAULT.with_control_vertices(rate as usize);
        whet::encode_subdiv(mesh, &opts)
            .map(|(b, _)| b)
            .map_err(|e| e.to_string())
    }
    fn decode(&self, bytes: &[u8]) -> Result<Mesh, String> {
        whet::decode(bytes, &whet_codec::DecodeOptions::DEFAULT).map_err(|e| e.to_string())
    }
}

fn sharpened(mesh: &Mesh) -> Result<whet_sharpen::Sharpened, String> {
    let run = |m: &Mesh| whet_sharpen::sharpen(m, &whet_sharpen::SharpenOptions::DEFAULT);
    match run(mesh) {
        Ok(s) => Ok(s),
        Err(whet_sharpen::Error::InvalidInput(_)) => {
            let mut m = mesh.clone();
            m.make_manifold();
            run(&m).map_err(|e| e.to_string())
        }
        Err(e) => Err(e.to_string()),
    }
}

fn stage_by_name(name: &str) -> Result<Stage, Failure> {
    match name {
        "decoded" => Ok(Stage::decoded()),
        "sharpened" => Ok(Stage::new("sharpened", |m| sharpened(m).map(|s| s.mesh))),
        "bent" => Ok(Stage::new("bent", |m| {
            let s = sharpened(m)?;
            let tags = super::sharpen::tag_edges(&s.tags);
            whet_bend::bend_levels(&s.mesh, &tags, 1)
                .map(|b| b.mesh)
                .map_err(|e| e.to_string())
        })),
        other => Err(Failure::input(anyhow::anyhow!(
            "unknown stage {other:?} (available: decoded, sharpened, bent)"
        ))),
    }
}

/// Runs a sweep and writes its files; returns the points.
pub fn run_plan(meshes: Vec<(String, Mesh)>, plan: &Plan) -> CliResult<Vec<Point>> {
    let exact = ExactCodec;
    let subdiv = SubdivCodec;
    let mut codecs: Vec<CodecSweep<'_>> = Vec::new();
    for m in &plan.modes {
        match m.as_str() {
            "exact" => codecs.push(CodecSweep {
                codec: &exact,
                rates: plan.exact_bits.clone(),
            }),
            "subdiv" => codecs.push(CodecSweep {
                codec: &subdiv,
                rates: plan.subdiv_control.clone(),
            }),
            other => {
                return Err(Failure::input(anyhow::anyhow!(
                    "unknown or unavailable mode {other:?} (available: exact, subdiv)"
                )))
            }
        }
    }
    let _ = &plan.rates;
    let stages: Vec<Stage> = plan
        .stages
        .iter()
        .map(|s| stage_by_name(s))
        .collect::<Result<_, _>>()?;
    let draco = match &plan.draco {
        Some(p) => Some(parse_draco_anchors(&std::fs::read_to_string(p).map_err(
            |e| {
                Failure::input(
                    anyhow::Error::new(e).context(format!("cannot read {}", p.display())),
                )
            },
        )?)),
        None => None,
    };
    let bar = ProgressBar::new(job_count(meshes.len(), &codecs) as u64);
    bar.set_style(
        ProgressStyle::with_template("{spinner} rd [{bar:30}] {pos}/{len} points {elapsed}")
            .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    let opts = SweepOptions::DEFAULT
        .with_metro_samples(plan.samples)
        .with_seed(plan.seed);
    let points = sweep(&meshes, &codecs, &stages, &opts, &|| bar.inc(1));
    bar.finish_and_clear();
    write_outputs(&plan.out, &meshes, &points, draco.as_ref())?;
    Ok(points)
}

fn write_file(path: &Path, text: &str) -> CliResult {
    std::fs::write(path, text).map_err(|e| {
        Failure::other(anyhow::Error::new(e).context(format!("cannot write {}", path.display())))
    })
}

fn write_outputs(
    out: &Path,
    meshes: &[(String, Mesh)],
    points: &[Point],
    draco: Option<&std::collections::BTreeMap<String, Vec<whet_rd::DracoPoint>>>,
) -> CliResult {
    std::fs::create_dir_all(out).map_err(|e| {
        Failure::other(anyhow::Error::new(e).context(format!("cannot create {}", out.display())))
    })?;
    write_file(&out.join("rd.csv"), &to_csv(points))?;
    write_file(&out.join("rd.json"), &to_json(points))?;
    write_file(&out.join("rd.md"), &to_markdown(points))?;
    for (name, _) in meshes {
        let d = draco.and_then(|m| m.get(name)).map(|v| v.as_slice());
        let svg = svg_plot(name, points, d).map_err(|e| Failure::other(anyhow::anyhow!(e)))?;
        write_file(&out.join(format!("{name}.svg")), &svg)?;
    }
    Ok(())
}

pub fn run(args: &RdArgs) -> CliResult {
    let mut meshes = Vec::new();
    for p in &args.meshes {
        let name = p
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "mesh".into());
        meshes.push((name, read_mesh(p, None)?));
    }
    let plan = Plan {
        modes: args.modes.clone(),
        rates: args.rates.clone(),
        exact_bits: args.exact_bits.clone(),
        subdiv_control: args.subdiv_control.clone(),
        stages: args.stages.clone(),
        out: args.out.clone(),
        samples: args.samples,
        seed: args.seed,
        draco: args.draco.clone(),
    };
    let points = run_plan(meshes, &plan)?;
    out!("{}", to_markdown(&points));
    eprintln!(
        "wrote {}/rd.csv, rd.json, rd.md and one SVG per mesh",
        plan.out.display()
    );
    Ok(())
}
