//! `whet convert` round trips the public fandisk through every format.

use crate::{s, whet};
use whet_testkit::{scratch_dir, shared_fixture};

#[test]
fn fandisk_round_trips_through_every_format() {
    let src = shared_fixture("fandisk.off");
    let original = whet::io::read_path(&src, None).unwrap();
    let dir = scratch_dir("convert-roundtrip");
    let cases: &[(&str, &[&str])] = &[
        ("obj", &[]),
        ("ply", &["--ascii"]),
        ("ply", &[]),
        ("ply", &["--big-endian"]),
        ("stl", &[]),
        ("stl", &["--ascii"]),
        ("off", &[]),
    ];
    for (i, (ext, flags)) in cases.iter().enumerate() {
        let mid = dir.join(format!("fandisk{i}.{ext}"));
        let back = dir.join(format!("fandisk{i}.back.off"));
        let mut args = vec!["convert", s(&src), "-o", s(&mid)];
        args.extend_from_slice(flags);
        let out = whet(&args);
        assert!(
            out.status.success(),
            "{ext} {flags:?}: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let out = whet(&["convert", s(&mid), "-o", s(&back)]);
        assert!(
            out.status.success(),
            "{ext} back: {}",
            String::from_utf8_lossy(&out.stderr)
        );
        let m = whet::io::read_path(&back, None).unwrap();
        assert_eq!(
            m.positions.len(),
            original.positions.len(),
            "{ext} {flags:?}"
        );
        assert_eq!(
            m.triangles.len(),
            original.triangles.len(),
            "{ext} {flags:?}"
        );
        if *ext == "stl" {
            // STL has no shared vertices: welding exactly equal coordinates restores them in
            // order of first appearance; binary STL stores f32.
            for tri in 0..m.triangles.len() {
                for k in 0..3 {
                    let a = original.positions[original.triangles[tri][k] as usize];
                    let b = m.positions[m.triangles[tri][k] as usize];
                    assert_eq!(a.as_vec3(), b.as_vec3(), "{ext} {flags:?} triangle {tri}");
                }
            }
        } else {
            assert_eq!(
                m, original,
                "{ext} {flags:?}: positions and triangles bit-exact"
            );
        }
    }
}

#[test]
fn make_manifold_flag_repairs() {
    let dir = scratch_dir("convert-manifold");
    let p = dir.join("fin.off");
    std::fs::write(
        &p,
        "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n3 0 1 2\n3 1 0 3\n3 0 1 4\n",
    )
    .unwrap();
    let out_path = dir.join("fixed.ply");
    let out = whet(&["convert", s(&p), "-o", s(&out_path), "--make-manifold"]);
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("cut 1 edges"));
    let m = whet::io::read_path(&out_path, None).unwrap();
    let r = m.topology_report();
    assert!(r.manifold && r.oriented, "{:?}", r.problems);
}

#[test]
fn unwritable_output_exits_1() {
    let src = shared_fixture("cube.off");
    let out = whet(&["convert", s(&src), "-o", "/nonexistent-dir/whet/out.obj"]);
    assert_eq!(out.status.code(), Some(1));
}
