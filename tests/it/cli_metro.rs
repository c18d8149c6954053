//! `whet metro`: the JSON contract, the colour export and bad input.

use crate::{s, whet, whet_json};
use whet_testkit::{resolve_shared_reference, scratch_dir, shared_fixture};

#[test]
fn json_contract_and_reference_pair() {
    let reference = shared_fixture("fandisk.off");
    let test = resolve_shared_reference("../shared/fixtures/metro/fandisk.noisy.off");
    let dir = scratch_dir("cli-metro");
    let ply = dir.join("err.ply");
    let j = whet_json(&[
        "metro",
        s(&reference),
        s(&test),
        "--samples",
        "200000",
        "--seed",
        "3",
        "--json",
        "--colorize",
        s(&ply),
    ]);
    for key in [
        "max", "mean", "rms", "max_pct", "mean_pct", "rms_pct", "diagonal", "samples",
    ] {
        assert!(j[key].is_number(), "{key}: {j}");
    }
    for side in ["forward", "backward"] {
        for key in [
            "max", "mean", "rms", "max_pct", "mean_pct", "rms_pct", "samples",
        ] {
            assert!(j[side][key].is_number(), "{side}.{key}: {j}");
        }
    }
    assert_eq!(j["samples"], 200000);
    // MeshLab (../shared/metro-reference.json, fandisk-noisy): max 0.2728 %, RMS 0.0699 %;
    // 200k samples: max within 2 %, RMS within 5 %.
    let max_pct = j["max_pct"].as_f64().unwrap();
    let rms_pct = j["rms_pct"].as_f64().unwrap();
    assert!((max_pct / 0.27276516 - 1.0).abs() < 0.02, "{max_pct}");
    assert!((rms_pct / 0.06989354 - 1.0).abs() < 0.05, "{rms_pct}");
    // Symmetric = larger of the two directions.
    let fwd = j["forward"]["max"].as_f64().unwrap();
    let bwd = j["backward"]["max"].as_f64().unwrap();
    assert_eq!(j["max"].as_f64().unwrap(), fwd.max(bwd));
    // The same seed gives the same figures.
    let again = whet_json(&[
        "metro",
        s(&reference),
        s(&test),
        "--samples",
        "200000",
        "--seed",
        "3",
        "--json",
    ]);
    assert_eq!(again["rms"], j["rms"]);
    // The colour export is a PLY of the test mesh.
    let m = whet::io::read_path(&ply, None).unwrap();
    assert_eq!(m.positions.len(), 6475);
    let header = std::fs::read(&ply).unwrap();
    let text = String::from_utf8_lossy(&header[..400.min(header.len())]);
    assert!(text.contains("quality") && text.contains("red"), "{text}");
}

#[test]
fn identical_meshes_measure_zero_and_bad_input_exits_2() {
    let cube = shared_fixture("cube.off");
    let j = whet_json(&["metro", s(&cube), s(&cube), "--samples", "10000", "--json"]);
    // Sample points are interpolated in f64, so "zero" is at rounding level.
    assert!(j["max"].as_f64().unwrap() < 1e-12);
    let dir = scratch_dir("cli-metro-bad");
    let empty = dir.join("empty.off");
    std::fs::write(&empty, "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n").unwrap();
    let o = whet(&["metro", s(&cube), s(&empty)]);
    assert_eq!(
        o.status.code(),
        Some(2),
        "{}",
        String::from_utf8_lossy(&o.stderr)
    );
    let garbage = dir.join("g.ply");
    std::fs::write(&garbage, b"ply\nformat nonsense\n").unwrap();
    let o = whet(&["metro", s(&garbage), s(&cube)]);
    assert_eq!(o.status.code(), Some(2));
    // An absurd sample count is refused at once, not sampled for hours.
    let o = whet(&["metro", s(&cube), s(&cube), "--samples", "100000000000"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("more than the limit"));
}
