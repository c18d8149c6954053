//! End-to-end tests of the `whet` binary and the facade: one integration binary, one module
//! per command.
#![allow(clippy::unwrap_used)] // a panic is a test failure

mod cli_codec;
mod cli_convert;
mod cli_info;
mod cli_metro;
mod cli_rd;
mod cli_sharpen;
mod cli_skipped;
mod fixtures;
mod fuzz_replay;

use std::path::Path;
use std::process::{Command, Output};

/// Runs the `whet` binary with `args`.
pub fn whet(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_whet"))
        .args(args)
        .output()
        .expect("the whet binary runs")
}

/// Runs `whet` and parses its stdout as one JSON object; panics with stderr on failure.
pub fn whet_json(args: &[&str]) -> serde_json::Value {
    let out = whet(args);
    assert!(
        out.status.success(),
        "whet {args:?} failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap_or_else(|e| {
        panic!(
            "whet {args:?} printed no JSON ({e}): {}",
            String::from_utf8_lossy(&out.stdout)
        )
    })
}

/// A fin: three triangles on the edge (0, 1), the smallest non-manifold mesh.
pub const FIN_OFF: &str =
    "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n";

/// Path as &str (test paths are UTF-8).
pub fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}
