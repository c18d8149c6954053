//! `whet rd` and `whet demo`: output files and their schema.

use crate::{s, whet};
use whet_testkit::{scratch_dir, shared_file, shared_fixture};

#[test]
fn rd_writes_csv_json_markdown_and_svg() {
    let dir = scratch_dir("cli-rd");
    let out = dir.join("rd");
    let o = whet(&[
        "rd",
        s(&shared_fixture("fandisk.off")),
        "--exact-bits",
        "8,11",
        "--samples",
        "50000",
        "--out",
        s(&out),
        "--draco",
        s(&shared_file("anchors/draco.md")),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let csv = std::fs::read_to_string(out.join("rd.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert_eq!(header, whet_rd::COLUMNS.join(","));
    assert_eq!(csv.lines().count(), 3);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("rd.json")).unwrap()).unwrap();
    let pts = json["points"].as_array().unwrap();
    assert_eq!(pts.len(), 2);
    assert_eq!(pts[0]["mesh"], "fandisk");
    assert_eq!(pts[0]["mode"], "exact");
    assert_eq!(pts[0]["stage"], "decoded");
    // q = 8 costs less and errs more than q = 11.
    assert!(pts[0]["bytes"].as_u64() < pts[1]["bytes"].as_u64());
    assert!(pts[0]["rms_e4"].as_f64() > pts[1]["rms_e4"].as_f64());
    let svg = std::fs::read_to_string(out.join("fandisk.svg")).unwrap();
    assert!(svg.contains("Draco"), "the Draco baseline is drawn");
    let md = String::from_utf8_lossy(&o.stdout);
    assert!(md.contains("### fandisk"));
}

#[test]
fn rd_reports_unknown_modes_and_stages() {
    let o = whet(&["rd", s(&shared_fixture("cube.off")), "--modes", "nonsense"]);
    assert_eq!(o.status.code(), Some(2));
    let o = whet(&["rd", s(&shared_fixture("cube.off")), "--stages", "nonsense"]);
    assert_eq!(o.status.code(), Some(2));
}
