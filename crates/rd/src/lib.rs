//! whet-rd owns whet's rate-distortion measurements: a sweep over meshes, codecs (anything
//! implementing [`Codec`]: whet's exact and swing modes, or a baseline) and rates, where
//! every decoded mesh also goes through the post-processing [`Stage`]s (decoded, sharpened,
//! bent), each result measured with whet-metro against the original; the results as
//! `rd.csv`, `rd.json` and markdown ([`to_csv`], [`to_json`], [`to_markdown`], one schema),
//! SVG curves in the papers' units ([`svg_plot`]), and Draco's published anchors for the
//! baseline ([`parse_draco_anchors`]) with the bytes each curve needs to reach Draco's error
//! ([`compare_with_draco`]). Codecs and stages are plugged in by the caller, so
//! this crate depends on none of them.
//!
//! ```
//! use whet_mesh::{DVec3, Mesh};
//! use whet_rd::{run_point, Codec, Stage, SweepOptions};
//!
//! /// A "codec" that rounds coordinates to 1/rate and stores nothing useful.
//! struct Rounding;
//! impl Codec for Rounding {
//!     fn name(&self) -> String { "rounding".into() }
//!     fn encode(&self, m: &Mesh, rate: f64) -> Result<Vec<u8>, String> {
//!         Ok(vec![0; (m.positions.len() as f64 * rate) as usize])
//!     }
//!     fn decode(&self, _: &[u8]) -> Result<Mesh, String> { Err("not a real codec".into()) }
//! }
//! let tet = Mesh::new(
//!     vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
//!     vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
//! );
//! let points = run_point("tet", &tet, &Rounding, 2.0, &[&Stage::decoded()], &SweepOptions::DEFAULT);
//! // A failed point is reported, not fatal.
//! assert_eq!(points.len(), 1);
//! assert!(points[0].error.as_deref().unwrap().starts_with("decode"));
//! ```
#![forbid(unsafe_code)]

mod compare;
mod draco;
mod output;
mod plot;
mod sweep;

pub use compare::{bytes_at_rms, compare_with_draco, draco_markdown, CurveReach, DracoMatch};
pub use draco::{parse_draco_anchors, DracoPoint};
pub use output::{point_json, to_csv, to_json, to_markdown, COLUMNS};
pub use plot::svg_plot;
pub use sweep::{job_count, run_point, sweep, Codec, CodecSweep, Point, Stage, SweepOptions};
