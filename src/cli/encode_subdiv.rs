//! `whet encode --mode subdiv`: fit a control mesh with continuous edge sharpness and write
//! the subdiv stream.

use super::{print_json, skipped_json, CliResult, Failure};
use serde_json::json;
use std::path::Path;

/// Encodes `mesh` in the subdiv mode and writes `output`; `skipped` is what reading `input`
/// left out, for the JSON output.
#[allow(clippy::too_many_arguments)]
pub fn run_subdiv(
    input: &Path,
    output: &Path,
    mesh: &whet::Mesh,
    skipped: &whet::io::ReadReport,
    control_vertices: usize,
    levels: Option<u32>,
    quant_bits: Option<u32>,
    json_out: bool,
) -> CliResult {
    let mut opts =
        whet_subdiv::SubdivEncodeOptions::DEFAULT.with_control_vertices(control_vertices);
    if let Some(q) = quant_bits {
        opts = opts.with_quant_bits(q);
    }
    if let Some(l) = levels {
        opts = opts.with_levels(l);
    }
    let (bytes, r) = whet::encode_subdiv(mesh, &opts).map_err(|e| {
        let input_fault = e.is_input_error();
        let err = anyhow::Error::new(e).context(format!("cannot encode {}", input.display()));
        if input_fault {
            Failure::input(err)
        } else {
            Failure::other(err)
        }
    })?;
    std::fs::write(output, &bytes).map_err(|e| {
        Failure::other(anyhow::Error::new(e).context(format!("cannot write {}", output.display())))
    })?;
    let bpov = bytes.len() as f64 * 8.0 / mesh.positions.len().max(1) as f64;
    if json_out {
        print_json(&json!({
            "mode": "subdiv",
            "bytes": bytes.len(),
            "triangles": r.decoded_triangles,
            "vertices": r.decoded_vertices,
            "control_vertices": r.control_vertices,
            "control_triangles": r.control_triangles,
            "control_bytes": r.control_bytes,
            "sharpness_bytes": r.sharpness_bytes,
            "sharp_edges": r.sharp_edges,
            "connectivity_bits": r.control_bytes as u64 * 8,
            "geometry_bits": r.sharpness_bytes as u64 * 8,
            "bits_per_original_vertex": bpov,
            "bits_per_vertex": bytes.len() as f64 * 8.0 / (r.decoded_vertices.max(1) as f64),
            "bits_per_triangle": bytes.len() as f64 * 8.0 / (r.decoded_triangles.max(1) as f64),
            "skipped_attributes": skipped_json(skipped),
        }));
    } else {
        outln!(
            "{} -> {}: {} bytes ({:.3} bits per original vertex), {} control vertices, decodes to {} triangles",
            input.display(),
            output.display(),
            bytes.len(),
            bpov,
            r.control_vertices,
            r.decoded_triangles
        );
    }
    Ok(())
}
