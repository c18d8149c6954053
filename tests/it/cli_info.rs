//! `whet info` on the public fixtures and on broken files.

use crate::{s, whet, whet_json};
use whet_testkit::{scratch_dir, shared_fixture};

#[test]
fn fandisk_json_contract() {
    let j = whet_json(&["info", s(&shared_fixture("fandisk.off")), "--json"]);
    assert_eq!(j["vertices"], 6475);
    assert_eq!(j["triangles"], 12946);
    assert_eq!(j["edges"], 19419);
    assert_eq!(j["components"], 1);
    assert_eq!(j["boundary_loops"], 0);
    assert_eq!(j["genus"], 0);
    assert_eq!(j["manifold"], true);
    assert_eq!(j["problems"], serde_json::json!([]));
    // SOURCES.md gives the bbox diagonal as 7.61559.
    let d = j["bbox_diagonal"].as_f64().unwrap();
    assert!((d - 7.61559).abs() < 1e-5, "diagonal {d}");
    assert!(j["mean_edge_length"].as_f64().unwrap() > 0.0);
}

/// Counts and genus of every public fixture, from shared/fixtures/SOURCES.md (measured there
/// with pymeshlab).
#[test]
fn every_shared_fixture_reports_its_counts() {
    let table: &[(&str, u64, u64, u64)] = &[
        ("fandisk", 6475, 12946, 0),
        ("block", 8771, 17550, 3),
        ("joint", 20902, 41808, 2),
        ("partLp", 4261, 8530, 3),
        ("rocker_arm", 10044, 20088, 1),
        ("sharp_sphere", 10443, 20882, 0),
        ("sledge", 104, 212, 2),
        ("cube", 8, 12, 0),
        ("screwdriver", 3395, 6786, 0),
        ("bunny", 3485, 6966, 0),
        ("fertility", 4494, 9000, 4),
        ("spot", 2930, 5856, 0),
        ("armadillo", 43243, 86482, 0),
        ("cad_box_hole", 13722, 27444, 1),
        ("cad_cyl_fillet", 13312, 26620, 0),
        ("cad_bracket", 10654, 21308, 1),
        ("bunny_dense", 55730, 111456, 0),
    ];
    for &(name, v, t, genus) in table {
        let path = shared_fixture(&format!("{name}.off"));
        let j = whet_json(&["info", s(&path), "--json"]);
        assert_eq!(j["vertices"], v, "{name}");
        assert_eq!(j["triangles"], t, "{name}");
        assert_eq!(j["genus"], genus, "{name}");
        assert_eq!(j["manifold"], true, "{name}");
        assert_eq!(j["boundary_loops"], 0, "{name}");
        assert_eq!(j["components"], 1, "{name}");
    }
}

fn expect_input_error(name: &str, contents: &[u8], needle: &str) {
    let dir = scratch_dir("info-errors");
    let path = dir.join(name);
    std::fs::write(&path, contents).unwrap();
    let out = whet(&["info", s(&path), "--json"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{name}: {err}");
    assert!(
        err.to_lowercase().contains(needle),
        "{name}: stderr {err:?} should mention {needle:?}"
    );
    assert!(out.stdout.is_empty(), "{name}: nothing on stdout");
    assert!(!err.contains("panicked"), "{name}: {err}");
}

#[test]
fn unreadable_files_exit_2() {
    expect_input_error(
        "nan.off",
        b"OFF\n3 1 0\n0 0 0\nnan 0 0\n0 1 0\n3 0 1 2\n",
        "non-finite",
    );
    expect_input_error(
        "inf.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 inf 0\nf 1 2 3\n",
        "non-finite",
    );
    expect_input_error("truncated.off", b"OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n", "");
    expect_input_error("garbage.ply", b"\x00\x01garbage\xff\xfe", "");
    expect_input_error(
        "range.off",
        b"OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n",
        "7",
    );
    expect_input_error("empty.stl", b"", "");
    let fandisk = std::fs::read(shared_fixture("fandisk.off")).unwrap();
    expect_input_error("cut.off", &fandisk[..fandisk.len() / 2], "");
}

#[test]
fn missing_file_exits_2_and_unknown_extension_too() {
    let out = whet(&["info", "/nonexistent/whet/mesh.off"]);
    assert_eq!(out.status.code(), Some(2));
    let dir = scratch_dir("info-ext");
    let p = dir.join("mesh.xyz");
    std::fs::write(&p, b"hello").unwrap();
    let out = whet(&["info", s(&p)]);
    assert_eq!(out.status.code(), Some(2));
}

#[test]
fn non_manifold_mesh_is_reported_not_refused() {
    let dir = scratch_dir("info-nonmanifold");
    let p = dir.join("fin.off");
    // Three triangles on edge (0, 1) and a bow-tie at vertex 5.
    std::fs::write(
        &p,
        "OFF\n9 5 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n5 5 5\n6 5 5\n5 6 5\n4 5 5\n\
         3 0 1 2\n3 1 0 3\n3 0 1 4\n3 5 6 7\n3 5 8 6\n",
    )
    .unwrap();
    let j = whet_json(&["info", s(&p), "--json"]);
    assert_eq!(j["manifold"], false);
    assert!(j["genus"].is_null());
    let kinds: Vec<&str> = j["problems"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["kind"].as_str().unwrap())
        .collect();
    assert!(kinds.contains(&"non_manifold_edge"), "{kinds:?}");
    let msgs = j["problems"].to_string();
    assert!(
        msgs.contains("edge (0, 1) has 3 incident triangles"),
        "{msgs}"
    );

    // The text form names the same problems.
    let out = whet(&["info", s(&p)]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("manifold        no"), "{text}");
    assert!(
        text.contains("edge (0, 1) has 3 incident triangles"),
        "{text}"
    );
}

/// `whet info` of a `.whet` stream: its header and sections, checksums checked, nothing
/// decoded; a damaged stream is an input error (exit 2) naming the problem.
#[test]
fn a_stream_reports_its_header_and_sections() {
    let dir = scratch_dir("cli-info-stream");
    let stream = dir.join("f.whet");
    let enc = whet_json(&[
        "encode",
        s(&shared_fixture("fandisk.off")),
        "-o",
        s(&stream),
        "--edge-length",
        "0.02",
        "--json",
    ]);
    let j = whet_json(&["info", s(&stream), "--json"]);
    assert_eq!(j["stream"], true);
    assert_eq!(j["mode"], "swing");
    assert_eq!(j["bytes"], enc["bytes"]);
    assert_eq!(j["vertices"], enc["vertices"]);
    assert_eq!(j["triangles"], enc["triangles"]);
    assert_eq!(j["version"], "1.3");
    assert_eq!(j["geometry_kind"], 9);
    assert_eq!(j["fields"]["angle_bits"], 6);
    // The box is the fixture's, rounded outward to binary32 (24 bytes, tag 32).
    let min = j["fields"]["bbox_f32"]["min"].as_array().unwrap();
    assert!(min.iter().all(|x| x.as_f64().unwrap().is_finite()));
    let names: Vec<&str> = j["sections"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x["name"].as_str().unwrap())
        .collect();
    assert_eq!(names, ["connectivity", "geometry"]);
    // Text form, and a stream found by its magic without the extension.
    let plain = dir.join("f.bin");
    std::fs::copy(&stream, &plain).unwrap();
    let o = whet(&["info", s(&plain)]);
    assert!(o.status.success());
    assert!(String::from_utf8_lossy(&o.stdout).contains("geometry kind   9"));
    // One flipped payload bit: the checksum names the section.
    let mut bytes = std::fs::read(&stream).unwrap();
    let n = bytes.len();
    bytes[n - 10] ^= 0x10;
    let bad = dir.join("bad.whet");
    std::fs::write(&bad, &bytes).unwrap();
    let o = whet(&["info", s(&bad)]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("checksum mismatch in geometry"), "{err}");
}
