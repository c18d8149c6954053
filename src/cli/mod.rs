//! Subcommands of the `whet` binary, one module each, and the mapping of failures to exit
//! codes.

/// `print!` that ends the process quietly when stdout is a closed pipe (`whet info | head`)
/// instead of panicking.
macro_rules! out {
    ($($arg:tt)*) => {
        $crate::cli::write_stdout(&format!($($arg)*))
    };
}

/// `println!` with the same pipe handling as [`out!`].
macro_rules! outln {
    () => {
        $crate::cli::write_stdout("\n")
    };
    ($($arg:tt)*) => {
        $crate::cli::write_stdout(&format!("{}\n", format!($($arg)*)))
    };
}

mod convert;
mod decode;
mod demo;
mod encode;
mod encode_subdiv;
mod info;
mod metro;
mod rd;
mod sharpen;
mod subdivide;
mod synth;

use clap::{Parser, Subcommand};
use std::path::Path;

/// whet: a mesh codec that re-tiles, codes connectivity with Edgebreaker and restores sharp
/// features after decoding.
#[derive(Parser, Debug)]
#[command(name = "whet", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Print counts, topology and problems of a mesh.
    Info(info::InfoArgs),
    /// Convert a mesh between OFF, OBJ, PLY and STL.
    Convert(convert::ConvertArgs),
    /// Encode a mesh into a .whet stream.
    Encode(encode::EncodeArgs),
    /// Decode a .whet stream into a mesh file.
    Decode(decode::DecodeArgs),
    /// Metro error (max, mean, RMS) between a reference and a test surface.
    Metro(metro::MetroArgs),
    /// Ground-truth shapes and their marching-cubes samplings.
    Synth(synth::SynthArgs),
    /// EdgeSharpener: restore the sharp edges and corners a uniform resampling chamfered.
    Sharpen(sharpen::SharpenArgs),
    /// Bender: feature-preserving interpolatory subdivision.
    Bend(sharpen::BendArgs),
    /// Semi-sharp Loop subdivision of a control mesh.
    Subdivide(subdivide::SubdivideArgs),
    /// Rate-distortion sweep: encode, decode, post-process and measure at several rates.
    Rd(rd::RdArgs),
    /// The main job on a mesh whet generates: a rate-distortion sweep of the synthetic fandisk.
    Demo(demo::DemoArgs),
}

/// A failed command: the error to print and the exit code.
pub struct Failure {
    pub code: u8,
    pub error: anyhow::Error,
}

/// Exit code of an input that cannot be read as a mesh or stream.
pub const EXIT_BAD_INPUT: u8 = 2;
/// Exit code of every other failure.
pub const EXIT_FAILURE: u8 = 1;

impl Failure {
    pub fn input(error: impl Into<anyhow::Error>) -> Failure {
        Failure {
            code: EXIT_BAD_INPUT,
            error: error.into(),
        }
    }
    pub fn other(error: impl Into<anyhow::Error>) -> Failure {
        Failure {
            code: EXIT_FAILURE,
            error: error.into(),
        }
    }
}

pub type CliResult<T = ()> = Result<T, Failure>;

/// The message of `error` with its causes, `: `-separated, leaving out a cause whose text
/// the message already holds: the library errors quote their source (`I/O error: {0}`) so
/// that they read whole on their own, and anyhow's chain would print it a second time.
pub fn error_chain(error: &anyhow::Error) -> String {
    let mut out = String::new();
    for cause in error.chain() {
        let text = cause.to_string();
        if out.contains(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out
}

pub fn run(cli: Cli) -> CliResult {
    match cli.command {
        Command::Info(a) => info::run(&a),
        Command::Convert(a) => convert::run(&a),
        Command::Encode(a) => encode::run(&a),
        Command::Decode(a) => decode::run(&a),
        Command::Metro(a) => metro::run(&a),
        Command::Synth(a) => synth::run(&a),
        Command::Rd(a) => rd::run(&a),
        Command::Subdivide(a) => subdivide::run(&a),
        Command::Sharpen(a) => sharpen::run(&a),
        Command::Bend(a) => sharpen::run_bend_cmd(&a),
        Command::Demo(a) => demo::run(&a),
    }
}

/// Default of the `--max-memory` flags: the decoder's allocation limit
/// (`whet_format::Limits::DEFAULT`, 4 GiB).
pub const DEFAULT_MAX_MEMORY: u64 = whet_format::Limits::DEFAULT.max_alloc_bytes;

/// The bytes of the stream file `path`, refused before reading when the file is larger than
/// `max_bytes` (a decoder holds the whole stream: a huge file must not fill the memory before
/// any limit is checked).
pub fn read_stream_file(path: &Path, max_bytes: u64) -> CliResult<Vec<u8>> {
    let cannot = |e: std::io::Error| {
        Failure::input(anyhow::Error::new(e).context(format!("cannot read {}", path.display())))
    };
    let len = std::fs::metadata(path).map_err(cannot)?.len();
    if len > max_bytes {
        return Err(Failure::input(anyhow::anyhow!(
            "{} is {len} bytes, more than the memory budget of {max_bytes} bytes (--max-memory)",
            path.display()
        )));
    }
    std::fs::read(path).map_err(cannot)
}

/// Refuses (exit code 2) an operation whose output of `triangles` triangles would take more
/// than `max_memory` bytes at `bytes_per_triangle` (the operation's measured peak): a few
/// levels of subdivision turn a small mesh into one no machine holds, and the allocator would
/// fail only after minutes of work, or the system would kill the process.
pub fn check_memory(
    what: &str,
    triangles: u64,
    bytes_per_triangle: u64,
    max_memory: u64,
) -> CliResult {
    let bytes = triangles.saturating_mul(bytes_per_triangle);
    if bytes > max_memory {
        return Err(Failure::input(anyhow::anyhow!(
            "{what} would make {triangles} triangles, about {} at {bytes_per_triangle} bytes \
             each, over --max-memory {max_memory} bytes: use fewer levels or raise \
             --max-memory",
            human_bytes(bytes)
        )));
    }
    Ok(())
}

/// `mesh` itself when it is an oriented manifold, else its [`whet::Mesh::make_manifold`]
/// repair, said on stderr in the words `whet encode` and `whet sharpen` use: every command
/// that needs a manifold takes what those two take. `make_manifold` keeps the indices of
/// the vertices it does not split (a split appends the extra copies), so sidecar files that
/// name vertices (sharp-edge tags, edge sharpness) still apply.
pub fn manifold(mesh: whet::Mesh) -> whet::Mesh {
    match whet_mesh::CornerTable::new(&mesh) {
        Err(e) if e.is_structural() => {
            let mut m = mesh;
            let rep = m.make_manifold();
            eprintln!("whet: the mesh is not an oriented manifold ({e}); make_manifold {rep}");
            m
        }
        _ => mesh,
    }
}

/// `bytes` in the largest of B, kB, MB, GB that keeps a unit digit.
pub fn human_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    match bytes {
        0..1_000 => format!("{bytes} B"),
        1_000..1_000_000 => format!("{:.1} kB", b / 1e3),
        1_000_000..1_000_000_000 => format!("{:.1} MB", b / 1e6),
        _ => format!("{:.1} GB", b / 1e9),
    }
}

/// Output triangles of `levels` 1-to-4 splits of `triangles` (saturating).
pub fn split_triangles(triangles: usize, levels: u32) -> u64 {
    (triangles as u64).saturating_mul(4u64.saturating_pow(levels))
}

/// Reads a mesh file, mapping unreadable input to exit code 2 with the path in the message.
pub fn read_mesh(path: &Path, format: Option<whet::io::Format>) -> CliResult<whet::Mesh> {
    whet::io::read_path(path, format).map_err(|e| read_failure(path, e))
}

/// Reads a mesh file as [`read_mesh`] does, and says on stderr what the file held that whet
/// does not keep (one note line, none when nothing was skipped); returns the report too, for
/// JSON output.
pub fn read_mesh_noting_skipped(
    path: &Path,
    format: Option<whet::io::Format>,
) -> CliResult<(whet::Mesh, whet::io::ReadReport)> {
    let (mesh, report) =
        whet::io::read_path_with_report(path, format).map_err(|e| read_failure(path, e))?;
    if !report.is_empty() {
        eprintln!(
            "whet: note: {}: {report} not kept (whet codes positions and triangles only)",
            path.display()
        );
    }
    Ok((mesh, report))
}

/// The `skipped_attributes` array of `--json` output: one `{"what", "count"}` object per
/// kind of data the reader skipped, empty when it skipped nothing.
pub fn skipped_json(report: &whet::io::ReadReport) -> serde_json::Value {
    report
        .skipped
        .iter()
        .map(|s| serde_json::json!({ "what": s.what, "count": s.count }))
        .collect()
}

/// A read error as a failure: exit code 2 for input that cannot be read as a mesh (or a
/// missing file), 1 otherwise, with the path in the message.
fn read_failure(path: &Path, e: whet::io::Error) -> Failure {
    let code = if e.is_input_error() || path_missing(path) {
        EXIT_BAD_INPUT
    } else {
        EXIT_FAILURE
    };
    Failure {
        code,
        error: anyhow::Error::new(e).context(format!("cannot read {}", path.display())),
    }
}

/// Writes a mesh file; any failure is exit code 1.
pub fn write_mesh(
    path: &Path,
    mesh: &whet::Mesh,
    format: Option<whet::io::Format>,
    opts: &whet::io::WriteOptions,
) -> CliResult {
    whet::io::write_path(path, mesh, format, opts).map_err(|e| {
        Failure::other(anyhow::Error::new(e).context(format!("cannot write {}", path.display())))
    })
}

fn path_missing(path: &Path) -> bool {
    !path.exists()
}

/// Prints one JSON value on stdout.
pub fn print_json(value: &serde_json::Value) {
    // serde_json's Display of a Value cannot fail.
    outln!("{value}");
}

/// Writes to stdout; a closed pipe ends the process with success (the reader has what it
/// wanted), any other error with exit code 1.
pub fn write_stdout(text: &str) {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_all(text.as_bytes()).and_then(|_| out.flush()) {
        if e.kind() == std::io::ErrorKind::BrokenPipe {
            std::process::exit(0);
        }
        eprintln!("whet: cannot write to stdout: {e}");
        std::process::exit(EXIT_FAILURE as i32);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cause_the_message_quotes_is_printed_once() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "no such file");
        let read = whet_io::Error::from(io);
        let e = anyhow::Error::new(read).context("cannot read x.off");
        assert_eq!(
            error_chain(&e),
            "cannot read x.off: I/O error: no such file"
        );
        // A cause that adds something is kept.
        let e = anyhow::anyhow!("inner detail").context("outer");
        assert_eq!(error_chain(&e), "outer: inner detail");
    }
}
