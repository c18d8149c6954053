//! `whet rd` and `whet demo`: rate-distortion sweeps with whet-rd.

use super::encode::AngleBits;
use super::{read_mesh, CliResult, Failure};
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use whet::Mesh;
use whet_rd::{
    compare_with_draco, draco_markdown, job_count, parse_draco_anchors, svg_plot, sweep, to_csv,
    to_json, to_markdown, Codec, CodecSweep, Point, Stage, SweepOptions,
};

/// Why `rate` is not a quantization of the exact mode.
fn exact_rate_problem(rate: f64) -> Option<String> {
    (rate.fract() != 0.0 || !(1.0..=30.0).contains(&rate))
        .then(|| format!("exact mode rates are quantization bits 1..=30, got {rate}"))
}

/// Why `rate` is not a rate of the swing mode.
fn swing_rate_problem(rate: f64) -> Option<String> {
    (!(rate.is_finite() && rate > 0.0))
        .then(|| format!("swing rates are bits per original vertex (> 0), got {rate}"))
}

/// Why `rate` is not a control vertex count of the subdiv mode.
fn subdiv_rate_problem(rate: f64) -> Option<String> {
    (rate.fract() != 0.0 || !(4.0..=1e15).contains(&rate))
        .then(|| format!("subdiv rates are control vertex counts (>= 4), got {rate}"))
}

/// Says why a rate is not one its codec takes.
type RateCheck = fn(f64) -> Option<String>;

/// The first rate of a sweep its codec cannot take, named for the flag that set it: a
/// sweep whose arguments are wrong is refused before it starts (exit 2), while a row that
/// fails on one mesh (a rate too high for it, say) stays a row with its error.
fn check_rates(plan: &Plan) -> CliResult {
    let lists: [(&str, &str, &[f64], RateCheck); 5] = [
        ("swing", "--rates", &plan.rates, swing_rate_problem),
        (
            "exact",
            "--exact-bits",
            &plan.exact_bits,
            exact_rate_problem,
        ),
        (
            "exact-traversal",
            "--exact-bits",
            &plan.exact_bits,
            exact_rate_problem,
        ),
        (
            "exact-traversal-static",
            "--exact-bits",
            &plan.exact_bits,
            exact_rate_problem,
        ),
        (
            "subdiv",
            "--subdiv-control",
            &plan.subdiv_control,
            subdiv_rate_problem,
        ),
    ];
    for (mode, flag, rates, problem) in lists {
        if !plan.modes.iter().any(|m| m == mode) {
            continue;
        }
        if let Some(p) = rates.iter().find_map(|&r| problem(r)) {
            return Err(Failure::input(anyhow::anyhow!("{flag}: {p}")));
        }
    }
    check_samples(plan.samples)
}

/// Refuses a Metro sample count of zero or past [`whet_metro::MAX_FACE_SAMPLES`].
pub fn check_samples(samples: usize) -> CliResult {
    if !(1..=whet_metro::MAX_FACE_SAMPLES).contains(&samples) {
        return Err(Failure::input(anyhow::anyhow!(
            "--samples must be between 1 and {}, got {samples}",
            whet_metro::MAX_FACE_SAMPLES
        )));
    }
    Ok(())
}

/// The exact mode as an rd codec; the rate is the quantization bits. Mode `exact` codes
/// with the default prediction, `exact-traversal` with the traversal prediction (the faster
/// decoder; compare their decode-time columns), `exact-traversal-static` with it and the
/// static residual code (faster again).
struct ExactCodec {
    prediction: whet_codec::ExactPrediction,
}

impl Codec for ExactCodec {
    fn name(&self) -> String {
        match self.prediction {
            whet_codec::ExactPrediction::Traversal => "exact-traversal".into(),
            whet_codec::ExactPrediction::TraversalStatic => "exact-traversal-static".into(),
            _ => "exact".into(),
        }
    }
    fn encode(&self, mesh: &Mesh, rate: f64) -> Result<Vec<u8>, String> {
        if let Some(problem) = exact_rate_problem(rate) {
            return Err(problem);
        }
        let opts = whet_codec::EncodeOptions::DEFAULT
            .with_quant_bits(rate as u32)
            .with_prediction(self.prediction);
        whet_codec::encode(mesh, &opts)
            .map(|e| e.bytes)
            .map_err(|e| e.to_string())
    }
    fn decode(&self, bytes: &[u8]) -> Result<Mesh, String> {
        whet_codec::decode(bytes, &own_streams()).map_err(|e| e.to_string())
    }
}

/// The swing mode (SwingWrapper) as an rd codec; the rate is bits per ORIGINAL vertex, the
/// papers' unit (the encoder searches the edge length to land within 5 %).
struct SwingCodec {
    angle_bits: AngleBits,
    error_of: whet_swing::ErrorOf,
}

impl Codec for SwingCodec {
    fn name(&self) -> String {
        "swing".into()
    }
    fn encode(&self, mesh: &Mesh, rate: f64) -> Result<Vec<u8>, String> {
        if let Some(problem) = swing_rate_problem(rate) {
            return Err(problem);
        }
        let opts = self.angle_bits.apply(
            whet_swing::SwingOptions::DEFAULT
                .with_rate(whet_swing::Rate::BitsPerVertex(rate))
                .with_error_of(self.error_of)
                // Enough to rank angle quantizations whose errors differ by > 3 %; the
                // sweep's own measurement uses --samples.
                .with_metro_samples(100_000),
        );
        whet_swing::encode(mesh, &opts)
            .map(|o| o.bytes)
            .map_err(|e| e.to_string())
    }
    fn decode(&self, bytes: &[u8]) -> Result<Mesh, String> {
        whet::decode(bytes, &own_streams()).map_err(|e| e.to_string())
    }
    fn decode_for_stages(&self, bytes: &[u8]) -> Option<Result<Mesh, String>> {
        // As `whet decode --sharpen`: EdgeSharpener starts from the unfiltered vertices. A
        // stream without a filter decodes to them already: no second decode.
        let header = whet_format::parse(bytes, &whet_format::Limits::UNLIMITED)
            .ok()?
            .header;
        let tags = [
            whet_format::tag::FILTER_NORMAL,
            whet_format::tag::FILTER_SMOOTHED,
        ];
        if tags.iter().all(|&t| header.get_i64(t).is_none()) {
            return None;
        }
        let opts = own_streams().with_surface_filter(false);
        Some(whet::decode(bytes, &opts).map_err(|e| e.to_string()))
    }
}

/// Default rates of the swing curve, bits per original vertex.
pub const DEFAULT_SWING_RATES: [f64; 6] = [0.5, 1.0, 2.0, 3.0, 4.0, 6.0];

#[derive(Args, Debug)]
pub struct RdArgs {
    /// Meshes to sweep.
    #[arg(required = true)]
    meshes: Vec<PathBuf>,
    /// Rates of the swing mode, bits per ORIGINAL vertex, comma separated.
    #[arg(long, value_delimiter = ',', default_value = "0.5,1,2,3,4,6")]
    rates: Vec<f64>,
    /// Swing angle bits of the swing curve, or `auto`: at each rate the encoder walks from 6
    /// bits up and then down within 4..=12 while the error falls and keeps the stream whose
    /// output measures the lowest RMS error (the sharpened output when the stages sharpen,
    /// else the decoded one).
    #[arg(long, value_name = "B|auto", default_value = "auto")]
    angle_bits: AngleBits,
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
    /// Codec modes to sweep (swing, exact, exact-traversal, exact-traversal-static, subdiv).
    #[arg(long, value_delimiter = ',', default_value = "swing,exact")]
    modes: Vec<String>,
    /// Post-processing stages to measure after decoding.
    #[arg(long, value_delimiter = ',', default_value = "decoded")]
    stages: Vec<String>,
    /// Stages of the exact mode's baseline curve, when they should differ from --stages
    /// (e.g. `decoded` only: Bender is meant for coarse retilings, not a dense exact mesh).
    #[arg(long, value_delimiter = ',')]
    exact_stages: Option<Vec<String>>,
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
    pub rates: Vec<f64>,
    pub angle_bits: AngleBits,
    pub exact_bits: Vec<f64>,
    pub subdiv_control: Vec<f64>,
    pub stages: Vec<String>,
    pub exact_stages: Option<Vec<String>>,
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
        if let Some(problem) = subdiv_rate_problem(rate) {
            return Err(problem);
        }
        let opts = whet_subdiv::SubdivEncodeOptions::DEFAULT.with_control_vertices(rate as usize);
        whet::encode_subdiv(mesh, &opts)
            .map(|(b, _)| b)
            .map_err(|e| e.to_string())
    }
    fn decode(&self, bytes: &[u8]) -> Result<Mesh, String> {
        whet::decode(bytes, &own_streams()).map_err(|e| e.to_string())
    }
}

/// What `whet decode --sharpen` makes of a stream, with the sharp-edge tags for Bender: the
/// sharpening its header states (`whet_swing::StatedSharpening`: the extended method
/// without a hint; its snap vetoes replayed), then its filter for after sharpening and its
/// projections; for a stream whose encoder measured no sharpening best, the plain decoded
/// mesh (its surface filter included) and filter 3bis's tags.
fn sharpened_from_stream(mesh: &Mesh, bytes: &[u8]) -> Result<(Mesh, Vec<[u32; 2]>), String> {
    let header = whet_format::parse(bytes, &whet_format::Limits::UNLIMITED)
        .ok()
        .map(|c| c.header);
    let stated = match &header {
        Some(h) => whet_swing::StatedSharpening::of(h).map_err(|e| e.to_string())?,
        None => whet_swing::StatedSharpening::default(),
    };
    match stated.apply(mesh).map_err(|e| e.to_string())? {
        Some(out) => {
            for (p, e) in &out.skipped {
                eprintln!("whet: the {} projection was skipped: {e}", p.name());
            }
            let tags = super::sharpen::tag_edges(&out.sharpened.tags);
            Ok((out.sharpened.mesh, tags))
        }
        None => {
            // As `whet decode --sharpen --bend`: filter 3bis's tags for Bender.
            let plain = whet::decode(bytes, &own_streams()).map_err(|e| e.to_string())?;
            let tags =
                super::sharpen::fallback_tags(&plain).map_err(|e| format!("{:#}", e.error))?;
            Ok((plain, tags))
        }
    }
}

fn stage_by_name(name: &str) -> Result<Stage, Failure> {
    match name {
        "decoded" => Ok(Stage::decoded()),
        "sharpened" => Ok(Stage::with_stream("sharpened", |m, b| {
            sharpened_from_stream(m, b).map(|s| s.0)
        })),
        "bent" => Ok(Stage::with_stream("bent", |m, b| {
            let (sharp, tags) = sharpened_from_stream(m, b)?;
            whet_bend::bend_levels(&sharp, &tags, 1)
                .map(|b| b.mesh)
                .map_err(|e| e.to_string())
        })),
        other => Err(Failure::input(anyhow::anyhow!(
            "unknown stage {other:?} (available: decoded, sharpened, bent)"
        ))),
    }
}

/// Runs a sweep and writes its files; returns the points and the markdown report (`rd.md`).
pub fn run_plan(meshes: Vec<(String, Mesh)>, plan: &Plan) -> CliResult<(Vec<Point>, String)> {
    let exact = ExactCodec {
        prediction: whet_codec::ExactPrediction::Degree,
    };
    let exact_traversal = ExactCodec {
        prediction: whet_codec::ExactPrediction::Traversal,
    };
    let exact_traversal_static = ExactCodec {
        prediction: whet_codec::ExactPrediction::TraversalStatic,
    };
    let subdiv = SubdivCodec;
    let sharpens = plan.stages.iter().any(|s| s == "sharpened" || s == "bent");
    let swing = SwingCodec {
        angle_bits: plan.angle_bits,
        error_of: if sharpens {
            whet_swing::ErrorOf::Sharpened
        } else {
            whet_swing::ErrorOf::Decoded
        },
    };
    let mut codecs: Vec<CodecSweep<'_>> = Vec::new();
    for m in &plan.modes {
        match m.as_str() {
            "swing" => codecs.push(CodecSweep::new(&swing, plan.rates.clone())),
            "exact" | "exact-traversal" | "exact-traversal-static" => {
                let codec = match m.as_str() {
                    "exact" => &exact,
                    "exact-traversal" => &exact_traversal,
                    _ => &exact_traversal_static,
                };
                let mut c = CodecSweep::new(codec, plan.exact_bits.clone());
                if let Some(s) = &plan.exact_stages {
                    c = c.with_stages(s.clone());
                }
                codecs.push(c)
            }
            "subdiv" => codecs.push(CodecSweep::new(&subdiv, plan.subdiv_control.clone())),
            other => {
                return Err(Failure::input(anyhow::anyhow!(
                    "unknown mode {other:?} (available: swing, exact, exact-traversal, \
                     exact-traversal-static, subdiv)"
                )))
            }
        }
    }
    check_rates(plan)?;
    let stages: Vec<Stage> = plan
        .stages
        .iter()
        .map(|s| stage_by_name(s))
        .collect::<Result<_, _>>()?;
    if let Some(extra) = &plan.exact_stages {
        for s in extra {
            stage_by_name(s)?;
            if !plan.stages.contains(s) {
                return Err(Failure::input(anyhow::anyhow!(
                    "--exact-stages names {s:?}, which --stages does not run"
                )));
            }
        }
    }
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
    let md = write_outputs(&plan.out, &meshes, &points, draco.as_ref())?;
    Ok((points, md))
}

fn write_file(path: &Path, text: &str) -> CliResult {
    std::fs::write(path, text).map_err(|e| {
        Failure::other(anyhow::Error::new(e).context(format!("cannot write {}", path.display())))
    })
}

/// The quantization whose RMS error the project's bar refers to, and the bar itself: reach
/// Draco's quantization-10 RMS with at most a quarter of its bytes.
pub const DRACO_BAR_QUANT_BITS: u32 = 10;
/// See [`DRACO_BAR_QUANT_BITS`].
pub const DRACO_BAR_RATIO: f64 = 0.25;

/// The bytes every curve needs for Draco's quantization-10 RMS error.
pub fn vs_draco_markdown(
    points: &[Point],
    draco: &std::collections::BTreeMap<String, Vec<whet_rd::DracoPoint>>,
) -> String {
    let matches = compare_with_draco(points, draco, DRACO_BAR_QUANT_BITS);
    if matches.is_empty() {
        return "No mesh of the sweep has a Draco anchor at quantization 10.\n".into();
    }
    draco_markdown(&matches, DRACO_BAR_RATIO)
}

fn write_outputs(
    out: &Path,
    meshes: &[(String, Mesh)],
    points: &[Point],
    draco: Option<&std::collections::BTreeMap<String, Vec<whet_rd::DracoPoint>>>,
) -> CliResult<String> {
    std::fs::create_dir_all(out).map_err(|e| {
        Failure::other(anyhow::Error::new(e).context(format!("cannot create {}", out.display())))
    })?;
    write_file(&out.join("rd.csv"), &to_csv(points))?;
    write_file(&out.join("rd.json"), &to_json(points))?;
    let mut md = to_markdown(points);
    if let Some(d) = draco {
        let vs = vs_draco_markdown(points, d);
        write_file(&out.join("vs-draco.md"), &vs)?;
        md.push_str("### Against Draco\n\n");
        md.push_str(&vs);
    }
    write_file(&out.join("rd.md"), &md)?;
    for (name, _) in meshes {
        let d = draco.and_then(|m| m.get(name)).map(|v| v.as_slice());
        let svg = svg_plot(name, points, d).map_err(|e| Failure::other(anyhow::anyhow!(e)))?;
        write_file(&out.join(format!("{name}.svg")), &svg)?;
    }
    Ok(md)
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
        angle_bits: args.angle_bits,
        exact_bits: args.exact_bits.clone(),
        subdiv_control: args.subdiv_control.clone(),
        stages: args.stages.clone(),
        exact_stages: args.exact_stages.clone(),
        out: args.out.clone(),
        samples: args.samples,
        seed: args.seed,
        draco: args.draco.clone(),
    };
    let (_, md) = run_plan(meshes, &plan)?;
    out!("{md}");
    eprintln!(
        "wrote {}/rd.csv, rd.json, rd.md and one SVG per mesh",
        plan.out.display()
    );
    Ok(())
}

/// Decode options for the streams the harness itself just encoded: trusted, so without the
/// byte and count limits that guard `whet decode` against hostile ones (a benchmark mesh
/// past the default budget's 50M decoded triangles still measures).
fn own_streams() -> whet_codec::DecodeOptions {
    whet_codec::DecodeOptions::DEFAULT.with_limits(whet_format::Limits::UNLIMITED)
}
