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
