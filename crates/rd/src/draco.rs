//! Reading Draco's published rate-distortion anchors (`../shared/anchors/draco.md`) so the
//! baseline can be drawn on the same plots.

use std::collections::BTreeMap;

/// One Draco measurement.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DracoPoint {
    /// Quantization bits.
    pub quant_bits: u32,
    /// Stream size.
    pub bytes: usize,
    /// Bits per original vertex.
    pub bpv: f64,
    /// Symmetric max error, % of the diagonal.
    pub max_pct: f64,
    /// Mean error, % of the diagonal.
    pub mean_pct: f64,
    /// RMS error, % of the diagonal.
    pub rms_pct: f64,
}

/// Parses the markdown rate-distortion table (`| mesh | V | T | q bits | bytes | bpv | bpt |
/// max % | mean % | RMS % | ...`) into points per mesh; other tables and lines are ignored.
pub fn parse_draco_anchors(text: &str) -> BTreeMap<String, Vec<DracoPoint>> {
    let mut out: BTreeMap<String, Vec<DracoPoint>> = BTreeMap::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        // Leading and trailing empty cells around 12 columns.
        if cells.len() < 12 {
            continue;
        }
        let c = &cells[1..cells.len() - 1];
        if c.len() < 10 {
            continue;
        }
        let parse = |s: &str| s.parse::<f64>().ok();
        let (Some(q), Some(bytes), Some(bpv), Some(max), Some(mean), Some(rms)) = (
            parse(c[3]),
            parse(c[4]),
            parse(c[5]),
            parse(c[7]),
            parse(c[8]),
            parse(c[9]),
        ) else {
            continue;
        };
        if c[1].parse::<u64>().is_err() || q.fract() != 0.0 {
            continue;
        }
        out.entry(c[0].to_string()).or_default().push(DracoPoint {
            quant_bits: q as u32,
            bytes: bytes as usize,
            bpv,
            max_pct: max,
            mean_pct: mean,
            rms_pct: rms,
        });
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_the_rd_table_only() {
        let text = "| mesh | V | T | q bits | bytes | bpv | bpt | max % | mean % | RMS % | enc ms | dec ms |\n\
                    |---|---|---|---|---|---|---|---|---|---|---|---|\n\
                    | fandisk | 6475 | 12946 | 10 | 7000 | 8.65 | 4.3 | 0.0500 | 0.0100 | 0.0150 | 6.1 | 1.2 |\n\
                    | fandisk | 6475 | 12946 | 1485 | 1.83 | 0.92 |\n";
        let m = parse_draco_anchors(text);
        assert_eq!(m["fandisk"].len(), 1);
        assert_eq!(m["fandisk"][0].quant_bits, 10);
        assert!((m["fandisk"][0].rms_pct - 0.015).abs() < 1e-12);
    }
}
