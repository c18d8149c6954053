//! The project's own fixtures (fixtures/synth) are exactly what the generator makes today;
//! fixtures/regenerate.sh rewrites them.

use glam::{DQuat, DVec3};
use std::path::PathBuf;
use whet_synth::{add_noise, marching_cubes, Shape, ShapeKind, ShapeParams};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("fixtures/synth")
        .join(name)
}

fn off_bytes(mesh: &whet::Mesh) -> Vec<u8> {
    let mut out = Vec::new();
    whet::io::write(
        &mut out,
        mesh,
        whet::io::Format::Off,
        &whet::io::WriteOptions::DEFAULT,
    )
    .unwrap();
    out
}

fn check(
    file: &str,
    truth: Option<&str>,
    kind: ShapeKind,
    params: ShapeParams,
    res: usize,
    noise: Option<(f64, u64)>,
) {
    let shape = Shape::new(kind, &params).unwrap();
    let mut mesh = marching_cubes(&shape, res).unwrap();
    if let Some((f, seed)) = noise {
        mesh = add_noise(&mesh, f, seed);
    }
    let stored = std::fs::read(fixture(file)).unwrap();
    assert!(
        stored == off_bytes(&mesh),
        "fixtures/synth/{file} differs from the generator: run fixtures/regenerate.sh"
    );
    if let Some(t) = truth {
        let stored = std::fs::read(fixture(t)).unwrap();
        assert!(
            stored == off_bytes(&shape.truth_mesh()),
            "fixtures/synth/{t} differs"
        );
    }
}

#[test]
fn synth_fixtures_match_the_generator() {
    let rot = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 25f64.to_radians());
    check(
        "cube-r12.off",
        Some("cube-truth.off"),
        ShapeKind::Cube,
        ShapeParams::default().with_rotation(rot),
        12,
        None,
    );
    check(
        "pyramid-r16.off",
        Some("pyramid-truth.off"),
        ShapeKind::Pyramid,
        ShapeParams::default(),
        16,
        None,
    );
    check(
        "fandisk-r24.off",
        Some("fandisk-truth.off"),
        ShapeKind::Fandisk,
        ShapeParams::default(),
        24,
        None,
    );
    check(
        "torus-box-r16.off",
        Some("torus-box-truth.off"),
        ShapeKind::TorusBox,
        ShapeParams::default(),
        16,
        None,
    );
    check(
        "box-r16-noise.off",
        None,
        ShapeKind::Box,
        ShapeParams::default(),
        16,
        Some((0.3, 7)),
    );
}

#[test]
fn synth_fixtures_are_valid_meshes() {
    for (f, genus) in [
        ("cube-r12.off", 0),
        ("pyramid-r16.off", 0),
        ("fandisk-r24.off", 0),
        ("torus-box-r16.off", 1),
    ] {
        let m = whet::io::read_path(&fixture(f), None).unwrap();
        let r = m.topology_report();
        assert!(
            r.manifold && r.oriented && r.problems.is_empty(),
            "{f}: {:?}",
            r.problems
        );
        assert_eq!(r.genus, Some(genus), "{f}");
    }
}
