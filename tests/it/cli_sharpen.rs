//! `whet sharpen`, `whet bend` and `whet decode --sharpen --bend`: sharpening a chamfered
//! marching-cubes cube must bring it closer to the true cube.

use crate::{s, whet, whet_json};
use whet_testkit::scratch_dir;

fn rms_pct(truth: &std::path::Path, test: &std::path::Path) -> (f64, f64) {
    let j = whet_json(&["metro", s(truth), s(test), "--samples", "100000", "--json"]);
    (
        j["max_pct"].as_f64().unwrap(),
        j["rms_pct"].as_f64().unwrap(),
    )
}

#[test]
fn sharpen_then_bend_on_a_chamfered_cube() {
    let dir = scratch_dir("cli-sharpen");
    let (mc, truth) = (dir.join("cube.off"), dir.join("truth.off"));
    let o = whet(&[
        "synth",
        "cube",
        "-o",
        s(&mc),
        "--truth",
        s(&truth),
        "--resolution",
        "40",
        "--rotate",
        "1,2,3,25",
    ]);
    assert!(o.status.success());
    let sharp = dir.join("sharp.ply");
    let tags = dir.join("sharp.tags");
    let j = whet_json(&[
        "sharpen",
        s(&mc),
        "-o",
        s(&sharp),
        "--tags",
        s(&tags),
        "--json",
    ]);
    for key in [
        "smooth_edges",
        "chamfer_edges",
        "corner_triangles",
        "new_vertices",
        "collapsed_triangles",
        "time_ms",
        "unmoved",
    ] {
        assert!(!j[key].is_null(), "missing {key}: {j}");
    }
    assert!(j["chamfer_edges"].as_u64().unwrap() > 0);
    let (max0, rms0) = rms_pct(&truth, &mc);
    let (max1, rms1) = rms_pct(&truth, &sharp);
    assert!(rms1 < rms0 / 3.0, "RMS {rms0} -> {rms1}");
    assert!(max1 <= max0, "max {max0} -> {max1}");
    let bent = dir.join("bent.off");
    let o = whet(&[
        "bend",
        s(&sharp),
        "-o",
        s(&bent),
        "--tags",
        s(&tags),
        "--levels",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let info = whet_json(&["info", s(&bent), "--json"]);
    assert_eq!(info["manifold"], true);
    // A cube has no curved surface for Bender to gain on; it must not undo the sharpening.
    let (_, rms2) = rms_pct(&truth, &bent);
    assert!(rms2 < rms0 / 3.0, "{rms2}");
    // Without tags, bend says it falls back to filter 3bis.
    let o = whet(&["bend", s(&sharp), "-o", s(&dir.join("b2.off"))]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("filter 3bis"));
}

#[test]
fn decode_sharpen_and_bend() {
    let dir = scratch_dir("cli-decode-sharpen");
    let mc = dir.join("cube.off");
    assert!(whet(&[
        "synth",
        "cube",
        "-o",
        s(&mc),
        "--resolution",
        "24",
        "--rotate",
        "0,1,1,30"
    ])
    .status
    .success());
    let stream = dir.join("c.whet");
    assert!(
        whet(&["encode", s(&mc), "-o", s(&stream), "--mode", "exact"])
            .status
            .success()
    );
    let out = dir.join("c.obj");
    let o = whet(&[
        "decode",
        s(&stream),
        "-o",
        s(&out),
        "--sharpen",
        "--bend",
        "1",
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let plain = whet_json(&["info", s(&mc), "--json"]);
    let info = whet_json(&["info", s(&out), "--json"]);
    assert!(info["triangles"].as_u64().unwrap() > 4 * plain["triangles"].as_u64().unwrap());
    assert_eq!(info["manifold"], true);
    let o = whet(&["decode", s(&stream), "-o", s(&out), "--bend", "1"]);
    assert_eq!(o.status.code(), Some(2), "--bend needs --sharpen");
}
