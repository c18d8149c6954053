//! `whet info`: counts, topology and problems of a mesh.

use super::{print_json, read_mesh, CliResult, Failure};
use anyhow::anyhow;
use clap::Args;
use serde_json::json;
use std::io::Read;
use std::path::{Path, PathBuf};

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Mesh file (.off, .obj, .ply, .stl), or a `.whet` stream (its header and sections,
    /// checked but not decoded).
    mesh: PathBuf,
    /// Input format, overriding the extension.
    #[arg(long)]
    format: Option<whet::io::Format>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// A `.whet` stream: refuse, before reading it, a file larger than this many bytes.
    #[arg(long, value_name = "BYTES", default_value_t = super::DEFAULT_MAX_MEMORY)]
    max_memory: u64,
}

pub fn run(args: &InfoArgs) -> CliResult {
    if args.format.is_none() && is_stream(&args.mesh) {
        return stream_info(args);
    }
    let mesh = read_mesh(&args.mesh, args.format)?;
    let r = mesh.topology_report();
    let diagonal = mesh.diagonal();
    // Mean edge length only over usable triangles' edges: out-of-range indices would panic.
    let mean_edge = if r
        .problems
        .iter()
        .any(|p| matches!(p, whet::MeshError::IndexOutOfRange { .. }))
    {
        f64::NAN
    } else {
        mesh.mean_edge_length()
    };
    if args.json {
        let problems: Vec<serde_json::Value> = r
            .problems
            .iter()
            .map(|p| json!({ "kind": p.kind(), "message": p.to_string() }))
            .collect();
        print_json(&json!({
            "vertices": r.vertices,
            "triangles": r.triangles,
            "edges": r.edges,
            "components": r.components,
            "boundary_loops": r.boundary_loops,
            "boundary_edges": r.boundary_edges,
            "euler_characteristic": r.euler_characteristic,
            "genus": r.genus,
            "manifold": r.manifold,
            "oriented": r.oriented,
            "bbox_diagonal": finite_or_null(diagonal),
            "mean_edge_length": finite_or_null(mean_edge),
            "problems": problems,
            "problem_count": r.problem_count,
        }));
    } else {
        outln!("{}", args.mesh.display());
        outln!("  vertices        {}", r.vertices);
        outln!("  triangles       {}", r.triangles);
        outln!("  edges           {}", r.edges);
        outln!("  components      {}", r.components);
        outln!(
            "  boundary loops  {} ({} edges)",
            r.boundary_loops,
            r.boundary_edges
        );
        match r.genus {
            Some(g) => outln!("  genus           {g}"),
            None => outln!("  genus           undefined (not an oriented manifold)"),
        }
        outln!("  euler char.     {}", r.euler_characteristic);
        outln!(
            "  manifold        {}",
            if r.manifold { "yes" } else { "no" }
        );
        outln!(
            "  oriented        {}",
            if r.oriented { "yes" } else { "no" }
        );
        outln!("  bbox diagonal   {diagonal}");
        outln!("  mean edge       {mean_edge}");
        if r.problem_count == 0 {
            outln!("  problems        none");
        } else {
            outln!("  problems        {}", r.problem_count);
            for p in &r.problems {
                outln!("    - {p}");
            }
            if r.problem_count > r.problems.len() {
                outln!("    ... and {} more", r.problem_count - r.problems.len());
            }
        }
    }
    Ok(())
}

fn finite_or_null(x: f64) -> serde_json::Value {
    if x.is_finite() {
        json!(x)
    } else {
        serde_json::Value::Null
    }
}

/// A `.whet` file: by its extension, or by its magic when the extension names no mesh format.
fn is_stream(path: &Path) -> bool {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("whet") => true,
        Some("off" | "obj" | "ply" | "stl") => false,
        _ => {
            let mut magic = [0u8; 4];
            std::fs::File::open(path)
                .and_then(|mut f| f.read_exact(&mut magic))
                .is_ok_and(|()| magic == whet_format::MAGIC)
        }
    }
}

/// `whet info` of a `.whet` stream: the container is parsed and every checksum checked
/// (whet-format, the default limits), nothing is decoded.
fn stream_info(args: &InfoArgs) -> CliResult {
    let path = &args.mesh;
    let bytes = super::read_stream_file(path, args.max_memory)?;
    let c = whet_format::parse(&bytes, &whet_format::Limits::DEFAULT)
        .map_err(|e| Failure::input(anyhow!("{}: {e}", path.display())))?;
    let h = &c.header;
    let fields: Vec<(String, serde_json::Value)> = h
        .fields()
        .iter()
        .map(|f| {
            let name = whet_format::tag::known(f.tag)
                .map_or_else(|| format!("tag_{}", f.tag), |(n, _)| n.to_string());
            let value = match (&f.value, f.tag) {
                (_, whet_format::tag::BBOX | whet_format::tag::BBOX_F32) => h.bbox().map_or(
                    serde_json::Value::Null,
                    |(min, max)| json!({ "min": min, "max": max }),
                ),
                (whet_format::HeaderValue::U64(v), _) => json!(v),
                (whet_format::HeaderValue::I64(v), _) => json!(v),
                (whet_format::HeaderValue::F64(v), _) => finite_or_null(*v),
                (whet_format::HeaderValue::Bytes(b), whet_format::tag::ENCODER) => {
                    json!(String::from_utf8_lossy(b))
                }
                (whet_format::HeaderValue::Bytes(b), whet_format::tag::SNAP_VETOES) => {
                    // Counts when the field reads (a malformed one: its size and the error).
                    match whet_codec::SnapVetoes::of(h) {
                        Some(Ok(v)) => json!({
                            "bytes": b.len(),
                            "judgements": v.passes().len(),
                            "snaps": v.judged(),
                            "vetoed": v.vetoed(),
                        }),
                        Some(Err(e)) => json!({ "bytes": b.len(), "error": e.to_string() }),
                        None => json!({ "bytes": b.len() }),
                    }
                }
                (whet_format::HeaderValue::Bytes(b), _) => json!({ "bytes": b.len() }),
            };
            (name, value)
        })
        .collect();
    let sections: Vec<serde_json::Value> = c
        .sections
        .iter()
        .map(|s| {
            json!({
                "tag": s.kind.tag(),
                "name": s.kind.name().unwrap_or("unknown"),
                "bytes": s.payload.len(),
            })
        })
        .collect();
    // A swing stream's geometry section starts with its kind (docs/format.md).
    let geometry_kind = (h.mode == whet_format::Mode::Swing)
        .then(|| c.section(whet_format::SectionKind::GEOMETRY))
        .flatten()
        .and_then(|g| g.first().copied());
    if args.json {
        print_json(&json!({
            "stream": true,
            "bytes": bytes.len(),
            "version": h.version.to_string(),
            "mode": h.mode.name(),
            "vertices": h.vertex_count,
            "triangles": h.triangle_count,
            "fields": serde_json::Map::from_iter(fields),
            "sections": sections,
            "geometry_kind": geometry_kind,
        }));
    } else {
        outln!("{}", path.display());
        outln!(
            "  stream          {} bytes, format {}",
            bytes.len(),
            h.version
        );
        outln!("  mode            {}", h.mode.name());
        outln!("  vertices        {}", h.vertex_count);
        outln!("  triangles       {}", h.triangle_count);
        for (name, value) in &fields {
            outln!("  {name:<15} {value}");
        }
        for s in &sections {
            outln!(
                "  section         {} ({} bytes)",
                s["name"].as_str().unwrap_or("?"),
                s["bytes"]
            );
        }
        if let Some(k) = geometry_kind {
            outln!("  geometry kind   {k}");
        }
        outln!("  checksums       ok");
    }
    Ok(())
}
