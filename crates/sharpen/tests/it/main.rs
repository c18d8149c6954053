//! Integration tests of whet-sharpen: one binary, one module per topic.
//!
//! - `ridge`: a hand-built chamfered ridge with exact expectations;
//! - `outputs`: the issue's output guarantees on marching-cubes samplings of the synth shapes;
//! - `inputs`: refused input, boundaries, components, already-sharp meshes, tags, options;
//! - `issue6`: the figures of issue 6 at test-suite scale (regression bounds) and noise;
//! - `normal_filter`: the normal filter of issue 10 (figures as regression bounds, guarantees,
//!   selection, random damage);
//! - `robustness`: random noise, holes and options never break the output's guarantees.
//! - `swing`: swing-decoded fixtures (whet-swing, whet-codec as dev-dependencies).
//! - `judge`: snap vetoes (`SnapJudge`, `VetoReplay`).
#![allow(clippy::unwrap_used)] // a panic is a test failure

#[path = "../../examples/support/mod.rs"]
mod support;

/// The EdgeSharpener methods (the normal filter has its own guarantees: `normal_filter`).
pub const EDGE_SHARPENER: [whet_sharpen::Method; 2] =
    [whet_sharpen::Method::Papers, whet_sharpen::Method::Extended];

mod inputs;
mod issue6;
mod judge;
mod normal_filter;
mod outputs;
mod ridge;
mod robustness;
mod rotations;
mod swing;
mod walls;
