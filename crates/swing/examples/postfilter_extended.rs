//! Measures what the extended surface filter's three fields would add to the filter for
//! after sharpening (header fields 17 and 19, two fields): each mesh is encoded at each rate
//! (`--optimize-for sharpened`'s choice is not made; EdgeSharpener's defaults), decoded
//! without the filter and sharpened; both filters are fitted, as the encoder fits them, on
//! the fields of the unfiltered mesh kept to the vertices the sharpener left alone
//! (`whet_codec::untouched_by_sharpening`), and applied there. Prints the symmetric RMS and
//! max (% of the diagonal, 300 000 Metro samples) of the sharpened mesh, with the two-field
//! fit, and with the five-field fit.
//!
//! ```text
//! cargo run --release -p whet-swing --example postfilter_extended -- <fixture.off> <bpv>...
//! ```
//!
//! Diagnostics: `RINGS=k` keeps k more rings around the sharpened part in place, `DROP=k`
//! replaces extended field k (0 `s2`, 1 `q`, 2 `t`) by a copy of `d n`, `CAP=c` caps `q` at
//! `c |d|`. On joint at 3 bpv the five-field max (0.662 % against 0.418 %) comes from `q`:
//! `DROP=1` gives 0.418 % (and keeps 0.2 % of the RMS gain instead of 3.1 %), `DROP=0` or
//! `2`, more rings and caps of 0.5 or 1 do not remove it.
//!
//! `PROJECT=1`: the planar and quadric projections (`PLANAR_FACTOR`, `QUADRIC_FACTOR`) after
//! the filter, as `whet decode --sharpen` runs them when a stream states them; the first
//! column is then the projections without a filter. `PROJECT=2`: the projections first, then
//! the filters fitted and applied on the vertices neither the sharpener nor the projections
//! moved (docs/results.md, "The filter for after sharpening under the projections").
//! `PRE=1` also prints the decoded mesh with its own surface filter sharpened, then
//! projected as `PROJECT` says.
#![allow(clippy::unwrap_used)] // a measurement tool

use whet_codec::{decode, untouched_by_sharpening, DecodeOptions, FilterFields};
use whet_mesh::{DVec3, Mesh};
use whet_metro::{metro, MetroOptions};
use whet_swing::{encode, fit_filters, Rate, SwingOptions};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh = whet_io::read_path(&whet_testkit::shared_fixture(&args[0]), None).unwrap();
    let bvh = whet_metro::Bvh::new(&mesh);
    let m = MetroOptions::DEFAULT.with_samples(300_000);
    let e = |x: &Mesh| {
        let r = metro(&mesh, x, &m).unwrap().symmetric;
        format!("{:.5} / {:.3}", r.rms_pct, r.max_pct)
    };
    for r in &args[1..] {
        let bpv: f64 = r.parse().unwrap();
        let opts = SwingOptions::DEFAULT.with_rate(Rate::BitsPerVertex(bpv));
        let out = encode(&mesh, &opts).unwrap();
        let l = out.edge_length;
        let raw = decode(
            &out.bytes,
            &DecodeOptions::DEFAULT.with_surface_filter(false),
        )
        .unwrap();
        let sharp = whet_sharpen::sharpen(&raw, &whet_sharpen::SharpenOptions::DEFAULT)
            .unwrap()
            .mesh;
        // PROJECT=2: the projections first, then the filter fitted and applied on the
        // vertices that neither the sharpener nor the projections moved.
        // Both projections, as `whet decode --sharpen` applies them when a stream states them
        // (a mesh they refuse stays as it is, as in the decoder).
        let projections = |x: &mut Mesh| {
            let b = out.angle_bits;
            let _ = whet_sharpen::flatten_planar_regions(
                x,
                &whet_sharpen::PlanarOptions::for_swing(b, whet_swing::PLANAR_FACTOR),
            );
            let _ = whet_sharpen::project_onto_local_quadrics(
                x,
                &whet_sharpen::QuadricOptions::for_swing(b, whet_swing::QUADRIC_FACTOR),
            );
        };
        let mut sharp = sharp;
        if std::env::var("PROJECT").is_ok_and(|v| v == "2") {
            projections(&mut sharp);
        }
        let mut free = untouched_by_sharpening(&raw, &sharp);
        // RINGS=k: k more rings around the sharpened part stay put.
        let rings: usize = std::env::var("RINGS")
            .ok()
            .map_or(0, |x| x.parse().unwrap());
        for _ in 0..rings {
            let seed = free.clone();
            for t in &sharp.triangles {
                if t.iter().any(|&v| !seed[v as usize]) {
                    for &v in t {
                        free[v as usize] = false;
                    }
                }
            }
        }
        let (two, extra) = FilterFields::extended(&raw, l);
        let keep = |f: &[DVec3]| -> Vec<DVec3> {
            (0..sharp.positions.len())
                .map(|v| match (free.get(v), f.get(v)) {
                    (Some(true), Some(&x)) => x,
                    _ => DVec3::ZERO,
                })
                .collect()
        };
        let kept = FilterFields {
            normal: keep(&two.normal),
            smoothed: keep(&two.smoothed),
        };
        let mut extra = [keep(&extra[0]), keep(&extra[1]), keep(&extra[2])];
        // DROP=k: leave out extended field k (0 s2, 1 q, 2 t), to find which one a change
        // of the max comes from.
        // CAP=c: q capped at c |d| (q = d min(|d| / L, c)).
        if let Some(c) = std::env::var("CAP").ok().map(|x| x.parse::<f64>().unwrap()) {
            extra[1] = kept
                .normal
                .iter()
                .map(|dn| *dn * (dn.length() / l).min(c))
                .collect();
        }
        // (Replaced by a copy of the normal field: a column of zeros leaves the equations
        // without a solution, a collinear one is split by the ridge.)
        if let Some(k) = std::env::var("DROP")
            .ok()
            .map(|x| x.parse::<usize>().unwrap())
        {
            extra[k] = kept.normal.clone();
        }
        let fit = fit_filters(&sharp, &kept, &extra, |p| {
            bvh.closest_point_within(p, 2.0 * l).map(|c| c.point)
        });
        let apply = |f: [f64; 5]| {
            let mut x = sharp.clone();
            let fields = [
                &kept.normal,
                &kept.smoothed,
                &extra[0],
                &extra[1],
                &extra[2],
            ];
            for (v, p) in x.positions.iter_mut().enumerate() {
                for (k, field) in fields.iter().enumerate() {
                    *p += f[k] * field[v];
                }
            }
            x
        };
        // PROJECT=1: the planar and quadric projections after the filter, as `whet decode
        // --sharpen` applies them when the stream states them.
        let project = |mut x: Mesh| -> Mesh {
            if std::env::var("PROJECT").is_ok_and(|v| v == "1") {
                projections(&mut x);
            }
            x
        };
        let sharp = project(sharp.clone());
        let basic = project(apply(fit.basic.extended_factors()));
        let (ext, ratio) = fit.extended.unwrap();
        let extended = project(apply(ext.extended_factors()));
        // PRE=1: also the decoded mesh with its own surface filter sharpened, then projected
        // (no filter after sharpening).
        if std::env::var("PRE").is_ok() {
            let filtered = decode(&out.bytes, &DecodeOptions::DEFAULT).unwrap();
            let s = whet_sharpen::sharpen(&filtered, &whet_sharpen::SharpenOptions::DEFAULT)
                .unwrap()
                .mesh;
            println!(
                "{} {bpv} bpv: filtered then sharpened {}",
                args[0],
                e(&project(s))
            );
        }
        println!(
            "{} {bpv} bpv ({} B): sharpened {}, two fields {}, five fields {} (fitted ratio {ratio:.3})",
            args[0],
            out.bytes.len(),
            e(&sharp),
            e(&basic),
            e(&extended)
        );
    }
}
