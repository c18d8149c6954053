//! Reading a sweep against Draco: how many bytes each whet curve needs to reach the RMS error
//! Draco reaches at one quantization, by log-log interpolation between measured points (the
//! curves are straight lines in log-log space to a good approximation, which is why the papers
//! plot them so).

use crate::draco::DracoPoint;
use crate::sweep::Point;
use std::collections::BTreeMap;

/// The bytes one whet curve needs to reach Draco's RMS error at one quantization.
#[derive(Clone, Debug, PartialEq)]
pub struct DracoMatch {
    /// Mesh name.
    pub mesh: String,
    /// Codec name of the whet curve.
    pub mode: String,
    /// Stage name of the whet curve.
    pub stage: String,
    /// Draco's quantization bits.
    pub draco_quant_bits: u32,
    /// Draco's stream size there.
    pub draco_bytes: usize,
    /// Draco's RMS error there, % of the diagonal.
    pub draco_rms_pct: f64,
    /// What the whet curve needs.
    pub whet: CurveReach,
}

/// Where a curve stands against an error target.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum CurveReach {
    /// Interpolated between two measured points that bracket the target.
    Interpolated {
        /// Bytes at the target error.
        bytes: f64,
    },
    /// The cheapest measured point already meets the target: at most these bytes.
    AtMost {
        /// Bytes of the cheapest measured point.
        bytes: f64,
    },
    /// No measured point meets the target.
    NotReached {
        /// The smallest RMS the curve measured, % of the diagonal.
        best_rms_pct: f64,
        /// Bytes of that point.
        bytes: f64,
    },
}

impl DracoMatch {
    /// whet bytes over Draco bytes, when the curve reaches the target.
    pub fn ratio(&self) -> Option<f64> {
        match self.whet {
            CurveReach::Interpolated { bytes } | CurveReach::AtMost { bytes } => {
                Some(bytes / self.draco_bytes as f64)
            }
            CurveReach::NotReached { .. } => None,
        }
    }
}

/// Where the curve `(bytes, rms)` (any order, positive figures) first reaches `target`.
pub fn bytes_at_rms(curve: &[(f64, f64)], target: f64) -> Option<CurveReach> {
    let mut c: Vec<(f64, f64)> = curve
        .iter()
        .copied()
        .filter(|&(b, e)| b > 0.0 && e > 0.0 && b.is_finite() && e.is_finite())
        .collect();
    if c.is_empty() {
        return None;
    }
    c.sort_by(|a, b| a.0.total_cmp(&b.0));
    if c[0].1 <= target {
        return Some(CurveReach::AtMost { bytes: c[0].0 });
    }
    for w in c.windows(2) {
        let ((b0, e0), (b1, e1)) = (w[0], w[1]);
        if e1 <= target && e0 > target {
            // Straight line in log-log space.
            let t = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
            let bytes = (b0.ln() + t * (b1.ln() - b0.ln())).exp();
            return Some(CurveReach::Interpolated { bytes });
        }
    }
    let best = c.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1))?;
    Some(CurveReach::NotReached {
        best_rms_pct: best.1,
        bytes: best.0,
    })
}

/// For every mesh of the sweep that has a Draco point at `quant_bits`, and every whet curve
/// (mode, stage) of that mesh, the bytes needed to reach Draco's RMS error there.
pub fn compare_with_draco(
    points: &[Point],
    draco: &BTreeMap<String, Vec<DracoPoint>>,
    quant_bits: u32,
) -> Vec<DracoMatch> {
    let mut out = Vec::new();
    let mut curves: Vec<(&str, &str, &str)> = Vec::new();
    for p in points {
        let key = (p.mesh.as_str(), p.mode.as_str(), p.stage.as_str());
        if !curves.contains(&key) {
            curves.push(key);
        }
    }
    for (mesh, mode, stage) in curves {
        let Some(d) = draco
            .get(mesh)
            .and_then(|v| v.iter().find(|d| d.quant_bits == quant_bits))
        else {
            continue;
        };
        let curve: Vec<(f64, f64)> = points
            .iter()
            .filter(|p| p.mesh == mesh && p.mode == mode && p.stage == stage && p.error.is_none())
            .map(|p| (p.bytes as f64, p.pct(p.rms)))
            .collect();
        let Some(whet) = bytes_at_rms(&curve, d.rms_pct) else {
            continue;
        };
        out.push(DracoMatch {
            mesh: mesh.to_string(),
            mode: mode.to_string(),
            stage: stage.to_string(),
            draco_quant_bits: quant_bits,
            draco_bytes: d.bytes,
            draco_rms_pct: d.rms_pct,
            whet,
        });
    }
    out
}

/// The comparison as a markdown table; `bar` is the byte ratio the project aims at (e.g. 0.25).
pub fn draco_markdown(matches: &[DracoMatch], bar: f64) -> String {
    let mut out = String::new();
    if let Some(first) = matches.first() {
        out.push_str(&format!(
            "Bytes each whet curve needs to reach Draco's RMS error at quantization {} (log-log \
             interpolation between measured points; bar: at most {:.0} % of Draco's bytes).\n\n",
            first.draco_quant_bits,
            bar * 100.0
        ));
    }
    out.push_str("| mesh | curve | Draco bytes | Draco RMS % | whet bytes | ratio | bar |\n");
    out.push_str("|---|---|---|---|---|---|---|\n");
    for m in matches {
        let (bytes, ratio, verdict) = match m.whet {
            CurveReach::Interpolated { bytes } => {
                let r = bytes / m.draco_bytes as f64;
                (
                    format!("{bytes:.0}"),
                    format!("{r:.3}"),
                    if r <= bar { "met" } else { "not met" }.to_string(),
                )
            }
            CurveReach::AtMost { bytes } => {
                let r = bytes / m.draco_bytes as f64;
                (
                    format!("<= {bytes:.0}"),
                    format!("<= {r:.3}"),
                    if r <= bar {
                        "met".to_string()
                    } else {
                        "cheapest point already below; sweep lower rates".to_string()
                    },
                )
            }
            CurveReach::NotReached {
                best_rms_pct,
                bytes,
            } => (
                "-".into(),
                "-".into(),
                format!("not reached (best RMS {best_rms_pct:.4} % at {bytes:.0} bytes)"),
            ),
        };
        out.push_str(&format!(
            "| {} | {} {} | {} | {:.4} | {} | {} | {} |\n",
            m.mesh, m.mode, m.stage, m.draco_bytes, m.draco_rms_pct, bytes, ratio, verdict
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interpolates_in_log_log_space() {
        // error = 1 / bytes: a straight line of slope -1 in log-log space.
        let curve = [(100.0, 0.01), (10.0, 0.1), (1000.0, 0.001)];
        match bytes_at_rms(&curve, 0.02) {
            Some(CurveReach::Interpolated { bytes }) => assert!((bytes - 50.0).abs() < 1e-9),
            other => panic!("{other:?}"),
        }
        assert_eq!(
            bytes_at_rms(&curve, 0.5),
            Some(CurveReach::AtMost { bytes: 10.0 })
        );
        assert_eq!(
            bytes_at_rms(&curve, 1e-4),
            Some(CurveReach::NotReached {
                best_rms_pct: 0.001,
                bytes: 1000.0
            })
        );
        assert_eq!(bytes_at_rms(&[], 1.0), None);
    }

    #[test]
    fn non_monotone_curves_take_the_first_crossing() {
        // A bump: 20 bytes is worse than 10; the first crossing of 0.05 lies between 20 and 40.
        let curve = [(10.0, 0.08), (20.0, 0.09), (40.0, 0.03)];
        let Some(CurveReach::Interpolated { bytes }) = bytes_at_rms(&curve, 0.05) else {
            panic!("expected an interpolated figure");
        };
        assert!(bytes > 20.0 && bytes < 40.0, "{bytes}");
    }
}
