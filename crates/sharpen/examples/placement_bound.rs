//! How far vertex placement alone could take `whet decode --sharpen` on the swing-decoded
//! CAD fixtures of `sharpen_figures`: for each stream that names a sharpening, its output
//! as the decoder writes it (every projection the stream states), then the same triangles
//! with vertices moved onto their closest point of the original (an oracle no decoder has):
//! every vertex, only the vertices on no crease edge ("faces"), only those on one or more
//! ("creases"; an edge is a crease where its triangles' normals differ by more than 30
//! degrees). Symmetric Metro against the original, 300 000 samples a direction, RMS gains
//! over the decoded input as the sharpening tables print them. The "every vertex" column
//! bounds what any post-processing that keeps the output's triangles can reach.
//!
//! ```text
//! cargo run --release -p whet-sharpen --example placement_bound -- [fixture name ...]
//! ```
#![allow(clippy::unwrap_used)] // a measurement tool

mod support;
mod swing_inputs;

use whet_mesh::{CornerId, CornerTable, Mesh};
use whet_metro::Bvh;

/// Normals further apart than this make an edge a crease (the crease projection's angle).
const CREASE_DEGREES: f64 = 30.0;

fn main() {
    let only: Vec<String> = std::env::args().skip(1).collect();
    println!("| stream | input RMS % | decode --sharpen | every vertex on the original | faces only | creases only |");
    println!("|---|---|---|---|---|---|");
    for (name, bpv, angles, s) in swing_inputs::every_swing_input() {
        if s.sharpen_hint == Some(whet_codec::SharpenHint::Unsharpened)
            || !(only.is_empty() || only.iter().any(|o| name.starts_with(o.as_str())))
        {
            continue;
        }
        let out = s.decode_sharpen();
        let on_crease = crease_vertices(&out);
        let bvh = Bvh::new(&s.original);
        let moved = |pick: &dyn Fn(usize) -> bool| {
            let mut m = out.clone();
            for (v, p) in m.positions.iter_mut().enumerate() {
                if pick(v) {
                    *p = bvh.closest_point(*p).point;
                }
            }
            m
        };
        let e = |m: &Mesh| support::error(&s.original, m, Some(300_000));
        let input = e(&s.decoded).rms_pct;
        let cell = |m: &Mesh| {
            let r = e(m);
            format!(
                "{:.4}, {:.3} ({:.2}x)",
                r.rms_pct,
                r.max_pct,
                input / r.rms_pct
            )
        };
        println!(
            "| {name} {bpv} {} | {input:.4} | {} | {} | {} | {} |",
            angles.tag(),
            cell(&out),
            cell(&moved(&|_| true)),
            cell(&moved(&|v| !on_crease[v])),
            cell(&moved(&|v| on_crease[v])),
        );
    }
}

/// Whether each vertex of `mesh` is on a crease edge.
fn crease_vertices(mesh: &Mesh) -> Vec<bool> {
    let table = CornerTable::new(mesh).unwrap();
    let cos = CREASE_DEGREES.to_radians().cos();
    let normal = |t: usize| mesh.face_cross(t).normalize_or_zero();
    let mut on = vec![false; mesh.positions.len()];
    for c in 0..3 * mesh.triangles.len() {
        let c = CornerId(c as u32);
        let Some(o) = table.opposite(c) else {
            continue;
        };
        if normal(c.index() / 3).dot(normal(o.index() / 3)) < cos {
            on[table.vertex(table.next(c)).index()] = true;
            on[table.vertex(table.prev(c)).index()] = true;
        }
    }
    on
}
