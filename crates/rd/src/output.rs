//! The sweep's files: `rd.csv`, `rd.json` and a markdown table, all with the same columns.

use crate::sweep::Point;
use serde_json::{json, Value};

/// Column names of `rd.csv` and keys of each point in `rd.json`, in order.
pub const COLUMNS: [&str; 25] = [
    "mesh",
    "mode",
    "rate",
    "stage",
    "bytes",
    "original_vertices",
    "original_triangles",
    "vertices",
    "triangles",
    "bits_per_original_vertex",
    "bits_per_original_triangle",
    "max",
    "mean",
    "rms",
    "max_pct",
    "mean_pct",
    "rms_pct",
    "max_e4",
    "mean_e4",
    "rms_e4",
    "encode_ms",
    "decode_ms",
    "stage_ms",
    "metro_ms",
    "error",
];

fn num(x: f64) -> Value {
    if x.is_finite() {
        json!(x)
    } else {
        Value::Null
    }
}

/// One point as a JSON object with the keys of [`COLUMNS`] (non-finite figures of a failed
/// point are `null`).
pub fn point_json(p: &Point) -> Value {
    json!({
        "mesh": p.mesh,
        "mode": p.mode,
        "rate": num(p.rate),
        "stage": p.stage,
        "bytes": p.bytes,
        "original_vertices": p.original_vertices,
        "original_triangles": p.original_triangles,
        "vertices": p.vertices,
        "triangles": p.triangles,
        "bits_per_original_vertex": num(p.bits_per_original_vertex()),
        "bits_per_original_triangle": num(p.bits_per_original_triangle()),
        "max": num(p.max),
        "mean": num(p.mean),
        "rms": num(p.rms),
        "max_pct": num(p.pct(p.max)),
        "mean_pct": num(p.pct(p.mean)),
        "rms_pct": num(p.pct(p.rms)),
        "max_e4": num(p.e4(p.max)),
        "mean_e4": num(p.e4(p.mean)),
        "rms_e4": num(p.e4(p.rms)),
        "encode_ms": num(p.encode_ms),
        "decode_ms": num(p.decode_ms),
        "stage_ms": num(p.stage_ms),
        "metro_ms": num(p.metro_ms),
        "error": p.error,
    })
}

/// `rd.json`: `{"format": "whet-rd", "version": 1, "points": [...]}`.
pub fn to_json(points: &[Point]) -> String {
    let v = json!({
        "format": "whet-rd",
        "version": 1,
        "columns": COLUMNS,
        "points": points.iter().map(point_json).collect::<Vec<_>>(),
    });
    // A Value always serialises.
    serde_json::to_string_pretty(&v).unwrap_or_default()
}

fn csv_field(v: &Value) -> String {
    match v {
        Value::Null => String::new(),
        Value::String(s) => {
            if s.contains([',', '"', '\n']) {
                format!("\"{}\"", s.replace('"', "\"\""))
            } else {
                s.clone()
            }
        }
        other => other.to_string(),
    }
}

/// `rd.csv`: a header line of [`COLUMNS`], one line per point (empty fields for missing
/// figures).
pub fn to_csv(points: &[Point]) -> String {
    let mut out = COLUMNS.join(",");
    out.push('\n');
    for p in points {
        let j = point_json(p);
        let row: Vec<String> = COLUMNS.iter().map(|c| csv_field(&j[*c])).collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

fn fmt(x: f64, digits: usize) -> String {
    if x.is_finite() {
        format!("{x:.digits$}")
    } else {
        "-".into()
    }
}

/// A markdown table per mesh: mode, rate, stage, bytes, bits per original vertex, errors in %
/// of the diagonal and 1e-4 units, times; a failed point shows its error.
pub fn to_markdown(points: &[Point]) -> String {
    let mut out = String::new();
    let mut meshes: Vec<&str> = Vec::new();
    for p in points {
        if !meshes.contains(&p.mesh.as_str()) {
            meshes.push(&p.mesh);
        }
    }
    for mesh in meshes {
        out.push_str(&format!("### {mesh}\n\n"));
        out.push_str("| mode | rate | stage | bytes | bpv | max % | mean % | RMS % | RMS (1e-4 diag) | enc ms | dec ms | stage ms | note |\n");
        out.push_str("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
        for p in points.iter().filter(|p| p.mesh == mesh) {
            out.push_str(&format!(
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |\n",
                p.mode,
                p.rate,
                p.stage,
                p.bytes,
                fmt(p.bits_per_original_vertex(), 3),
                fmt(p.pct(p.max), 4),
                fmt(p.pct(p.mean), 4),
                fmt(p.pct(p.rms), 4),
                fmt(p.e4(p.rms), 2),
                fmt(p.encode_ms, 1),
                fmt(p.decode_ms, 1),
                fmt(p.stage_ms, 1),
                p.error.as_deref().unwrap_or("").replace('|', "/"),
            ));
        }
        out.push('\n');
    }
    out
}
