//! A tiny sweep through the real exact codec: schema of every output, failure reporting.
#![allow(clippy::unwrap_used)] // a panic is a test failure

use whet_mesh::Mesh;
use whet_rd::*;

struct Exact;
impl Codec for Exact {
    fn name(&self) -> String {
        "exact".into()
    }
    fn encode(&self, m: &Mesh, rate: f64) -> Result<Vec<u8>, String> {
        let opts = whet_codec::EncodeOptions::DEFAULT.with_quant_bits(rate as u32);
        whet_codec::encode(m, &opts)
            .map(|e| e.bytes)
            .map_err(|e| e.to_string())
    }
    fn decode(&self, b: &[u8]) -> Result<Mesh, String> {
        whet_codec::decode(b, &whet_codec::DecodeOptions::DEFAULT).map_err(|e| e.to_string())
    }
}

fn tiny_sweep() -> Vec<Point> {
    let mesh = whet_testkit::meshes::icosphere(2);
    let meshes = vec![("ico".to_string(), mesh)];
    let codecs = [CodecSweep::new(&Exact, vec![6.0, 10.0, 40.0])];
    let stages = [
        Stage::decoded(),
        Stage::new("failing", |_| Err("always fails".into())),
    ];
    let done = std::sync::atomic::AtomicUsize::new(0);
    let pts = sweep(
        &meshes,
        &codecs,
        &stages,
        &SweepOptions::DEFAULT.with_metro_samples(20_000),
        &|| {
            done.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        },
    );
    assert_eq!(done.into_inner(), job_count(1, &codecs));
    pts
}

#[test]
fn tiny_sweep_schema() {
    let pts = tiny_sweep();
    // 3 rates x 2 stages, in the given order.
    assert_eq!(pts.len(), 6);
    assert_eq!(pts[0].stage, "decoded");
    assert_eq!(pts[1].stage, "failing");
    // Rate 40 is refused by the codec: reported, not fatal.
    assert!(pts[4].error.as_deref().unwrap().starts_with("encode"));
    // More bits, less error.
    assert!(pts[0].rms > pts[2].rms && pts[2].rms > 0.0);
    assert!(pts[0].bits_per_original_vertex() < pts[2].bits_per_original_vertex());
    assert!(pts[1].error.as_deref().unwrap().contains("always fails"));

    let csv = to_csv(&pts);
    let mut lines = csv.lines();
    assert_eq!(lines.next().unwrap(), COLUMNS.join(","));
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 6);
    for r in &rows {
        assert_eq!(split_csv(r).len(), COLUMNS.len(), "{r}");
    }
    assert_eq!(
        split_csv(rows[4]).last().unwrap(),
        "encode: quantization bits must be 1..=30, got 40"
    );

    let json: serde_json::Value = serde_json::from_str(&to_json(&pts)).unwrap();
    assert_eq!(json["format"], "whet-rd");
    assert_eq!(json["version"], 1);
    let p0 = &json["points"][0];
    for c in COLUMNS {
        assert!(p0.get(c).is_some(), "missing {c}");
    }
    assert!(p0["rms_e4"].as_f64().unwrap() > 0.0);
    assert!(json["points"][1]["rms"].is_null());

    let md = to_markdown(&pts);
    assert!(md.contains("### ico") && md.contains("always fails"));
    let svg = svg_plot("ico", &pts, None).unwrap();
    assert!(svg.starts_with("<svg") && svg.contains("bits per original vertex"));
}

/// Splits one CSV line (RFC 4180 quoting).
fn split_csv(line: &str) -> Vec<String> {
    let mut out = vec![String::new()];
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(c) = chars.next() {
        match (c, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                chars.next();
                out.last_mut().unwrap().push('"');
            }
            ('"', _) => quoted = !quoted,
            (',', false) => out.push(String::new()),
            (c, _) => out.last_mut().unwrap().push(c),
        }
    }
    out
}
