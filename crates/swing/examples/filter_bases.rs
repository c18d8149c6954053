//! Measures least-squares mixes of more displacement fields than the surface filter's two
//! (a two-ring mean of `s`, the umbrella Laplacian with its tangential part, `d |d| / L`,
//! and `d`, `s` split between convex and concave vertices),
//! each fitted like the shipped filter and measured with Metro (300 000 samples):
//!
//! ```text
//! cargo run --release -p whet-swing --example filter_bases -- <fixture.off> <bytes | 10·bpv>
//! ```
//! (a second argument under 100 is ten times a rate in bits per original vertex: `8` = 0.8).
#![allow(clippy::unwrap_used)] // a measurement tool
use whet_codec::{decode, DecodeOptions, FilterFields};
use whet_mesh::{DVec3, Mesh};
use whet_metro::{metro, Bvh, MetroOptions};
use whet_swing::{encode, Rate, SwingOptions};

fn smooth(m: &Mesh, f: &[DVec3]) -> Vec<DVec3> {
    let n = m.positions.len();
    let mut s = f.to_vec();
    let mut c = vec![1.0f64; n];
    for t in &m.triangles {
        for (v, w) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            s[v as usize] += f[w as usize];
            c[v as usize] += 1.0;
        }
    }
    s.iter().zip(&c).map(|(a, b)| *a / *b).collect()
}

fn umbrella(m: &Mesh) -> Vec<DVec3> {
    let n = m.positions.len();
    let mut s = vec![DVec3::ZERO; n];
    let mut c = vec![0.0f64; n];
    for t in &m.triangles {
        for (v, w) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            s[v as usize] += m.positions[w as usize];
            c[v as usize] += 1.0;
        }
    }
    (0..n)
        .map(|v| {
            if c[v] > 0.0 {
                s[v] / c[v] - m.positions[v]
            } else {
                DVec3::ZERO
            }
        })
        .collect()
}

/// Unit area-weighted vertex normals (the direction of the filter's fields).
fn unit_normals(m: &Mesh) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; m.positions.len()];
    for (t, tri) in m.triangles.iter().enumerate() {
        let c = m.face_cross(t);
        for &v in tri {
            n[v as usize] += c;
        }
    }
    n.iter().map(|x| x.normalize_or_zero()).collect()
}

fn solve(a: &mut [Vec<f64>], b: &mut [f64]) -> Vec<f64> {
    let n = b.len();
    for i in 0..n {
        let p = a[i][i];
        for j in i + 1..n {
            let f = a[j][i] / p;
            for k in i..n {
                a[j][k] -= f * a[i][k];
            }
            b[j] -= f * b[i];
        }
    }
    let mut x = vec![0.0; n];
    for i in (0..n).rev() {
        let mut s = b[i];
        for k in i + 1..n {
            s -= a[i][k] * x[k];
        }
        x[i] = s / a[i][i];
    }
    x
}

fn fit(orig: &Bvh, m: &Mesh, bases: &[Vec<DVec3>]) -> Mesh {
    let k = bases.len();
    let mut ata = vec![vec![0.0; k]; k];
    let mut atb = vec![0.0; k];
    let pat = [
        [1.0 / 3.0, 1.0 / 3.0, 1.0 / 3.0],
        [2.0 / 3.0, 1.0 / 6.0, 1.0 / 6.0],
        [1.0 / 6.0, 2.0 / 3.0, 1.0 / 6.0],
        [1.0 / 6.0, 1.0 / 6.0, 2.0 / 3.0],
    ];
    let mut q = orig.coherent_query();
    for (ti, t) in m.triangles.iter().enumerate() {
        let nf = m.face_normal(ti);
        let area = m.face_area(ti);
        let [i, j, l] = t.map(|v| v as usize);
        for w in pat {
            let p = w[0] * m.positions[i] + w[1] * m.positions[j] + w[2] * m.positions[l];
            let r = (q.closest_point(p).point - p).dot(nf);
            let x: Vec<f64> = bases
                .iter()
                .map(|b| (w[0] * b[i] + w[1] * b[j] + w[2] * b[l]).dot(nf))
                .collect();
            for a in 0..k {
                atb[a] += area * r * x[a];
                for c in 0..k {
                    ata[a][c] += area * x[a] * x[c];
                }
            }
        }
    }
    let c = solve(&mut ata, &mut atb);
    eprintln!("coefficients {c:.3?}");
    let mut out = m.clone();
    for v in 0..m.positions.len() {
        for (b, cb) in bases.iter().zip(&c) {
            out.positions[v] += *cb * b[v];
        }
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let bytes: usize = args[1].parse().unwrap();
    let mesh = whet_io::read_path(&whet_testkit::shared_fixture(&args[0]), None).unwrap();
    let rate = if bytes < 100 {
        Rate::BitsPerVertex(bytes as f64 / 10.0)
    } else {
        Rate::TargetBytes(bytes)
    };
    let out = encode(&mesh, &SwingOptions::DEFAULT.with_rate(rate)).unwrap();
    let back = decode(
        &out.bytes,
        &DecodeOptions::DEFAULT.with_surface_filter(false),
    )
    .unwrap();
    let bvh = Bvh::new(&mesh);
    let f = FilterFields::new(&back);
    let s2 = smooth(&back, &f.smoothed);
    let lap = umbrella(&back);
    let nl: Vec<DVec3> = f
        .normal
        .iter()
        .map(|d| *d * d.length() / out.edge_length)
        .collect();
    // The two fields split by the sign of d: convex and concave vertices fitted apart.
    let d_sign: Vec<f64> = f
        .normal
        .iter()
        .zip(&unit_normals(&back))
        .map(|(dn, n)| dn.dot(*n))
        .collect();
    let split = |field: &[DVec3], convex: bool| -> Vec<DVec3> {
        field
            .iter()
            .zip(&d_sign)
            .map(|(x, &d)| if (d > 0.0) == convex { *x } else { DVec3::ZERO })
            .collect()
    };
    let sets: Vec<(&str, Vec<Vec<DVec3>>)> = vec![
        (
            "d+,d-,s+,s-",
            vec![
                split(&f.normal, true),
                split(&f.normal, false),
                split(&f.smoothed, true),
                split(&f.smoothed, false),
            ],
        ),
        ("d,s", vec![f.normal.clone(), f.smoothed.clone()]),
        (
            "d,s,s2",
            vec![f.normal.clone(), f.smoothed.clone(), s2.clone()],
        ),
        (
            "d,s,lap",
            vec![f.normal.clone(), f.smoothed.clone(), lap.clone()],
        ),
        (
            "d,s,d|d|",
            vec![f.normal.clone(), f.smoothed.clone(), nl.clone()],
        ),
        (
            "all",
            vec![f.normal.clone(), f.smoothed.clone(), s2, lap, nl],
        ),
    ];
    let mo = MetroOptions::DEFAULT.with_samples(300_000);
    let r0 = metro(&mesh, &back, &mo).unwrap().symmetric;
    println!(
        "{} {} B: none {:.4} max {:.3}",
        args[0],
        out.bytes.len(),
        r0.rms_pct,
        r0.max_pct
    );
    for (name, b) in sets {
        let m = fit(&bvh, &back, &b);
        let r = metro(&mesh, &m, &mo).unwrap().symmetric;
        println!("  {name}: {:.4} max {:.3}", r.rms_pct, r.max_pct);
    }
}
