//! Debugging aid: how the error of a retiling is distributed (original vertices to M').
#![allow(clippy::unwrap_used)]
use whet_swing::{encode, Rate, SwingOptions};
fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let mesh = whet_io::read_path(&whet_testkit::shared_fixture(&a[0]), None).unwrap();
    // `0.01` is L as a fraction of the diagonal, `bpv:1.5` a rate in bits per original vertex.
    let rate = match a[1].strip_prefix("bpv:") {
        Some(r) => Rate::BitsPerVertex(r.parse().unwrap()),
        None => Rate::EdgeLength(a[1].parse().unwrap()),
    };
    let bits: u32 = a.get(2).map_or(8, |x| x.parse().unwrap());
    let out = encode(
        &mesh,
        &SwingOptions::DEFAULT.with_rate(rate).with_angle_bits(bits),
    )
    .unwrap();
    println!(
        "L {} of the diagonal, {} bytes, T' {}, {:?}",
        out.edge_length_fraction,
        out.bytes.len(),
        out.retiled.triangles.len(),
        out.stats
    );
    let diag = mesh.diagonal();
    let bvh = whet_metro::Bvh::new(&out.retiled);
    let mut d = whet_metro::vertex_distances(&mesh, &bvh);
    // Backward direction per original vertex (not area-weighted, a rough view).
    d.sort_by(|x, y| y.total_cmp(x));
    let total: f64 = d.iter().map(|x| x * x).sum();
    let n = d.len();
    for frac in [0.001, 0.01, 0.05, 0.2] {
        let k = ((n as f64) * frac) as usize;
        let part: f64 = d[..k].iter().map(|x| x * x).sum();
        println!(
            "top {:.1}% of vertices: {:.1}% of squared error",
            frac * 100.0,
            100.0 * part / total
        );
    }
    println!(
        "rms {:.4}% (vertex-based), max {:.3}%",
        100.0 * (total / n as f64).sqrt() / diag,
        100.0 * d[0] / diag
    );
    // Signed: is M' inside or outside?
    let bvh_m = whet_metro::Bvh::new(&mesh);
    let normals = mesh.face_normals();
    let mut s_in = 0.0;
    let mut s_out = 0.0;
    for p in &out.retiled.positions {
        let c = bvh_m.closest_point(*p);
        let s = (*p - c.point).dot(normals[c.triangle as usize]);
        if s > 0.0 {
            s_out += s * s
        } else {
            s_in += s * s
        }
    }
    let nv = out.retiled.positions.len() as f64;
    println!(
        "M' vertices off M: rms out {:.5}% in {:.5}%",
        100.0 * (s_out / nv).sqrt() / diag,
        100.0 * (s_in / nv).sqrt() / diag
    );
    whet_io::write_path(
        std::path::Path::new("/tmp/errdist.off"),
        &out.retiled,
        None,
        &whet_io::WriteOptions::DEFAULT,
    )
    .unwrap();
    // Worst original vertices
    let mut idx: Vec<usize> = (0..mesh.positions.len()).collect();
    let dd = whet_metro::vertex_distances(&mesh, &bvh);
    idx.sort_by(|&x, &y| dd[y].total_cmp(&dd[x]));
    for &i in idx.iter().take(5) {
        println!(
            "worst at {:?} {:.3}%",
            mesh.positions[i].to_array(),
            100.0 * dd[i] / diag
        );
    }
}
