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

/// Asserts that `out`, the sharpened union of `first` and a second part shifted 100 along x
/// (`whet_testkit::meshes::union`, `union_vertices` vertices in all), holds `first`'s vertices
/// and triangles as they were, and that every new vertex is the second part's.
pub fn assert_first_part_unchanged(
    out: &whet_mesh::Mesh,
    first: &whet_mesh::Mesh,
    union_vertices: usize,
) {
    let nv = first.positions.len();
    let new = &out.positions[union_vertices..];
    assert!(
        new.iter().all(|p| p.x > 50.0),
        "a new vertex off the second part"
    );
    assert_eq!(out.positions[..nv], first.positions[..]);
    let kept: Vec<[u32; 3]> = out
        .triangles
        .iter()
        .filter(|t| t.iter().all(|&v| (v as usize) < nv))
        .copied()
        .collect();
    assert_eq!(kept, first.triangles);
}

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
