//! Prints the size and a digest of the exact-mode stream of every shared fixture at
//! Q = 11 and 14 and of the bench icosphere, with the default prediction and then (lines
//! marked `traversal`) the traversal prediction, and checks each round trip: a refactoring aid
//! (`cargo run --release -p whet-codec --example stream_digest`), since a change that should
//! not alter the stream must leave every line the same.
#![allow(clippy::unwrap_used)]

use whet_codec::{decode, encode, DecodeOptions, EncodeOptions, ExactPrediction};

fn digest(bytes: &[u8]) -> u64 {
    // FNV-1a, 64 bits.
    bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| {
        (h ^ b as u64).wrapping_mul(0x0100_0000_01b3)
    })
}

fn main() {
    let dir = whet_testkit::shared_fixture("armadillo.off");
    let dir = dir.parent().unwrap();
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| {
            let p = e.ok()?.path();
            (p.extension()? == "off").then_some(p)
        })
        .collect();
    names.sort();
    let mut meshes: Vec<(String, whet_mesh::Mesh)> = names
        .iter()
        .map(|p| {
            let name = p.file_stem().unwrap().to_string_lossy().into_owned();
            (name, whet_io::read_path(p, None).unwrap())
        })
        .collect();
    meshes.push((
        "icosphere8-shuffled".into(),
        whet_testkit::meshes::shuffle(&whet_testkit::meshes::icosphere(8), 1),
    ));
    for (prediction, label) in [
        (ExactPrediction::Degree, ""),
        (ExactPrediction::Traversal, " traversal"),
        (ExactPrediction::TraversalStatic, " traversal-static"),
    ] {
        print_streams(&meshes, prediction, label);
    }
}

fn print_streams(meshes: &[(String, whet_mesh::Mesh)], prediction: ExactPrediction, label: &str) {
    for (name, mesh) in meshes {
        for bits in [11, 14] {
            let opts = EncodeOptions::DEFAULT
                .with_quant_bits(bits)
                .with_prediction(prediction);
            let enc = encode(mesh, &opts).unwrap();
            let back = decode(&enc.bytes, &DecodeOptions::DEFAULT).unwrap();
            assert_eq!(back.triangles.len(), enc.report.triangles, "{name}");
            println!(
                "{name} q{bits}{label}: {} B (conn {} + geom {} bytes) {:016x}",
                enc.bytes.len(),
                enc.report.connectivity_bits / 8,
                enc.report.geometry_bits / 8,
                digest(&enc.bytes)
            );
        }
    }
}
