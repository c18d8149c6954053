//! `whet decode`: a `.whet` stream to a mesh file.

use super::{write_mesh, CliResult, Failure};
use clap::Args;
use std::path::PathBuf;
use whet_codec::{decode, DecodeOptions};

#[derive(Args, Debug)]
pub struct DecodeArgs {
    /// Input `.whet` file.
    input: PathBuf,
    /// Output mesh file (.obj, .off, .ply, .stl).
    #[arg(short, long)]
    output: PathBuf,
    /// Output format, overriding the extension.
    #[arg(long)]
    output_format: Option<whet::io::Format>,
}

pub fn run(args: &DecodeArgs) -> CliResult {
    let bytes = std::fs::read(&args.input).map_err(|e| {
        Failure::input(
            anyhow::Error::new(e).context(format!("cannot read {}", args.input.display())),
        )
    })?;
    let mesh = decode(&bytes, &DecodeOptions::DEFAULT).map_err(|e| {
        let input = e.is_input_error();
        let err = anyhow::Error::new(e).context(format!("cannot decode {}", args.input.display()));
        if input {
            Failure::input(err)
        } else {
            Failure::other(err)
        }
    })?;
    write_mesh(
        &args.output,
        &mesh,
        args.output_format,
        &whet::io::WriteOptions::DEFAULT,
    )
}
