//! `whet encode`: a mesh file to a `.whet` stream.

use super::{print_json, read_mesh, CliResult, Failure};
use clap::{Args, ValueEnum};
use serde_json::json;
use std::path::PathBuf;
use whet_codec::{EncodeOptions, Encoder, Mode};

/// Codec modes selectable on the command line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum ModeArg {
    /// Edgebreaker connectivity + quantized parallelogram-predicted positions (lossless
    /// connectivity).
    Exact,
}

#[derive(Args, Debug)]
pub struct EncodeArgs {
    /// Input mesh file.
    input: PathBuf,
    /// Output `.whet` file.
    #[arg(short, long)]
    output: PathBuf,
    /// Codec mode.
    #[arg(long, value_enum, default_value_t = ModeArg::Exact)]
    mode: ModeArg,
    /// Position quantization bits per coordinate (exact mode).
    #[arg(long, default_value_t = 14, value_parser = clap::value_parser!(u32).range(1..=30))]
    quant_bits: u32,
    /// Input format, overriding the extension.
    #[arg(long)]
    format: Option<whet::io::Format>,
    /// Print one JSON object with the stream's figures.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &EncodeArgs) -> CliResult {
    let mesh = read_mesh(&args.input, args.format)?;
    let mode = match args.mode {
        ModeArg::Exact => Mode::Exact,
    };
    let opts = EncodeOptions::DEFAULT
        .with_mode(mode)
        .with_quant_bits(args.quant_bits);
    let encoded = Encoder::new(opts).encode(&mesh).map_err(|e| {
        let input = !matches!(e, whet_codec::Error::Parameter(_));
        let err = anyhow::Error::new(e).context(format!("cannot encode {}", args.input.display()));
        if input {
            Failure::input(err)
        } else {
            Failure::other(err)
        }
    })?;
    std::fs::write(&args.output, &encoded.bytes).map_err(|e| {
        Failure::other(
            anyhow::Error::new(e).context(format!("cannot write {}", args.output.display())),
        )
    })?;
    let r = &encoded.report;
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
            "quant_bits": args.quant_bits,
            "components": r.components,
            "clers_histogram": { "C": h[0], "L": h[1], "E": h[2], "R": h[3], "S": h[4] },
            "repair": {
                "dropped_out_of_range": r.repair.dropped_out_of_range,
                "dropped_degenerate": r.repair.dropped_degenerate,
                "dropped_duplicates": r.repair.dropped_duplicates,
                "flipped_triangles": r.repair.flipped_triangles,
                "cut_edges": r.repair.cut_edges,
                "added_vertices": r.repair.added_vertices,
            },
            "dropped_unused_vertices": r.dropped_unused_vertices,
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
