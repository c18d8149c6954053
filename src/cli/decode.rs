//! `whet decode`: a `.whet` stream to a mesh file.

use super::{write_mesh, CliResult, Failure};
use clap::Args;
use std::path::PathBuf;
use whet_codec::DecodeOptions;

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
    /// Run EdgeSharpener on the decoded mesh (restores the sharp edges and corners a uniform
    /// retiling chamfered). A swing stream's snap vetoes (the snaps its encoder measured
    /// worse against the original) are replayed unless --method, --smooth-factor,
    /// --curved-walls, --passes or --gray-labels changes the sharpening they were judged
    /// for.
    #[arg(long)]
    sharpen: bool,
    /// Then refine with Bender this many levels (needs --sharpen for its tags).
    #[arg(long, value_name = "N", requires = "sharpen")]
    bend: Option<u32>,
    /// EdgeSharpener's smooth-edge factor. Without it, the one a swing stream names with
    /// its method (see --method); otherwise 2.
    #[arg(long)]
    smooth_factor: Option<f64>,
    /// EdgeSharpener's method: extended, papers, or none (decode as without --sharpen, then
    /// --bend with filter 3bis's tags). Without it, a swing stream encoded with
    /// `--optimize-for sharpened` names the method (and smooth factor) its encoder measured
    /// best against the original, or none for a part sharpening makes worse (as any swing
    /// stream does where most of the default sharpening's snaps were worse); otherwise
    /// extended.
    #[arg(long)]
    method: Option<String>,
    /// EdgeSharpener's curved-wall factor (`whet sharpen --curved-walls`; 0: off). Without
    /// it, the one a swing stream names with its method (see --method); otherwise off.
    #[arg(long, requires = "sharpen")]
    curved_walls: Option<f64>,
    /// EdgeSharpener passes (`whet sharpen --passes`). Without it, the number a swing stream
    /// names with its method (see --method); otherwise 1.
    #[arg(long, requires = "sharpen")]
    passes: Option<u32>,
    /// EdgeSharpener's gray-vertex labels on surface samplings (`whet sharpen
    /// --gray-labels`): true or false. Without it, what a swing stream states with its
    /// method (see --method); otherwise off.
    #[arg(long, value_name = "BOOL", requires = "sharpen")]
    gray_labels: Option<bool>,
    /// Subdiv streams: subdivision levels, overriding the header (0 gives the control mesh).
    #[arg(long)]
    levels: Option<u32>,
    /// Swing streams: leave out the surface filter the stream carries (the retiled vertices
    /// stay on the original surface). `--sharpen` always leaves it out before sharpening
    /// (EdgeSharpener extrapolates planes from those vertices) and applies the stream's
    /// filter for after sharpening to the vertices it left alone; with this flag, neither.
    #[arg(long)]
    no_surface_filter: bool,
    /// Memory budget in bytes for what a stream or a level count asks for: the container's
    /// payloads, the decoded mesh (from the header's counts), a subdiv stream's levels,
    /// `--sharpen` and `--bend` are estimated and refused before they run when they need
    /// more.
    #[arg(long, value_name = "BYTES", default_value_t = super::DEFAULT_MAX_MEMORY)]
    max_memory: u64,
}

pub fn run(args: &DecodeArgs) -> CliResult {
    let bytes = super::read_stream_file(&args.input, args.max_memory)?;
    let limits = whet_format::Limits::DEFAULT.with_max_alloc_bytes(args.max_memory);
    if args.sharpen {
        // An exact or swing stream states its triangle count: refuse sharpening it before
        // decoding when that alone passes the budget (checked again on the decoded mesh).
        if let Ok(h) = whet_codec::peek_header(&bytes) {
            if matches!(h.mode, whet_format::Mode::Exact | whet_format::Mode::Swing) {
                check_sharpen_memory(h.triangle_count, args.max_memory)?;
            }
        }
    }
    let opts = DecodeOptions::DEFAULT
        .with_surface_filter(!(args.no_surface_filter || args.sharpen))
        .with_limits(limits);
    let mesh = whet::decode_with_levels(&bytes, &opts, args.levels).map_err(|e| {
        let input = e.is_input_error();
        // The byte limits are --max-memory here: say so where the library says "Limits".
        let hint = if over_max_memory(&e) {
            " (--max-memory sets the byte limit)"
        } else {
            ""
        };
        let err =
            anyhow::Error::new(e).context(format!("cannot decode {}{hint}", args.input.display()));
        if input {
            Failure::input(err)
        } else {
            Failure::other(err)
        }
    })?;
    let mesh = if args.sharpen {
        check_sharpen_memory(mesh.triangles.len() as u64, args.max_memory)?;
        let header = whet_format::parse(&bytes, &limits).ok().map(|c| c.header);
        // The stream's choice (`SharpenHint::stated`); an explicit --method replaces it,
        // factor included.
        let stated = header.as_ref().and_then(whet_codec::SharpenHint::stated);
        let (method, stream_factor, stream_walls, stream_passes, stream_gray) =
            match (&args.method, stated) {
                (Some(m), _) => (m.as_str(), None, None, None, false),
                (None, Some((h, f))) => {
                    let h2 = header.as_ref();
                    (
                        h.name(),
                        Some(f),
                        h2.and_then(whet_codec::SharpenHint::curved_walls_of),
                        h2.and_then(whet_codec::SharpenHint::passes_of),
                        h2.is_some_and(whet_codec::SharpenHint::gray_labels_of),
                    )
                }
                (None, None) => ("extended", None, None, None, false),
            };
        // The explicit values are checked even where no sharpening runs.
        let explicit = whet_sharpen::SharpenOptions::DEFAULT
            .with_passes(args.passes.unwrap_or(1))
            .with_curved_wall_factor(args.curved_walls.unwrap_or(0.0));
        explicit.validate().map_err(super::Failure::input)?;
        if method == whet_codec::SharpenHint::Unsharpened.name() {
            // No candidate beat the decoded mesh (or `--method none`): what `whet decode`
            // gives without --sharpen (the stream's own surface filter included).
            if args.method.is_none() {
                eprintln!(
                    "whet: the stream's encoder measured sharpening as no gain on this mesh; \
                     decoding without it (--method extended|papers sharpens anyway)"
                );
            }
            let plain = if args.no_surface_filter {
                mesh
            } else {
                let opts = DecodeOptions::DEFAULT.with_limits(limits);
                whet::decode_with_levels(&bytes, &opts, args.levels)
                    .map_err(|e| Failure::other(anyhow::Error::new(e)))?
            };
            return match args.bend {
                Some(levels) => {
                    // No sharpening, so no tags from it: filter 3bis's, as `whet bend`
                    // without --tags, so that creases the retiling kept stay sharp.
                    let tags = super::sharpen::fallback_tags(&plain)?;
                    let bent = bend_levels(&plain, &tags, levels, args.max_memory)?;
                    write_decoded(args, &bent)
                }
                None => write_decoded(args, &plain),
            };
        }
        let smooth_factor = args.smooth_factor.or(stream_factor).unwrap_or(2.0);
        let mut opts = super::sharpen::sharpen_options(method, smooth_factor)?
            .with_passes(args.passes.or(stream_passes).unwrap_or(1))
            .with_surface_gray_labels(args.gray_labels.unwrap_or(stream_gray))
            // Passes after the first run on grown meshes: each is held to the budget the
            // first was checked against.
            .with_pass_budget_triangles(args.max_memory / whet_sharpen::PEAK_BYTES_PER_TRIANGLE);
        if let Some(w) = args.curved_walls.or(stream_walls) {
            opts = opts.with_curved_wall_factor(w);
        }
        opts.validate().map_err(super::Failure::input)?;
        // The stream's snap vetoes (field 33) were judged for the sharpening it states: they
        // are replayed only when no option changes that sharpening.
        let own_sharpening = args.method.is_none()
            && args.smooth_factor.is_none()
            && args.curved_walls.is_none()
            && args.passes.is_none()
            && args.gray_labels.is_none();
        let mut replay = match (&header, own_sharpening) {
            (Some(h), true) => super::sharpen::stated_vetoes(h)?,
            _ => None,
        };
        let mut s = super::sharpen::run_sharpen_replayed(&mesh, &opts, replay.as_mut())?;
        if !args.no_surface_filter {
            // A swing stream's filter for after sharpening: the smooth parts the sharpener
            // left alone get the surface filter fitted for them (docs/swing.md section 2).
            if let Some(h) = &header {
                whet_codec::SurfaceFilter::after_sharpening_of(h)
                    .apply_after_sharpening(&mesh, &mut s.mesh);
                // Then the flat faces onto their planes, the curved ones onto local
                // quadrics, the face vertices beside creases onto their own side's quadric
                // and the crease vertices onto their sides' intersection, when the
                // stream says so.
                super::sharpen::project_as_stated(h, &mut s.mesh);
            }
        }
        match args.bend {
            Some(levels) => bend_levels(
                &s.mesh,
                &super::sharpen::tag_edges(&s.tags),
                levels,
                args.max_memory,
            )?,
            None => s.mesh,
        }
    } else {
        mesh
    };
    write_decoded(args, &mesh)
}

fn write_decoded(args: &DecodeArgs, mesh: &whet::Mesh) -> CliResult {
    write_mesh(
        &args.output,
        mesh,
        args.output_format,
        &whet::io::WriteOptions::DEFAULT,
    )
}

/// Bender over `mesh` with its sharp-edge tags (at most 8 levels).
fn bend_levels(
    mesh: &whet::Mesh,
    tags: &[[u32; 2]],
    levels: u32,
    max_memory: u64,
) -> CliResult<whet::Mesh> {
    if levels > 8 {
        return Err(Failure::input(anyhow::anyhow!(
            "--bend {levels}: at most 8 levels"
        )));
    }
    super::sharpen::run_bend(mesh, tags, levels, max_memory)
}

/// Refuses (exit code 2) sharpening `triangles` triangles past `max_memory` bytes at the
/// sharpener's measured peak per triangle.
fn check_sharpen_memory(triangles: u64, max_memory: u64) -> CliResult {
    let peak = triangles.saturating_mul(whet_sharpen::PEAK_BYTES_PER_TRIANGLE);
    if peak > max_memory {
        return Err(Failure::input(anyhow::anyhow!(
            "sharpening {triangles} triangles would take about {} at {} bytes each, over \
             --max-memory {max_memory} bytes: raise --max-memory or decode without --sharpen",
            super::human_bytes(peak),
            whet_sharpen::PEAK_BYTES_PER_TRIANGLE,
        )));
    }
    Ok(())
}

/// True when `e` refused the stream for the allocation budget that `--max-memory` sets
/// (`Limits::max_alloc_bytes`), not for a count or section-length limit, which it does not.
fn over_max_memory(e: &whet::Error) -> bool {
    fn codec(e: &whet_codec::Error) -> bool {
        matches!(
            e,
            whet_codec::Error::Format(whet_format::Error::LimitExceeded { what, .. })
                if *what == whet_format::ALLOCATION_LIMIT || *what == whet_codec::DECODE_PEAK_LIMIT
        )
    }
    match e {
        whet::Error::Codec(c) => codec(c),
        whet::Error::Subdiv(whet_subdiv::Error::Codec(c)) => codec(c),
        whet::Error::Subdiv(whet_subdiv::Error::LimitExceeded { what, .. }) => {
            *what == whet_subdiv::SUBDIVISION_PEAK_LIMIT
        }
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::over_max_memory;

    fn limit(what: &'static str) -> whet_format::Error {
        whet_format::Error::LimitExceeded {
            what,
            limit: 1,
            value: 2,
        }
    }

    #[test]
    fn only_byte_budget_refusals_point_at_max_memory() {
        let codec = |w| whet::Error::Codec(whet_codec::Error::Format(limit(w)));
        let control = |w| {
            whet::Error::Subdiv(whet_subdiv::Error::Codec(whet_codec::Error::Format(limit(
                w,
            ))))
        };
        assert!(over_max_memory(&codec("allocation (bytes)")));
        assert!(over_max_memory(&codec(
            "bytes decoding allocates (estimated)"
        )));
        assert!(over_max_memory(&control(
            "bytes decoding allocates (estimated)"
        )));
        assert!(over_max_memory(&whet::Error::Subdiv(
            whet_subdiv::Error::LimitExceeded {
                what: "bytes the subdivision allocates (estimated)",
                limit: 1,
                value: 2,
            }
        )));
        // Limits --max-memory does not set.
        assert!(!over_max_memory(&codec("section length (bytes)")));
        assert!(!over_max_memory(&codec("triangle count")));
        assert!(!over_max_memory(&whet::Error::Subdiv(
            whet_subdiv::Error::LimitExceeded {
                what: "decoded triangles",
                limit: 1,
                value: 2,
            }
        )));
    }
}
