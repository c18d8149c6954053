//! `whet sharpen` (EdgeSharpener) and `whet bend` (Bender), and the helpers `whet decode`
//! uses to run them after decoding.

use super::{print_json, read_mesh, write_mesh, CliResult, Failure};
use clap::Args;
use std::path::PathBuf;
use whet::Mesh;
use whet_sharpen::{
    sharpen, sharpen_region, Method, SharpTags, SharpenOptions, Sharpened, VertexSelection,
};

#[derive(Args, Debug)]
pub struct SharpenArgs {
    /// Input mesh (e.g. a decoded retiled mesh).
    input: PathBuf,
    /// Output mesh.
    #[arg(short, long)]
    output: PathBuf,
    /// An edge is smooth when its normal angle is under this factor times the mesh average.
    #[arg(long, default_value_t = 2.0)]
    smooth_factor: f64,
    /// `extended` (default: whet's extended chamfer detection), `papers` (the papers'
    /// six filters only) or `normal-filter` (seed 002: blends, chamfers with samples, noise).
    #[arg(long, default_value = "extended")]
    method: String,
    /// extended: do not weld the clusters of near-coincident vertices joined by zero-area
    /// triangles (marching cubes' output). They are welded before the run, so that their
    /// slivers do not keep chamfers from being cut, and put back wherever the output left them
    /// untouched; a vertex that stays welded keeps its index, used by no triangle.
    #[arg(long)]
    no_weld: bool,
    /// extended: sharpen every part, also those whose creases are already sharp (most of
    /// their strong creases on edges between smooth regions: a CAD original, or a mesh
    /// sharpened before), which are otherwise left alone; their narrow real faces and coarse
    /// facets then get taken for chamfers.
    #[arg(long)]
    no_sharp_parts: bool,
    /// extended: sharpen every part of a surface sampling, also those where most chamfer
    /// edges found are refused as curved (a surface that bends everywhere: an organic model),
    /// which are otherwise left alone; their few chamfer edges that pass get cut.
    #[arg(long)]
    no_curved_parts: bool,
    /// extended: on a surface sampling (a retiling, a swing-decoded mesh) give the gray
    /// vertices, those in no smooth triangle, the plane of a neighbour they lie on, as
    /// marching cubes always do: a chamfer two triangles wide then gets cut, but so does a
    /// blend a few samples wide (off by default; a swing stream states it where its encoder
    /// measured it better).
    #[arg(long)]
    gray_labels: bool,
    /// extended and papers: where two rings of triangles lie outside every smooth region, an
    /// edge turning by under this factor times the smooth threshold counts as smooth, so a
    /// face curved at the sampling's scale (a small hole's wall) gets its chamfers found.
    /// 0 (the default) is off; 1 to 4 otherwise (2 measured best).
    #[arg(long)]
    curved_walls: Option<f64>,
    /// extended and papers: run the sharpener this many times (1 to 4), each pass on the
    /// previous one's output; a pass's splits can leave chamfers the next finds. On
    /// marching-cubes input 2 lowered the max or the RMS on every sampling measured (the max
    /// nowhere higher; a third pass adds nothing), for 65-80 % more time.
    #[arg(long, default_value_t = 1)]
    passes: u32,
    /// normal-filter: neighbourhood radius in mean edge lengths (a little more than the widest
    /// feature to sharpen).
    #[arg(long, default_value_t = SharpenOptions::DEFAULT.rho)]
    rho: f64,
    /// normal-filter: a face is a feature face when two normals of its neighbourhood have a dot
    /// product under eta.
    #[arg(long, default_value_t = SharpenOptions::DEFAULT.eta, allow_negative_numbers = true)]
    eta: f64,
    /// normal-filter: the neighbourhood does not cross edges whose normals' dot product is at
    /// most lambda.
    #[arg(long, default_value_t = SharpenOptions::DEFAULT.lambda, allow_negative_numbers = true)]
    lambda: f64,
    /// normal-filter: change only this region, a file of 0-based vertex indices separated by
    /// whitespace (`#` starts a comment).
    #[arg(long)]
    select: Option<PathBuf>,
    /// After sharpening, move the vertex nearest each cut cone tip or corner onto the point
    /// where the tangent planes of the vertices 1.5 to 5 edges around it meet
    /// (docs/sharpen.md, "Apex restoration"). Off by default: a rounded corner whose radius
    /// is under the sampling is taken for a cut one (`whet decode --sharpen` applies it where
    /// the stream's encoder measured a gain, header field 39).
    #[arg(long)]
    restore_apexes: bool,
    /// Write the sharp-edge tags (for `whet bend --tags`) to this file.
    #[arg(long)]
    tags: Option<PathBuf>,
    /// Print the report as one JSON object.
    #[arg(long)]
    json: bool,
}

/// Options from the command line's words.
pub fn sharpen_options(method: &str, smooth_factor: f64) -> Result<SharpenOptions, Failure> {
    let method: Method = method.parse().map_err(Failure::input)?;
    let opts = SharpenOptions::DEFAULT
        .with_method(method)
        .with_smooth_factor(smooth_factor);
    opts.validate().map_err(Failure::input)?;
    Ok(opts)
}

/// Sharpens, cutting non-manifold input first (and saying so).
pub fn run_sharpen(mesh: &Mesh, opts: &SharpenOptions) -> CliResult<Sharpened> {
    run_sharpen_replayed(mesh, opts, None)
}

/// [`run_sharpen`] replaying a stream's snap vetoes (field 33) when `replay` is given; a
/// warning says so when they did not fit the run (they are then not applied).
pub fn run_sharpen_replayed(
    mesh: &Mesh,
    opts: &SharpenOptions,
    mut replay: Option<&mut whet_sharpen::VetoReplay>,
) -> CliResult<Sharpened> {
    let mut run = |m: &Mesh| match replay.as_deref_mut() {
        Some(r) => whet_sharpen::sharpen_judged(m, opts, r),
        None => sharpen(m, opts),
    };
    let out = match run(mesh) {
        Ok(s) => Ok(s),
        Err(whet_sharpen::Error::InvalidInput(e)) if e.is_structural() => {
            let mut m = mesh.clone();
            let rep = m.make_manifold();
            eprintln!("whet: the mesh is not an oriented manifold ({e}); make_manifold {rep}");
            run(&m).map_err(Failure::input)
        }
        Err(e) => Err(Failure::input(e)),
    }?;
    if let Some(r) = replay {
        if r.mismatched_passes() > 0 {
            eprintln!(
                "whet: the stream's snap vetoes do not fit this sharpening run ({} of its \
                 passes differ); they were not applied there",
                r.mismatched_passes()
            );
        }
    }
    Ok(out)
}

/// The snap vetoes a swing stream's header states (field 33) for the sharpening it states,
/// ready to replay; `None` without the field. A malformed field is bad input.
pub fn stated_vetoes(header: &whet_format::Header) -> CliResult<Option<whet_sharpen::VetoReplay>> {
    match whet_codec::SnapVetoes::of(header) {
        None => Ok(None),
        Some(Ok(v)) => Ok(Some(whet_sharpen::VetoReplay::new(v.into_passes()))),
        Some(Err(e)) => Err(Failure::input(e)),
    }
}

/// A swing stream's projections after sharpening, applied to `sharpened`: the output of the
/// sharpening and of the stream's filter for after sharpening (docs/swing.md section 2).
/// First the planar-region projection (optional header field 25), then the local quadric
/// projection (field 31), then the one-sided quadric projection beside creases (field 37),
/// then the crease projection (field 35), then the apex restoration (field 39). A mesh a projection refuses (it needs an oriented manifold, which
/// sharpening gives) is kept as it is with a warning, as the encoder's measurement keeps
/// it: the fields are optional refinements, not part of the decoded mesh.
pub fn project_as_stated(header: &whet_format::Header, sharpened: &mut Mesh) {
    let projections = whet_swing::StatedProjection::all_of(header);
    for (p, e) in whet_swing::StatedProjection::apply_all(&projections, sharpened) {
        eprintln!("whet: the {} projection was skipped: {e}", p.name());
    }
}

pub fn run(args: &SharpenArgs) -> CliResult {
    let mesh = read_mesh(&args.input, None)?;
    let opts = sharpen_options(&args.method, args.smooth_factor)?
        .with_rho(args.rho)
        .with_eta(args.eta)
        .with_lambda(args.lambda)
        .with_weld_clusters(!args.no_weld)
        .with_keep_sharp_parts(!args.no_sharp_parts)
        .with_keep_curved_parts(!args.no_curved_parts)
        .with_surface_gray_labels(args.gray_labels)
        .with_passes(args.passes);
    let opts = match args.curved_walls {
        Some(w) => opts.with_curved_wall_factor(w),
        None => opts,
    };
    opts.validate().map_err(Failure::input)?;
    let mut out = match &args.select {
        None => run_sharpen(&mesh, &opts)?,
        Some(path) => {
            if opts.method != Method::NormalFilter {
                return Err(Failure::input(anyhow::anyhow!(
                    "--select works with --method normal-filter only"
                )));
            }
            // A selection names vertices of this mesh: no make_manifold (it renumbers).
            let region = VertexSelection::read_path(path, &mesh).map_err(|e| {
                Failure::input(
                    anyhow::Error::new(e).context(format!("cannot read {}", path.display())),
                )
            })?;
            sharpen_region(&mesh, &opts, &region).map_err(Failure::input)?
        }
    };
    let apexes = if args.restore_apexes {
        let opts = whet_sharpen::ApexOptions::DEFAULT;
        Some(whet_sharpen::restore_apexes(&mut out.mesh, &opts).map_err(Failure::input)?)
    } else {
        None
    };
    write_mesh(
        &args.output,
        &out.mesh,
        None,
        &whet::io::WriteOptions::DEFAULT,
    )?;
    if let Some(t) = &args.tags {
        out.tags.write_path(t, &out.mesh).map_err(|e| {
            Failure::other(anyhow::Error::new(e).context(format!("cannot write {}", t.display())))
        })?;
    }
    if out.report.welded_vertices > 0 {
        // The file keeps them (input vertex i is output vertex i); say why they are unused.
        eprintln!(
            "whet: welded {} near-coincident input vertices into a neighbour (marching-cubes \
             clusters); they stay in the output at their index, used by no triangle \
             (--no-weld keeps them)",
            out.report.welded_vertices
        );
    }
    if out.report.already_sharp_components > 0 {
        // An unchanged output is otherwise a puzzle: say why.
        eprintln!(
            "whet: left {} already sharp part(s) unchanged (their creases run along edges, \
             not across chamfers; --no-sharp-parts sharpens them anyway)",
            out.report.already_sharp_components
        );
    }
    if out.report.curved_parts > 0 {
        eprintln!(
            "whet: left {} curved part(s) unchanged (most chamfer edges found there were \
             refused as curved; --no-curved-parts sharpens them anyway)",
            out.report.curved_parts
        );
    }
    if args.json {
        let mut v: serde_json::Value = serde_json::from_str(&out.report.to_json())
            .map_err(|e| Failure::other(anyhow::Error::new(e)))?;
        // null without --restore-apexes.
        v["apex_restoration"] = match apexes {
            Some(r) => serde_json::json!({
                "candidates": r.candidates,
                "spread": r.spread,
                "fitted": r.fitted,
                "moved_vertices": r.moved_vertices,
                "refused_moves": r.refused_moves,
            }),
            None => serde_json::Value::Null,
        };
        print_json(&v);
    } else {
        eprintln!(
            "{} -> {}: {} vertices, {} triangles",
            args.input.display(),
            args.output.display(),
            out.mesh.positions.len(),
            out.mesh.triangles.len()
        );
    }
    Ok(())
}

#[derive(Args, Debug)]
pub struct BendArgs {
    /// Input mesh (e.g. a sharpened one).
    input: PathBuf,
    /// Output mesh.
    #[arg(short, long)]
    output: PathBuf,
    /// Subdivision levels.
    #[arg(long, default_value_t = 1)]
    levels: u32,
    /// Sharp-edge tags written by `whet sharpen --tags`; without it the edges are tagged by
    /// EdgeSharpener's filter 3bis rule on the input.
    #[arg(long)]
    tags: Option<PathBuf>,
    /// Refuse to start when the output would need more than this many bytes (estimated from
    /// the output's triangle count).
    #[arg(long, value_name = "BYTES", default_value_t = super::DEFAULT_MAX_MEMORY)]
    max_memory: u64,
}

/// Sharp edges of `tags` as plain pairs.
pub fn tag_edges(tags: &SharpTags) -> Vec<[u32; 2]> {
    tags.edges.iter().map(|e| [e[0].0, e[1].0]).collect()
}

/// Tags for a mesh that came without them: EdgeSharpener's filter 3bis on the mesh, keeping
/// the sharp edges that are edges of the mesh itself.
pub fn fallback_tags(mesh: &Mesh) -> CliResult<Vec<[u32; 2]>> {
    let s = run_sharpen(mesh, &SharpenOptions::DEFAULT)?;
    let n = mesh.positions.len() as u32;
    let mut own: Vec<u64> = mesh
        .undirected_edges()
        .iter()
        .map(|e| whet::edge_key(e[0], e[1]))
        .collect();
    own.sort_unstable();
    Ok(tag_edges(&s.tags)
        .into_iter()
        .filter(|e| e[0] < n && e[1] < n && own.binary_search(&whet::edge_key(e[0], e[1])).is_ok())
        .collect())
}

/// Refuses `levels` levels of Bender on `triangles` triangles past `max_memory`.
fn check_bend_memory(triangles: usize, levels: u32, max_memory: u64) -> CliResult {
    super::check_memory(
        &format!("{levels} levels of Bender"),
        super::split_triangles(triangles, levels),
        whet_bend::PEAK_BYTES_PER_OUTPUT_TRIANGLE,
        max_memory,
    )
}

/// Bender, `levels` times; errors are input errors.
fn bend(mesh: &Mesh, sharp: &[[u32; 2]], levels: u32) -> CliResult<Mesh> {
    whet_bend::bend_levels(mesh, sharp, levels)
        .map(|b| b.mesh)
        .map_err(Failure::input)
}

/// Bender, `levels` times, after checking its estimated peak memory against `max_memory`.
pub fn run_bend(mesh: &Mesh, sharp: &[[u32; 2]], levels: u32, max_memory: u64) -> CliResult<Mesh> {
    check_bend_memory(mesh.triangles.len(), levels, max_memory)?;
    bend(mesh, sharp, levels)
}

pub fn run_bend_cmd(args: &BendArgs) -> CliResult {
    let mesh = read_mesh(&args.input, None)?;
    if args.levels > 8 {
        return Err(Failure::input(anyhow::anyhow!(
            "--levels {} would multiply the triangles by 4^{}; at most 8",
            args.levels,
            args.levels
        )));
    }
    // Before the repair and the tagging pass: a refusal should cost nothing.
    check_bend_memory(mesh.triangles.len(), args.levels, args.max_memory)?;
    let mesh = super::manifold(mesh);
    let sharp = match &args.tags {
        Some(t) => tag_edges(&SharpTags::read_path(t, &mesh).map_err(Failure::input)?),
        None => {
            eprintln!("whet bend: no --tags given; tagging sharp edges with EdgeSharpener's filter 3bis rule");
            fallback_tags(&mesh)?
        }
    };
    // Checked above, before the repair and the tagging pass.
    let out = bend(&mesh, &sharp, args.levels)?;
    write_mesh(&args.output, &out, None, &whet::io::WriteOptions::DEFAULT)?;
    eprintln!(
        "{} -> {}: {} levels, {} sharp edges, {} triangles",
        args.input.display(),
        args.output.display(),
        args.levels,
        sharp.len(),
        out.triangles.len()
    );
    Ok(())
}
