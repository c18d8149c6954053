//! `whet encode` and `whet convert` say what the input held that whet does not keep
//! (texture coordinates, normals, colours...): one note on stderr, and `skipped_attributes`
//! in `whet encode --json`.

use crate::{s, whet, whet_json};
use serde_json::json;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use whet_testkit::{scratch_dir, shared_fixture};

/// The public spot as OBJ with one texture coordinate and one normal per vertex, referenced
/// by every face (`f a/a/a ...`); its vertex count.
fn spot_with_uvs_and_normals(dir: &Path) -> (PathBuf, usize) {
    let mesh = whet::io::read_path(&shared_fixture("spot.off"), None).unwrap();
    let mut text = String::new();
    for p in &mesh.positions {
        writeln!(text, "v {} {} {}", p.x, p.y, p.z).unwrap();
    }
    for p in &mesh.positions {
        writeln!(text, "vt {} {}", p.x, p.y).unwrap();
    }
    for p in &mesh.positions {
        let n = p.normalize_or_zero();
        writeln!(text, "vn {} {} {}", n.x, n.y, n.z).unwrap();
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        writeln!(text, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}").unwrap();
    }
    let path = dir.join("spot_uv_normals.obj");
    std::fs::write(&path, text).unwrap();
    (path, mesh.positions.len())
}

/// The note lines of `stderr`.
fn notes(stderr: &[u8]) -> Vec<String> {
    String::from_utf8_lossy(stderr)
        .lines()
        .filter(|l| l.starts_with("whet: note:"))
        .map(str::to_owned)
        .collect()
}

#[test]
fn encode_notes_skipped_attributes_and_reports_them_in_every_mode() {
    let dir = scratch_dir("cli-skipped-encode");
    let (obj, vertices) = spot_with_uvs_and_normals(&dir);
    assert_eq!(vertices, 2930);
    let note = format!(
        "whet: note: {}: 2930 texture coordinates and 2930 vertex normals not kept \
         (whet codes positions and triangles only)",
        obj.display()
    );
    let expected = json!([
        { "what": "texture coordinates", "count": 2930 },
        { "what": "vertex normals", "count": 2930 },
    ]);
    let modes: &[(&str, &[&str])] = &[
        ("swing", &[]),
        ("exact", &["--mode", "exact"]),
        ("subdiv", &["--mode", "subdiv", "--control-vertices", "60"]),
    ];
    for (mode, flags) in modes {
        let stream = dir.join(format!("spot.{mode}.whet"));
        let mut args = vec!["encode", s(&obj), "-o", s(&stream), "--json"];
        args.extend_from_slice(flags);
        let out = whet(&args);
        assert!(
            out.status.success(),
            "{mode}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(notes(&out.stderr), vec![note.clone()], "{mode}");
        let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(j["skipped_attributes"], expected, "{mode}: {j}");
        // The keys that were there before are unchanged.
        assert_eq!(j["mode"], *mode);
        assert_eq!(
            j["bytes"],
            std::fs::metadata(&stream).unwrap().len(),
            "{mode}"
        );
    }
    // The original mesh's counts are those of the positions and faces, as from the OFF.
    let j = whet_json(&[
        "encode",
        s(&obj),
        "-o",
        s(&dir.join("again.whet")),
        "--json",
    ]);
    assert_eq!(j["original_vertices"], 2930);
    assert_eq!(j["original_triangles"], 5856);
    // Without --json the note is the same.
    let out = whet(&["encode", s(&obj), "-o", s(&dir.join("plain.whet"))]);
    assert!(out.status.success());
    assert_eq!(notes(&out.stderr), vec![note]);
}

#[test]
fn a_file_of_positions_and_faces_gets_no_note_and_an_empty_array() {
    let dir = scratch_dir("cli-skipped-none");
    let cube = shared_fixture("cube.off");
    let stream = dir.join("cube.whet");
    for flags in [&["--mode", "exact"][..], &[][..]] {
        let mut args = vec!["encode", s(&cube), "-o", s(&stream), "--json"];
        args.extend_from_slice(flags);
        let out = whet(&args);
        assert!(
            out.status.success(),
            "{flags:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(notes(&out.stderr).is_empty(), "{flags:?}");
        let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
        assert_eq!(j["skipped_attributes"], json!([]), "{flags:?}: {j}");
    }
    let out = whet(&["convert", s(&cube), "-o", s(&dir.join("cube.obj"))]);
    assert!(out.status.success());
    assert!(notes(&out.stderr).is_empty());
}

#[test]
fn convert_notes_what_it_drops() {
    let dir = scratch_dir("cli-skipped-convert");
    let (obj, _) = spot_with_uvs_and_normals(&dir);
    let ply = dir.join("spot.ply");
    let out = whet(&["convert", s(&obj), "-o", s(&ply)]);
    assert!(out.status.success());
    assert_eq!(
        notes(&out.stderr),
        vec![format!(
            "whet: note: {}: 2930 texture coordinates and 2930 vertex normals not kept \
             (whet codes positions and triangles only)",
            obj.display()
        )]
    );
    // What whet wrote holds nothing more to drop.
    let out = whet(&["convert", s(&ply), "-o", s(&dir.join("spot.off"))]);
    assert!(out.status.success());
    assert!(notes(&out.stderr).is_empty());

    // Binary STL: zero attribute bytes (whet writes zeros) are no news, non-zero ones are.
    let stl = dir.join("cube.stl");
    let out = whet(&["convert", s(&shared_fixture("cube.off")), "-o", s(&stl)]);
    assert!(out.status.success());
    let back = dir.join("cube.back.off");
    let out = whet(&["convert", s(&stl), "-o", s(&back)]);
    assert!(out.status.success());
    assert!(notes(&out.stderr).is_empty());
    let mut bytes = std::fs::read(&stl).unwrap();
    // Facet 2's attribute bytes: a 15-bit colour with its valid bit.
    let attr = 84 + 50 * 2 + 48;
    bytes[attr..attr + 2].copy_from_slice(&0x801fu16.to_le_bytes());
    let coloured = dir.join("cube.coloured.stl");
    std::fs::write(&coloured, &bytes).unwrap();
    let out = whet(&["convert", s(&coloured), "-o", s(&back)]);
    assert!(out.status.success());
    assert_eq!(
        notes(&out.stderr),
        vec![format!(
            "whet: note: {}: STL attribute bytes (non-zero on 1 facet) not kept \
             (whet codes positions and triangles only)",
            coloured.display()
        )]
    );
}
