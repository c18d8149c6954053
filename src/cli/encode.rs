//! `whet encode`: a mesh file to a `.whet` stream.

use super::{print_json, read_mesh_noting_skipped, skipped_json, write_mesh, CliResult, Failure};
use clap::{ArgGroup, Args, ValueEnum};
use serde_json::json;
use std::path::PathBuf;
use whet_codec::{EncodeOptions, Encoder, Mode};
use whet_swing::{Rate, SwingOptions};

/// Codec modes selectable on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// SwingWrapper: retile into a nearly regular mesh with edges of about one length,
    /// one quantized swing angle per vertex (lossy, the main codec).
    Swing,
    /// Edgebreaker connectivity + quantized parallelogram-predicted positions (lossless
    /// connectivity).
    Exact,
    /// A small control mesh with continuous edge sharpness fitted to the input; the decoder
    /// subdivides it (semi-sharp Loop; seed 004).
    Subdiv,
}

/// `--prediction` (exact mode).
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum PredictionArg {
    /// The prediction-degree order, several parallelograms per vertex: the smaller stream.
    Degree,
    /// Traversal order, one parallelogram per vertex: about 1.8 times as fast to decode,
    /// 3-15 % larger on most meshes and up to about 50 % on blocky CAD parts; format 1.5.
    Traversal,
    /// The traversal order with its residuals coded by static per-context tables (rANS):
    /// faster to decode than `traversal` again, for about 1 % more bytes; format 1.6.
    TraversalStatic,
}

impl From<PredictionArg> for whet_codec::ExactPrediction {
    fn from(p: PredictionArg) -> Self {
        match p {
            PredictionArg::Degree => whet_codec::ExactPrediction::Degree,
            PredictionArg::Traversal => whet_codec::ExactPrediction::Traversal,
            PredictionArg::TraversalStatic => whet_codec::ExactPrediction::TraversalStatic,
        }
    }
}

/// `--angle-bits`: a count, or `auto`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AngleBits {
    /// Fixed bits.
    Fixed(u32),
    /// Chosen by measurement.
    Auto,
}

impl std::str::FromStr for AngleBits {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        if s.eq_ignore_ascii_case("auto") {
            return Ok(AngleBits::Auto);
        }
        match s.parse::<u32>() {
            Ok(b)
                if (whet_codec::swing::MIN_ANGLE_BITS..=whet_codec::swing::MAX_ANGLE_BITS)
                    .contains(&b) =>
            {
                Ok(AngleBits::Fixed(b))
            }
            _ => Err(format!(
                "expected `auto` or angle bits {}..={}, got {s:?}",
                whet_codec::swing::MIN_ANGLE_BITS,
                whet_codec::swing::MAX_ANGLE_BITS
            )),
        }
    }
}

impl AngleBits {
    /// Applies to swing options.
    pub fn apply(self, opts: SwingOptions) -> SwingOptions {
        match self {
            AngleBits::Fixed(b) => opts.with_angle_bits(b).with_auto_angle_bits(false),
            AngleBits::Auto => opts.with_auto_angle_bits(true),
        }
    }
}

/// `--optimize-for`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OptimizeFor {
    /// The decoded mesh.
    Decoded,
    /// The decoded mesh after EdgeSharpener.
    Sharpened,
}

impl From<OptimizeFor> for whet_swing::ErrorOf {
    fn from(o: OptimizeFor) -> Self {
        match o {
            OptimizeFor::Decoded => whet_swing::ErrorOf::Decoded,
            OptimizeFor::Sharpened => whet_swing::ErrorOf::Sharpened,
        }
    }
}

/// Swing mode's default edge length, as a fraction of the bounding-box diagonal, when no
/// rate option is given.
const DEFAULT_EDGE_LENGTH: f64 = 0.01;

#[derive(Args, Debug)]
#[command(group(ArgGroup::new("rate").args(["edge_length", "bpv", "target_bytes", "max_error"])))]
pub struct EncodeArgs {
    /// Input mesh file.
    input: PathBuf,
    /// Output `.whet` file.
    #[arg(short, long)]
    output: PathBuf,
    /// Codec mode.
    #[arg(long, value_enum, default_value_t = ModeArg::Swing)]
    mode: ModeArg,
    /// Position quantization bits per coordinate (exact mode: every vertex, default 14;
    /// swing mode: the seed triangles, default 20).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=30))]
    quant_bits: Option<u32>,
    /// Exact: how positions are ordered and predicted (default degree).
    #[arg(long, value_enum)]
    prediction: Option<PredictionArg>,
    /// Swing: target edge length as a fraction of the bounding-box diagonal (default 0.01).
    #[arg(long, value_name = "L")]
    edge_length: Option<f64>,
    /// Swing: bits per vertex of the ORIGINAL mesh; the edge length is searched to land
    /// within 5 %.
    #[arg(long, value_name = "R")]
    bpv: Option<f64>,
    /// Swing: stream size in bytes; the edge length is searched to land within 5 %.
    #[arg(long, value_name = "N")]
    target_bytes: Option<usize>,
    /// Swing: largest RMS error in percent of the bounding-box diagonal (measured with
    /// Metro against the input); the cheapest stream found that meets it.
    #[arg(long, value_name = "E")]
    max_error: Option<f64>,
    /// Swing: bits of a quantized swing angle (3..=14), or `auto`: with --bpv,
    /// --target-bytes or --max-error, walk from 6 bits up and then down within 4..=12 while
    /// the score improves and keep the lowest error (or the smallest stream meeting the
    /// target), measured on the output of --optimize-for; for the sharpened output the
    /// error is RMS x max^0.25, and the runner-up within 5 % gets its sharpening chosen
    /// too, the one that ends better being written.
    #[arg(long, value_name = "B|auto", default_value = "6")]
    angle_bits: AngleBits,
    /// Swing: which output --max-error and --angle-bits auto measure: the decoded mesh, or
    /// the decoded mesh after `whet decode --sharpen` (for CAD parts).
    #[arg(long, value_enum, default_value_t = OptimizeFor::Decoded)]
    optimize_for: OptimizeFor,
    /// Swing: write no surface filter into the stream (the decoder then returns the retiled
    /// vertices on the original surface). By default the encoder fits one; `whet decode
    /// --sharpen` leaves it out, as EdgeSharpener works on the unfiltered vertices.
    #[arg(long)]
    no_surface_filter: bool,
    /// Swing: keep the surface filter to its two fields of format 1.1 (streams readable by
    /// whet before format 1.4, about 5 % faster to decode). By default the encoder writes
    /// the extended filter, three more fields, where half its fitted gain beats the bytes
    /// they add (2-9 % less RMS error at equal bytes on smooth meshes), into the streams
    /// whose decoded mesh is the output it optimizes (with --optimize-for sharpened: those
    /// that state no sharpening).
    #[arg(long)]
    basic_surface_filter: bool,
    /// Swing: the most retiled triangles an edge length may ask for (estimated from the
    /// original's area before any work; the retiler holds about 450 bytes per retiled
    /// triangle, so the default, 2^24, is about 7.5 GB). Shorter lengths are refused, and
    /// the rate searches stay above them.
    #[arg(long, value_name = "N", default_value_t = whet_swing::RetileTuning::DEFAULT.max_triangles)]
    max_retiled_triangles: usize,
    /// Swing: also write the retiled mesh the stream encodes (byte-identical to what
    /// `whet decode` writes in the same format).
    #[arg(long, value_name = "PATH")]
    emit_retiled: Option<PathBuf>,
    /// Subdiv: control vertices to fit.
    #[arg(long, default_value_t = 500)]
    control_vertices: usize,
    /// Subdiv: subdivision levels the decoder applies (default: the fitting levels).
    #[arg(long)]
    levels: Option<u32>,
    /// Input format, overriding the extension.
    #[arg(long)]
    format: Option<whet::io::Format>,
    /// Print one JSON object with the stream's figures.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &EncodeArgs) -> CliResult {
    let rate_given = args.edge_length.is_some()
        || args.bpv.is_some()
        || args.target_bytes.is_some()
        || args.max_error.is_some();
    if args.mode != ModeArg::Swing && (rate_given || args.emit_retiled.is_some()) {
        return Err(Failure::other(anyhow::anyhow!(
            "--edge-length, --bpv, --target-bytes, --max-error and --emit-retiled apply to \
             --mode swing only"
        )));
    }
    if args.mode != ModeArg::Exact && args.prediction.is_some() {
        return Err(Failure::other(anyhow::anyhow!(
            "--prediction applies to --mode exact only"
        )));
    }
    let (mesh, skipped) = read_mesh_noting_skipped(&args.input, args.format)?;
    match args.mode {
        ModeArg::Exact => run_exact(args, &mesh, &skipped),
        ModeArg::Swing => run_swing(args, &mesh, &skipped),
        ModeArg::Subdiv => super::encode_subdiv::run_subdiv(
            &args.input,
            &args.output,
            &mesh,
            &skipped,
            args.control_vertices,
            args.levels,
            args.quant_bits,
            args.json,
        ),
    }
}

/// The context of an encoding error: "cannot encode <path>", or just the path when the
/// library's own message already starts with "cannot encode" (its input errors do).
fn encode_context(path: &std::path::Path, e: &impl std::fmt::Display) -> String {
    if e.to_string().starts_with("cannot encode") {
        path.display().to_string()
    } else {
        format!("cannot encode {}", path.display())
    }
}

fn write_stream(args: &EncodeArgs, bytes: &[u8]) -> CliResult {
    std::fs::write(&args.output, bytes).map_err(|e| {
        Failure::other(
            anyhow::Error::new(e).context(format!("cannot write {}", args.output.display())),
        )
    })
}

fn report_repair(r: &whet_codec::EncodeReport) {
    if !r.repair.is_unchanged() {
        eprintln!(
            "whet: the input was not an oriented manifold; make_manifold {}",
            r.repair
        );
    }
    if r.dropped_unused_vertices > 0 {
        eprintln!(
            "whet: {} vertices used by no triangle were left out",
            r.dropped_unused_vertices
        );
    }
}

fn repair_json(r: &whet_codec::EncodeReport) -> serde_json::Value {
    json!({
        "dropped_out_of_range": r.repair.dropped_out_of_range,
        "dropped_degenerate": r.repair.dropped_degenerate,
        "dropped_duplicates": r.repair.dropped_duplicates,
        "flipped_triangles": r.repair.flipped_triangles,
        "cut_edges": r.repair.cut_edges,
        "added_vertices": r.repair.added_vertices,
    })
}

fn run_exact(args: &EncodeArgs, mesh: &whet::Mesh, skipped: &whet::io::ReadReport) -> CliResult {
    let quant_bits = args.quant_bits.unwrap_or(14);
    let prediction = args.prediction.unwrap_or(PredictionArg::Degree);
    let opts = EncodeOptions::DEFAULT
        .with_mode(Mode::Exact)
        .with_quant_bits(quant_bits)
        .with_prediction(prediction.into());
    let encoded = Encoder::new(opts).encode(mesh).map_err(|e| {
        let input = !matches!(e, whet_codec::Error::Parameter(_));
        let context = encode_context(&args.input, &e);
        let err = anyhow::Error::new(e).context(context);
        if input {
            Failure::input(err)
        } else {
            Failure::other(err)
        }
    })?;
    write_stream(args, &encoded.bytes)?;
    let r = &encoded.report;
    report_repair(r);
    let h = r.clers_histogram;
    if args.json {
        print_json(&json!({
            "mode": "exact",
            "bytes": r.bytes,
            "triangles": r.triangles,
            "vertices": r.vertices,
            "connectivity_bits": r.connectivity_bits,
            "geometry_bits": r.geometry_bits,
            "bits_per_vertex": r.bits_per_vertex(),
            "bits_per_triangle": r.bits_per_triangle(),
            "quant_bits": quant_bits,
            "prediction": match prediction {
                PredictionArg::Degree => "degree",
                PredictionArg::Traversal => "traversal",
                PredictionArg::TraversalStatic => "traversal-static",
            },
            "components": r.components,
            "clers_histogram": { "C": h[0], "L": h[1], "E": h[2], "R": h[3], "S": h[4] },
            "repair": repair_json(r),
            "dropped_unused_vertices": r.dropped_unused_vertices,
            "skipped_attributes": skipped_json(skipped),
        }));
    } else {
        outln!(
            "{} -> {}: {} bytes, {} vertices, {} triangles, {:.3} bits/vertex, {:.3} bits/triangle (connectivity {} bits, geometry {} bits)",
            args.input.display(),
            args.output.display(),
            r.bytes,
            r.vertices,
            r.triangles,
            r.bits_per_vertex(),
            r.bits_per_triangle(),
            r.connectivity_bits,
            r.geometry_bits
        );
    }
    Ok(())
}

fn run_swing(args: &EncodeArgs, mesh: &whet::Mesh, skipped: &whet::io::ReadReport) -> CliResult {
    let rate = if let Some(l) = args.edge_length {
        Rate::EdgeLength(l)
    } else if let Some(r) = args.bpv {
        Rate::BitsPerVertex(r)
    } else if let Some(n) = args.target_bytes {
        Rate::TargetBytes(n)
    } else if let Some(e) = args.max_error {
        Rate::MaxError(e)
    } else {
        Rate::EdgeLength(DEFAULT_EDGE_LENGTH)
    };
    let quant_bits = args.quant_bits.unwrap_or(SwingOptions::DEFAULT.quant_bits);
    let opts = args.angle_bits.apply(
        SwingOptions::DEFAULT
            .with_rate(rate)
            .with_quant_bits(quant_bits)
            .with_error_of(args.optimize_for.into())
            .with_surface_filter(!args.no_surface_filter)
            .with_extended_filter(!args.basic_surface_filter)
            .with_tuning(
                whet_swing::RetileTuning::DEFAULT.with_max_triangles(args.max_retiled_triangles),
            ),
    );
    let out = whet_swing::encode(mesh, &opts).map_err(|e| {
        let input = e.is_input_error();
        let context = encode_context(&args.input, &e);
        let err = anyhow::Error::new(e).context(context);
        if input {
            Failure::input(err)
        } else {
            Failure::other(err)
        }
    })?;
    write_stream(args, &out.bytes)?;
    if let Some(path) = &args.emit_retiled {
        write_mesh(path, &out.retiled, None, &whet::io::WriteOptions::DEFAULT)?;
    }
    let r = &out.report;
    report_repair(r);
    let target_bytes = match rate {
        Rate::BitsPerVertex(bpv) => Some(bpv * out.original_vertices as f64 / 8.0),
        Rate::TargetBytes(n) => Some(n as f64),
        _ => None,
    };
    if let Some(target) = target_bytes {
        let off = r.bytes as f64 / target - 1.0;
        if off.abs() > opts.tolerance {
            eprintln!(
                "whet: the stream written is {:+.1} % from the target of {:.0} bytes: no \
                 edge length the size search tried landed within {:.0} %",
                100.0 * off,
                target,
                100.0 * opts.tolerance
            );
        }
    }
    // The retiling bridges features thinner than L; far past that, part of the surface is
    // missing from the decoded mesh, which the user should hear about rather than find.
    let gap_pct = 100.0 * out.coverage_gap * out.edge_length_fraction;
    // Built apart from the object below, which is near serde_json's macro recursion limit
    // (raised in main.rs).
    let sharpen_trials: Vec<_> = out
        .sharpen_trials
        .iter()
        .map(|t| {
            json!({
                "method": t.hint.name(),
                "smooth_factor": t.smooth_factor,
                "curved_walls": t.curved_walls,
                "passes": t.passes,
                "gray_labels": t.gray_labels,
                "rms_error_pct": t.rms_pct,
                "max_error_pct": t.max_pct,
                "planar": t.planar,
                "quadric": t.quadric,
                "beside": t.beside,
                "crease": t.crease,
                "apex": t.apex,
                "sharpened_filter": t.sharpened_filter,
                "runner_up": t.runner_up,
            })
        })
        .collect();
    if !out.coverage_gap.is_finite() {
        // A distance that could not be computed, which the encoder counts as uncovered
        // (JSON: null).
        eprintln!(
            "whet: part of the surface may be left uncovered: the distance from the original \
             to the retiling could not be measured"
        );
    } else if out.coverage_gap > whet_swing::MAX_COVERAGE_GAP {
        eprintln!(
            "whet: the retiling leaves part of the surface uncovered: an original vertex lies \
             {:.1} edge lengths ({gap_pct:.2} % of the diagonal) from it, where parts thinner \
             than the edge length ({:.2} % of the diagonal) were wrapped wrongly; a higher rate \
             (--bpv, --target-bytes) or a shorter --edge-length covers them",
            out.coverage_gap,
            100.0 * out.edge_length_fraction
        );
    }
    if let whet_codec::SwingGeometry::Explicit(reason) = &out.geometry {
        eprintln!("whet: swing geometry coded as explicit positions: {reason}");
    }
    let h = r.clers_histogram;
    if args.json {
        let mut j = json!({
            "mode": "swing",
            "bytes": r.bytes,
            "triangles": r.triangles,
            "vertices": r.vertices,
            "connectivity_bits": r.connectivity_bits,
            "geometry_bits": r.geometry_bits,
            "bits_per_vertex": r.bits_per_vertex(),
            "bits_per_triangle": r.bits_per_triangle(),
            "edge_length": out.edge_length_fraction,
            "edge_length_absolute": out.edge_length,
            "angle_bits": out.angle_bits,
            "quant_bits": quant_bits,
            "retiled_vertices": r.vertices,
            "retiled_triangles": r.triangles,
            "original_vertices": out.original_vertices,
            "original_triangles": out.original_triangles,
            "bits_per_original_vertex": out.bits_per_original_vertex(),
            "clers_histogram": { "C": h[0], "L": h[1], "E": h[2], "R": h[3], "S": h[4] },
            "valence6_fraction": out.valence6_fraction(),
            "components": r.components,
            "geometry": match &out.geometry {
                whet_codec::SwingGeometry::Swing => "swing",
                _ => "explicit",
            },
            "rms_error_pct": out.rms_pct,
            "coverage_gap": if gap_pct.is_finite() { json!(out.coverage_gap) } else { json!(null) },
            "coverage_gap_pct": if gap_pct.is_finite() { json!(gap_pct) } else { json!(null) },
            "surface_filter": {
                "normal": out.surface_filter.extended_factors()[0],
                "smoothed": out.surface_filter.extended_factors()[1],
                "smoothed2": out.surface_filter.extended_factors()[2],
                "quadratic": out.surface_filter.extended_factors()[3],
                "tangential": out.surface_filter.extended_factors()[4],
            },
            "sharpened_filter": {
                "normal": out.sharpened_filter.factors().0,
                "smoothed": out.sharpened_filter.factors().1,
            },
            "sharpen_method": out.sharpen_hint.map(|h| h.name()),
            "sharpen_smooth_factor": out.sharpen_hint.and(out.sharpen_smooth_factor),
            "sharpen_curved_walls": out.sharpen_hint.and(out.sharpen_curved_walls),
            "sharpen_passes": out.sharpen_hint.map(|_| out.sharpen_passes.unwrap_or(1)),
            "sharpen_gray_labels": out.sharpen_hint.map(|_| out.sharpen_gray_labels),
            "sharpen_trials": sharpen_trials,
            "planar_tolerance": out.planar_factor,
            "quadric_projection": out.quadric_factor,
            "beside_projection": out.beside_factor,
            "crease_projection": out.crease_factor,
            "apex_projection": out.apex_factor,
            "sharpen_input_max_error_pct": out.sharpen_input_max_pct,
            "search": out.search.iter().map(|&(f, b)| json!([f, b])).collect::<Vec<_>>(),
            "angle_trials": out.angle_trials.iter().map(|t| json!({
                "angle_bits": t.angle_bits,
                "edge_length": if t.edge_length_fraction.is_finite() { json!(t.edge_length_fraction) } else { json!(null) },
                "bytes": t.bytes,
                "rms_error_pct": t.rms_pct,
                "max_error_pct": t.max_pct,
                "sharpened_rms_error_pct": t.sharpened.map(|s| s.0),
                "sharpened_max_error_pct": t.sharpened.map(|s| s.1),
            })).collect::<Vec<_>>(),
            "repair": repair_json(r),
            "dropped_unused_vertices": r.dropped_unused_vertices,
            "skipped_attributes": skipped_json(skipped),
        });
        // Field 33 (docs/sharpen.md, "Snap vetoes"); out of the literal above, which is at
        // serde_json's macro recursion limit.
        // `snap_vetoes` counts the snaps vetoed (in field 33, or through the hint "none"
        // where they were the majority); `snaps_judged` those judged (0: no judgement).
        j["snap_vetoes"] = json!(out.snap_vetoes.as_ref().map_or(0, |v| v.vetoed()));
        j["snaps_judged"] = json!(out.snap_vetoes.as_ref().map_or(0, |v| v.judged()));
        print_json(&j);
    } else {
        outln!(
            "{} -> {}: {} bytes, {} retiled vertices, {} retiled triangles (L = {:.4} of the diagonal), {:.3} bits per original vertex, {:.3} bits/retiled triangle (connectivity {} bits, geometry {} bits)",
            args.input.display(),
            args.output.display(),
            r.bytes,
            r.vertices,
            r.triangles,
            out.edge_length_fraction,
            out.bits_per_original_vertex(),
            r.bits_per_triangle(),
            r.connectivity_bits,
            r.geometry_bits
        );
    }
    Ok(())
}
