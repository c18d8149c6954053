//! `whet info`: counts, topology and problems of a mesh.

use super::{print_json, read_mesh, CliResult};
use clap::Args;
use serde_json::json;
use std::path::PathBuf;

#[derive(Args, Debug)]
pub struct InfoArgs {
    /// Mesh file (.off, .obj, .ply, .stl).
    mesh: PathBuf,
    /// Input format, overriding the extension.
    #[arg(long)]
    format: Option<whet::io::Format>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

pub fn run(args: &InfoArgs) -> CliResult {
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
