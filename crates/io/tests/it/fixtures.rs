//! The shared fixture meshes: every one loads with the expected counts, and fandisk survives
//! every format.

use whet_io::{read_path, Format};

use crate::common::{
    assert_identical, assert_same_after_welding, encodings, exact, fixtures_dir, round_trip,
};

/// (name, vertices, triangles) of every fixture.
const FIXTURES: [(&str, usize, usize); 17] = [
    ("fandisk", 6475, 12946),
    ("block", 8771, 17550),
    ("joint", 20902, 41808),
    ("partLp", 4261, 8530),
    ("rocker_arm", 10044, 20088),
    ("sharp_sphere", 10443, 20882),
    ("sledge", 104, 212),
    ("cube", 8, 12),
    ("screwdriver", 3395, 6786),
    ("bunny", 3485, 6966),
    ("fertility", 4494, 9000),
    ("spot", 2930, 5856),
    ("armadillo", 43243, 86482),
    ("cad_box_hole", 13722, 27444),
    ("cad_cyl_fillet", 13312, 26620),
    ("cad_bracket", 10654, 21308),
    ("bunny_dense", 55730, 111456),
];

#[test]
fn every_fixture_loads_with_its_counts() {
    let dir = fixtures_dir();
    let mut found: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| Format::from_path(p) == Some(Format::Off))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    found.sort();
    let mut expected: Vec<String> = FIXTURES.iter().map(|f| f.0.to_owned()).collect();
    expected.sort();
    assert_eq!(found, expected, "the .off files in {}", dir.display());
    for (name, vertices, triangles) in FIXTURES {
        let path = dir.join(format!("{name}.off"));
        let mesh = read_path(&path, None).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(
            (mesh.positions.len(), mesh.triangles.len()),
            (vertices, triangles),
            "{name}"
        );
    }
}

#[test]
fn fandisk_survives_every_format() {
    let mesh = read_path(&fixtures_dir().join("fandisk.off"), None).unwrap();
    for (name, format, opts) in encodings() {
        let back = round_trip(&mesh, format, &opts);
        if format == Format::Stl {
            assert_same_after_welding(&mesh, &back, !exact(name), name);
        } else {
            assert_identical(&back, &mesh, name);
        }
    }
}
