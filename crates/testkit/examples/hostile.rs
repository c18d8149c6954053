//! Writes the hostile inputs of docs/results.md, "Hostile inputs", as OFF files:
//!
//! ```text
//! cargo run --release -p whet-testkit --example hostile -- hub <spokes> <out.off>
//! cargo run --release -p whet-testkit --example hostile -- soup <triangles> <out.off>
//! ```
//!
//! `hub`: [`whet_testkit::meshes::hub_disk`] with three rings, one vertex of valence
//! `spokes` among `5 spokes` triangles. `soup`: separate small triangles scattered over a
//! 100-unit cube (deterministic), every one its own component with three boundary edges.
#![allow(clippy::unwrap_used)] // a command-line tool: a bad argument ends it

use std::io::Write;
use whet_mesh::{DVec3, Mesh};

fn soup(n: u32) -> Mesh {
    let mut state = 0x2545_f491_4f6c_dd1du64;
    let mut rand = || {
        state ^= state << 13;
        state ^= state >> 7;
        state ^= state << 17;
        (state >> 11) as f64 / (1u64 << 53) as f64 * 100.0
    };
    let mut m = Mesh::default();
    for i in 0..n {
        let o = DVec3::new(rand(), rand(), rand());
        m.positions
            .extend([o, o + DVec3::X * 0.3, o + DVec3::new(0.0, 0.3, 0.1)]);
        m.triangles.push([3 * i, 3 * i + 1, 3 * i + 2]);
    }
    m
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let usage = "usage: hostile (hub <spokes> | soup <triangles>) <out.off>";
    assert!(args.len() == 3, "{usage}");
    let n: u32 = args[1].parse().expect(usage);
    let mesh = match args[0].as_str() {
        "hub" => whet_testkit::meshes::hub_disk(n, 3),
        "soup" => soup(n),
        _ => panic!("{usage}"),
    };
    let mut out = std::io::BufWriter::new(std::fs::File::create(&args[2]).unwrap());
    writeln!(
        out,
        "OFF\n{} {} 0",
        mesh.positions.len(),
        mesh.triangles.len()
    )
    .unwrap();
    for p in &mesh.positions {
        writeln!(out, "{} {} {}", p.x, p.y, p.z).unwrap();
    }
    for t in &mesh.triangles {
        writeln!(out, "3 {} {} {}", t[0], t[1], t[2]).unwrap();
    }
}
