//! Measurement: removing the swing angles' quantization noise before the surface filter.
//! Every swing tip lies within half an angle step of where the circle met the original,
//! along the circle's tangent (nearly the surface normal). The decoder knows that bin, so a
//! smoothing step may move each tip along its tangent, towards the surface its neighbours
//! describe, but no farther than its bin. This retiles a mesh, denoises it that way with
//! several strengths, fits and applies the surface filter, and measures against the original.
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_denoise -- L/diag BITS SAMPLES mesh.off...
//! ```
#![allow(clippy::unwrap_used)] // a measurement tool

use std::collections::HashMap;
use whet_codec::{SwingParams, VertexSource};
use whet_mesh::{DVec3, Mesh};
use whet_metro::{metro, Bvh, MetroOptions};
use whet_swing::{fit_surface_filter, retile, RetileTuning};

/// Per vertex: the area-weighted normal, the height above its neighbours' mean along it
/// (`d`), and its neighbours.
fn fields(m: &Mesh) -> (Vec<DVec3>, Vec<f64>, Vec<Vec<u32>>) {
    let n = m.positions.len();
    let mut nrm = vec![DVec3::ZERO; n];
    let mut nb: Vec<Vec<u32>> = vec![Vec::new(); n];
    for t in &m.triangles {
        let [a, b, c] = t.map(|v| m.positions[v as usize]);
        let x = (b - a).cross(c - a);
        for k in 0..3 {
            nrm[t[k] as usize] += x;
            for j in [1, 2] {
                let w = t[(k + j) % 3];
                if !nb[t[k] as usize].contains(&w) {
                    nb[t[k] as usize].push(w);
                }
            }
        }
    }
    let nrm: Vec<DVec3> = nrm.iter().map(|v| v.normalize_or_zero()).collect();
    let d = (0..n)
        .map(|i| {
            if nb[i].is_empty() {
                return 0.0;
            }
            let mean = nb[i]
                .iter()
                .map(|&w| m.positions[w as usize])
                .sum::<DVec3>()
                / nb[i].len() as f64;
            nrm[i].dot(m.positions[i] - mean)
        })
        .collect();
    (nrm, d, nb)
}

fn main() {
    let a: Vec<String> = std::env::args().skip(1).collect();
    let f: f64 = a[0].parse().unwrap();
    let bits: u32 = a[1].parse().unwrap();
    let samples: usize = a[2].parse().unwrap();
    for name in &a[3..] {
        let mesh = whet_io::read_path(&whet_testkit::shared_fixture(name), None).unwrap();
        let params = SwingParams::new(f * mesh.diagonal(), bits, &mesh.bounding_box(), 20).unwrap();
        let r = retile(&mesh, &params, &RetileTuning::DEFAULT).unwrap().mesh;
        let tris = &r.triangles;
        let pos = &r.positions;
        let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
        for (i, t) in tris.iter().enumerate() {
            for k in 0..3 {
                edges.insert((t[k], t[(k + 1) % 3]), i);
            }
        }
        // Each swing tip's tangent and half bin width.
        let mut tangent = vec![DVec3::ZERO; pos.len()];
        let mut half = vec![0.0f64; pos.len()];
        let mut seen = vec![false; pos.len()];
        for (i, t) in tris.iter().enumerate() {
            let [v, va, vb] = *t;
            let VertexSource::Swing(q) = r.sources[v as usize] else {
                continue;
            };
            if seen[v as usize] {
                continue;
            }
            seen[v as usize] = true;
            let Some(&p) = edges.get(&(vb, va)) else {
                continue;
            };
            if p >= i {
                continue;
            }
            let c = tris[p]
                .iter()
                .copied()
                .find(|&x| x != va && x != vb)
                .unwrap();
            let fr = params
                .frame(pos[va as usize], pos[vb as usize], pos[c as usize])
                .unwrap();
            let th = params.angles.angle(q);
            tangent[v as usize] = fr.e1 * -th.sin() + fr.e2 * th.cos();
            half[v as usize] = 0.5 * fr.radius * params.angles.step();
        }
        let bvh = Bvh::new(&mesh);
        let l = params.edge_length;
        let mo = MetroOptions::DEFAULT.with_samples(samples);
        for (gamma, passes, clamp) in [
            (0.0, 0, true),
            (0.5, 1, true),
            (1.0, 1, true),
            (1.0, 1, false),
            (0.5, 3, true),
            (1.0, 3, true),
            (0.5, 3, false),
        ] {
            let mut m = Mesh::new(pos.clone(), tris.clone());
            let mut moved = vec![0.0f64; pos.len()];
            for _ in 0..passes {
                let (nrm, d, nb) = fields(&m);
                let mut next = m.positions.clone();
                for i in 0..pos.len() {
                    if half[i] == 0.0 || nb[i].is_empty() {
                        continue;
                    }
                    let s = nb[i].iter().map(|&w| d[w as usize]).sum::<f64>() / nb[i].len() as f64;
                    let e = d[i] - s;
                    let nt = nrm[i].dot(tangent[i]);
                    if nt.abs() < 0.5 {
                        continue;
                    }
                    let mut t = moved[i] - gamma * e / nt;
                    if clamp {
                        t = t.clamp(-half[i], half[i]);
                    }
                    next[i] = pos[i] + tangent[i] * t;
                    moved[i] = t;
                }
                m.positions = next;
            }
            let filter = fit_surface_filter(&m, |p| {
                bvh.closest_point_within(p, 2.0 * l).map(|c| c.point)
            });
            let raw = metro(&mesh, &m, &mo).unwrap().symmetric.rms_pct;
            filter.apply(&mut m, l);
            let filtered = metro(&mesh, &m, &mo).unwrap().symmetric.rms_pct;
            println!(
                "{name} L={f} B={bits}: gamma {gamma} passes {passes} clamp {clamp}: denoised {raw:.4} %, filtered {filtered:.4} % (factors {:?})",
                filter.factors()
            );
        }
    }
}
