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
    let path = if args[0].contains('/') {
        std::path::PathBuf::from(&args[0])
    } else {
        whet_testkit::shared_fixture(&args[0])
    };
    let mesh = whet_io::read_path(&path, None).unwrap();
    let f: f64 = args[1].parse().unwrap();
    let l = f * mesh.diagonal();
    let params = SwingParams::new(l, 8, &mesh.bounding_box(), 20).unwrap();
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
            println!(
                "{} folds > 90 deg: {:?}",
                folds.len(),
                &folds[..folds.len().min(30)]
            );
        }
        Err(e) => println!("error: {e}"),
    }
}
