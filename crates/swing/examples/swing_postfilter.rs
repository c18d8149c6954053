//! Measures the surface filter applied after EdgeSharpener (not shipped; docs/results.md,
//! SwingWrapper "Not reached"): each mesh is encoded at each rate (6 angle bits), decoded
//! without the filter, sharpened, and the stream's filter is then applied to the input
//! vertices whose triangles the sharpener left alone (`RINGS=k` keeps k rings around the
//! sharpened part untouched; default 1). Prints the RMS and max error (% of the diagonal,
//! 300 000 Metro samples) of the unfiltered, filtered, sharpened and sharpened + filtered
//! meshes.
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_postfilter -- <fixture.off> <bpv>...
//! ```
#![allow(clippy::unwrap_used)] // a measurement tool

use whet_codec::{decode, DecodeOptions, FilterFields};
use whet_metro::{metro, MetroOptions};
use whet_swing::{encode, Rate, SwingOptions};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh = whet_io::read_path(&whet_testkit::shared_fixture(&args[0]), None).unwrap();
    let rings: usize = std::env::var("RINGS")
        .ok()
        .map_or(1, |x| x.parse().unwrap());
    for r in &args[1..] {
        let bpv: f64 = r.parse().unwrap();
        let opts = SwingOptions::DEFAULT.with_rate(Rate::BitsPerVertex(bpv));
        let out = encode(&mesh, &opts).unwrap();
        let raw = decode(
            &out.bytes,
            &DecodeOptions::DEFAULT.with_surface_filter(false),
        )
        .unwrap();
        let filtered = decode(&out.bytes, &DecodeOptions::DEFAULT).unwrap();
        let sharp = whet_sharpen::sharpen(&raw, &whet_sharpen::SharpenOptions::DEFAULT)
            .unwrap()
            .mesh;
        // Touched: moved or new vertices, then `rings` rings of triangles around them.
        let n0 = raw.positions.len();
        let mut touched: Vec<bool> = (0..sharp.positions.len())
            .map(|v| v >= n0 || sharp.positions[v] != raw.positions[v])
            .collect();
        for _ in 0..rings {
            let seed = touched.clone();
            for t in &sharp.triangles {
                if t.iter().any(|&v| seed[v as usize]) {
                    for &v in t {
                        touched[v as usize] = true;
                    }
                }
            }
        }
        let fields = FilterFields::new(&raw);
        let (a, b) = out.surface_filter.factors();
        let mut post = sharp.clone();
        for v in (0..n0).filter(|&v| !touched[v]) {
            post.positions[v] += a * fields.normal[v] + b * fields.smoothed[v];
        }
        // Factors fitted on the sharpened mesh itself (the fields masked to the vertices
        // the sharpener left alone).
        let bvh = whet_metro::Bvh::new(&mesh);
        let l = out.edge_length;
        let (mut f0, mut f1) = (
            vec![whet_mesh::DVec3::ZERO; sharp.positions.len()],
            vec![whet_mesh::DVec3::ZERO; sharp.positions.len()],
        );
        for v in (0..n0).filter(|&v| !touched[v]) {
            f0[v] = fields.normal[v];
            f1[v] = fields.smoothed[v];
        }
        let fitted = whet_swing::fit_displacements(&sharp, &f0, &f1, |p| {
            bvh.closest_point_within(p, 2.0 * l).map(|c| c.point)
        });
        let (a2, b2) = fitted.factors();
        let mut post_fit = sharp.clone();
        for v in 0..post_fit.positions.len() {
            post_fit.positions[v] += a2 * f0[v] + b2 * f1[v];
        }
        let m = MetroOptions::DEFAULT.with_samples(300_000);
        let e = |x: &whet_mesh::Mesh| {
            let r = metro(&mesh, x, &m).unwrap().symmetric;
            format!("{:.4} {:.3}", r.rms_pct, r.max_pct)
        };
        println!(
            "{} {bpv}: unfiltered {} filtered {} sharpened {} sharpened+filter {} sharpened+fitted ({a2:.3}, {b2:.3}) {}",
            args[0],
            e(&raw),
            e(&filtered),
            e(&sharp),
            e(&post),
            e(&post_fit)
        );
    }
}
