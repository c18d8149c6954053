//! Retiles one mesh and writes the retiled mesh as OFF, printing the labels: a debugging aid.
//!
//! ```text
//! cargo run --release -p whet-swing --example swing_debug -- mesh.off FRACTION out.off
//! ```
#![allow(clippy::unwrap_used)] // a debugging tool

use whet_codec::SwingParams;
use whet_swing::{retile, RetileTuning};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let mesh = match args[0].as_str() {
        name if name.starts_with("builtin:holes") => {
            // builtin:holes:<icosphere level>:<modulus>:<width>
            let p: Vec<usize> = name
                .split(':')
                .skip(2)
                .map(|x| x.parse().unwrap())
                .collect();
            let (lev, m, w) = (
                *p.first().unwrap_or(&4),
                *p.get(1).unwrap_or(&97),
                *p.get(2).unwrap_or(&6),
            );
            whet_testkit::meshes::punch(&whet_testkit::meshes::icosphere(lev as u32), |t| t % m < w)
        }
        "builtin:grid" => whet_testkit::meshes::grid(20, 20),
        name if name.contains('/') => whet_io::read_path(std::path::Path::new(name), None).unwrap(),
        name => whet_io::read_path(&whet_testkit::shared_fixture(name), None).unwrap(),
    };
    if let Some(out) = args.get(3) {
        whet_io::write_path(
            std::path::Path::new(out),
            &mesh,
            None,
            &whet_io::WriteOptions::DEFAULT,
        )
        .unwrap();
    }
    let f: f64 = args[1].parse().unwrap();
    let l = f * mesh.diagonal();
    let bits: u32 = std::env::var("BITS")
        .ok()
        .and_then(|b| b.parse().ok())
        .unwrap_or(6);
    let params = SwingParams::new(l, bits, &mesh.bounding_box(), 20).unwrap();
    match retile(&mesh, &params, &RetileTuning::DEFAULT) {
        Ok(r) => {
            let labels: String = r.mesh.labels.iter().map(|l| l.letter()).collect();
            println!("{} triangles, stats {:?}", r.mesh.triangles.len(), r.stats);
            println!("labels: {}", &labels[..labels.len().min(4000)]);
            let m = whet_mesh::Mesh::new(r.mesh.positions.clone(), r.mesh.triangles.clone());
            if let Some(out) = args.get(2) {
                whet_io::write_path(
                    std::path::Path::new(out),
                    &m,
                    None,
                    &whet_io::WriteOptions::DEFAULT,
                )
                .unwrap();
            }
            println!("{:?}", m.topology_report());
            // Folds: adjacent triangles whose normals differ by more than 90 degrees.
            let mut edge_tri = std::collections::HashMap::new();
            for (t, tri) in m.triangles.iter().enumerate() {
                for i in 0..3 {
                    edge_tri.insert((tri[i], tri[(i + 1) % 3]), t);
                }
            }
            let normals = m.face_normals();
            let mut folds = Vec::new();
            for (t, tri) in m.triangles.iter().enumerate() {
                for i in 0..3 {
                    if let Some(&u) = edge_tri.get(&(tri[(i + 1) % 3], tri[i])) {
                        if u > t && normals[t].dot(normals[u]) < 0.0 {
                            folds.push((
                                t,
                                u,
                                r.mesh.labels.get(t.wrapping_sub(1)).map(|l| l.letter()),
                                r.mesh.labels.get(u.wrapping_sub(1)).map(|l| l.letter()),
                            ));
                        }
                    }
                }
            }
            // Triangles far off the original (a wrap defect or a cut): creation index, label.
            let bvh = whet_metro::Bvh::new(&mesh);
            let mut far = Vec::new();
            for (t, tri) in m.triangles.iter().enumerate() {
                let [a, b, c] = tri.map(|v| m.positions[v as usize]);
                let d = [
                    (a + b + c) / 3.0,
                    (a + b) / 2.0,
                    (b + c) / 2.0,
                    (c + a) / 2.0,
                ]
                .iter()
                .map(|&p| (bvh.closest_point(p).point - p).length())
                .fold(0.0, f64::max);
                if d > 0.3 * l {
                    let label = r.mesh.labels.get(t.wrapping_sub(1)).map(|l| l.letter());
                    far.push((t, label, (d / l * 100.0).round() / 100.0));
                }
            }
            println!(
                "{} triangles farther than 0.3 L: {:?}",
                far.len(),
                &far[..far.len().min(60)]
            );
            println!(
                "{} folds > 90 deg: {:?}",
                folds.len(),
                &folds[..folds.len().min(30)]
            );
        }
        Err(e) => println!("error: {e}"),
    }
}
