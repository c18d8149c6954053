//! `whet convert`: between OFF, OBJ, PLY and STL.

use super::{read_mesh_noting_skipped, write_mesh, CliResult};
use clap::Args;
use std::path::PathBuf;
use whet::io::{Format, PlyEncoding, StlEncoding, WriteOptions};

#[derive(Args, Debug)]
pub struct ConvertArgs {
    /// Input mesh file.
    input: PathBuf,
    /// Output mesh file; its extension picks the format.
    #[arg(short, long)]
    output: PathBuf,
    /// Input format, overriding the input's extension.
    #[arg(long)]
    format: Option<Format>,
    /// Output format, overriding the output's extension.
    #[arg(long)]
    output_format: Option<Format>,
    /// Write PLY and STL as text instead of binary.
    #[arg(long)]
    ascii: bool,
    /// Write binary PLY big-endian instead of little-endian.
    #[arg(long, conflicts_with = "ascii")]
    big_endian: bool,
    /// Cut non-manifold vertices and edges first (see `Mesh::make_manifold`) and report it.
    #[arg(long)]
    make_manifold: bool,
}

pub fn run(args: &ConvertArgs) -> CliResult {
    let (mut mesh, _) = read_mesh_noting_skipped(&args.input, args.format)?;
    if args.make_manifold {
        let rep = mesh.make_manifold();
        eprintln!("make_manifold: {rep}");
    }
    let mut opts = WriteOptions::DEFAULT;
    opts.ply = if args.ascii {
        PlyEncoding::Ascii
    } else if args.big_endian {
        PlyEncoding::BinaryBigEndian
    } else {
        PlyEncoding::BinaryLittleEndian
    };
    opts.stl = if args.ascii {
        StlEncoding::Ascii
    } else {
        StlEncoding::Binary
    };
    write_mesh(&args.output, &mesh, args.output_format, &opts)
}
