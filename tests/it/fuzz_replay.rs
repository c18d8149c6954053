//! Replays every fuzz regression (fuzz/corpus/<target>/regressions) and the seed corpora on
//! stable, so crashers found once stay fixed.

use std::path::PathBuf;

fn files(target: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let base = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fuzz/corpus")
        .join(target);
    for dir in [base.join("regressions"), base.clone()] {
        if let Ok(rd) = std::fs::read_dir(&dir) {
            for e in rd.flatten() {
                let p = e.path();
                if p.is_file() {
                    out.push(p);
                }
            }
        }
    }
    out.sort();
    out
}

#[test]
fn decode_regressions_and_seeds() {
    let f = files("decode");
    assert!(!f.is_empty(), "fuzz/corpus/decode has the seed streams");
    for p in f {
        whet_codec::fuzz_decode(&std::fs::read(&p).unwrap());
    }
}

/// fuzz/corpus/exact_payloads/regressions/crash-39d2b6a2…: the seed-triangle midpoint
/// overflowed i32 on garbage residuals (found by cargo fuzz, fixed by i64 arithmetic and
/// an early stop on off-grid coordinates).
#[test]
fn exact_payload_regressions_and_seeds() {
    let f = files("exact_payloads");
    assert!(!f.is_empty());
    for p in f {
        whet_codec::fuzz_exact_payloads(&std::fs::read(&p).unwrap());
    }
}

/// Swing streams of built meshes (closed, filtered; open, with deletion flags; unfiltered)
/// as `swing_payloads` inputs: the seeds of that target's corpus.
fn swing_seed_streams() -> Vec<(String, Vec<u8>)> {
    use whet_swing::{encode, Rate, SwingOptions};
    use whet_testkit::meshes::{icosphere, punch, torus};
    let at = |f: f64| SwingOptions::DEFAULT.with_rate(Rate::EdgeLength(f));
    let cases = [
        ("icosphere_filtered", icosphere(3), at(0.08)),
        (
            "icosphere_plain",
            icosphere(3),
            at(0.1).with_surface_filter(false),
        ),
        ("torus", torus(24, 12), at(0.06)),
        ("punched", punch(&icosphere(4), |t| t % 97 < 6), at(0.05)),
    ];
    cases
        .into_iter()
        .map(|(name, mesh, opts)| (name.to_string(), encode(&mesh, &opts).unwrap().bytes))
        .collect()
}

/// The seed conversion keeps the stream: the fuzz harness decodes a seed to exactly what
/// `decode` makes of its stream. `WHET_WRITE_FUZZ_SEEDS=1` (re)writes the seed files.
#[test]
fn swing_payload_seeds_decode_like_their_streams() {
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz/corpus/swing_payloads");
    for (name, stream) in swing_seed_streams() {
        let seed = whet_codec::swing_payload_seed(&stream).unwrap();
        let direct = whet_codec::decode(&stream, &whet_codec::DecodeOptions::DEFAULT).unwrap();
        let via_seed = whet_codec::fuzz_swing_payloads(&seed).unwrap();
        assert_eq!(via_seed, direct, "{name}");
        if std::env::var_os("WHET_WRITE_FUZZ_SEEDS").is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(dir.join(format!("seed-{name}")), &seed).unwrap();
        }
    }
}

#[test]
fn swing_payload_regressions_and_seeds() {
    let f = files("swing_payloads");
    assert!(
        !f.is_empty(),
        "fuzz/corpus/swing_payloads has the seed inputs"
    );
    for p in f {
        whet_codec::fuzz_swing_payloads(&std::fs::read(&p).unwrap());
    }
}
