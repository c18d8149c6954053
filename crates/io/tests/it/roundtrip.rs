//! Write then read gives the mesh back: bit for bit where the encoding stores f64, up to f32
//! rounding and welding for STL.

use std::fs;

use whet_io::{
    read, read_path, write, write_path, write_ply_with_quality, Error, Format, PlyEncoding,
    WriteOptions,
};
use whet_mesh::{DVec3, Mesh};

use crate::common::{
    assert_identical, assert_same_after_welding, awkward, bytes, encodings, exact, grid,
    round_trip, temp_path, welds,
};

#[test]
fn every_encoding_round_trips_a_grid() {
    for f32_exact in [false, true] {
        let mesh = grid(13, f32_exact, 7);
        for (name, format, opts) in encodings() {
            let back = round_trip(&mesh, format, &opts);
            let context = format!("{name} (f32 exact: {f32_exact})");
            if exact(name) || f32_exact {
                // The grid's vertices appear in index order, so welding keeps the numbering.
                assert_identical(&back, &mesh, &context);
            } else {
                assert_same_after_welding(&mesh, &back, true, &context);
            }
        }
    }
}

#[test]
fn exact_encodings_keep_awkward_coordinates() {
    let mesh = awkward();
    for (name, format, opts) in encodings() {
        if exact(name) {
            assert_identical(&round_trip(&mesh, format, &opts), &mesh, name);
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig {
        cases: 200,
        ..proptest::prelude::ProptestConfig::default()
    })]

    /// Any finite coordinates, of every magnitude (bit patterns), and coordinates of the
    /// magnitudes meshes have, come back bit for bit from the encodings that store f64: the
    /// text writers print shortest round-trip digits (zmij's, or the standard library's).
    #[test]
    fn exact_encodings_keep_any_finite_coordinates(
        raw in proptest::collection::vec(proptest::prelude::any::<u64>(), 9..60),
        scaled in proptest::collection::vec(-1.0f64..1.0, 9..60),
        scale in proptest::sample::select(vec![1e-6, 1e-3, 1.0, 250.0, 1e5]),
    ) {
        let finite = raw.iter().map(|&b| {
            let x = f64::from_bits(b);
            if x.is_finite() { x } else { f64::from_bits(b & !(1 << 62)) }
        });
        for coords in [finite.collect::<Vec<_>>(), scaled.iter().map(|x| x * scale).collect()] {
            let positions: Vec<DVec3> =
                coords.chunks_exact(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect();
            let triangles = (0..positions.len() as u32 - 2).map(|i| [i, i + 1, i + 2]).collect();
            let mesh = Mesh::new(positions, triangles);
            for (name, format, opts) in encodings() {
                if exact(name) {
                    assert_identical(&round_trip(&mesh, format, &opts), &mesh, name);
                }
            }
        }
    }
}

#[test]
fn binary_stl_refuses_what_f32_cannot_hold() {
    let opts = WriteOptions::DEFAULT;
    let e = write(&mut Vec::new(), &awkward(), Format::Stl, &opts).unwrap_err();
    assert!(matches!(e, Error::Unsupported { .. }), "{e}");
}

#[test]
fn stl_renumbers_by_first_appearance_and_welds_duplicates() {
    // Vertex 3 is referenced first, and vertex 4 duplicates vertex 0.
    let mesh = Mesh::new(
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(-0.0, 0.0, 0.0),
        ],
        vec![[3, 1, 2], [4, 1, 3], [0, 2, 1]],
    );
    for (name, format, opts) in encodings() {
        if !welds(format) {
            continue;
        }
        let back = round_trip(&mesh, format, &opts);
        assert_eq!(
            back.positions,
            vec![DVec3::Z, DVec3::X, DVec3::Y, DVec3::ZERO],
            "{name}"
        );
        assert_eq!(
            back.triangles,
            vec![[0, 1, 2], [3, 1, 0], [3, 2, 1]],
            "{name}"
        );
    }
}

#[test]
fn empty_meshes_round_trip() {
    let mesh = Mesh::default();
    for (name, format, opts) in encodings() {
        assert_identical(&round_trip(&mesh, format, &opts), &mesh, name);
    }
    // Vertices without triangles survive where the format stores vertices.
    let cloud = Mesh::new(vec![DVec3::ONE, DVec3::NEG_ONE], vec![]);
    for (name, format, opts) in encodings() {
        if !welds(format) {
            assert_identical(&round_trip(&cloud, format, &opts), &cloud, name);
        }
    }
}

#[test]
fn paths_pick_the_format_from_the_extension() {
    let mesh = grid(5, true, 3);
    for (name, format, opts) in encodings() {
        let path = temp_path(&format!(
            "{}.{}",
            name.replace(' ', "_"),
            format.extension().to_uppercase()
        ));
        write_path(&path, &mesh, None, &opts).unwrap();
        let back = read_path(&path, None);
        let explicit = read_path(&path, Some(format));
        fs::remove_file(&path).unwrap();
        assert_identical(&back.unwrap(), &mesh, name);
        assert_identical(&explicit.unwrap(), &mesh, name);
    }
    let path = temp_path("mesh.unknown");
    let e = write_path(&path, &mesh, None, &WriteOptions::DEFAULT).unwrap_err();
    assert!(matches!(e, Error::UnknownFormat { .. }), "{e}");
    assert!(!path.exists());
    // An explicit format overrides the extension.
    write_path(&path, &mesh, Some(Format::Obj), &WriteOptions::DEFAULT).unwrap();
    let back = read_path(&path, Some(Format::Obj));
    fs::remove_file(&path).unwrap();
    assert_identical(&back.unwrap(), &mesh, "obj with explicit format");
}

#[test]
fn write_errors_that_are_not_input_errors() {
    let mesh = grid(3, true, 1);
    let dir = temp_path("missing-dir");
    let e = write_path(&dir.join("x.off"), &mesh, None, &WriteOptions::DEFAULT).unwrap_err();
    assert!(matches!(e, Error::Io(_)), "{e}");
    assert!(!e.is_input_error());
}

#[test]
fn quality_export_reads_back_and_declares_meshlab_properties() {
    let mesh = grid(6, false, 11);
    let n = mesh.positions.len();
    let quality: Vec<f64> = (0..n).map(|i| i as f64 / 7.0).collect();
    let colors: Vec<[u8; 3]> = (0..n).map(|i| [i as u8, 255 - i as u8, 7]).collect();
    for encoding in [
        PlyEncoding::Ascii,
        PlyEncoding::BinaryLittleEndian,
        PlyEncoding::BinaryBigEndian,
    ] {
        for (q, c) in [
            (&quality[..], &colors[..]),
            (&quality[..], &[][..]),
            (&[][..], &colors[..]),
        ] {
            let mut out = Vec::new();
            write_ply_with_quality(&mut out, &mesh, q, c, encoding).unwrap();
            let end = out.windows(11).position(|w| w == b"end_header\n").unwrap();
            let header = String::from_utf8(out[..end].to_vec()).unwrap();
            assert_eq!(header.contains("property double quality\n"), !q.is_empty());
            assert_eq!(
                header.contains("property uchar red\nproperty uchar green\nproperty uchar blue\n"),
                !c.is_empty()
            );
            let back = read(&out[..], Format::Ply).unwrap();
            assert_identical(&back, &mesh, &format!("{encoding:?}"));
        }
        if encoding == PlyEncoding::Ascii {
            let mut out = Vec::new();
            write_ply_with_quality(&mut out, &mesh, &quality, &colors, encoding).unwrap();
            let text = String::from_utf8(out).unwrap();
            let second = text
                .split("end_header\n")
                .nth(1)
                .unwrap()
                .lines()
                .nth(1)
                .unwrap();
            let values: Vec<f64> = second.split(' ').map(|t| t.parse().unwrap()).collect();
            let p = mesh.positions[1];
            assert_eq!(values, vec![p.x, p.y, p.z, 1.0 / 7.0, 1.0, 254.0, 7.0]);
        }
    }
    let e = write_ply_with_quality(
        &mut Vec::new(),
        &mesh,
        &quality,
        &colors[1..],
        PlyEncoding::Ascii,
    )
    .unwrap_err();
    assert!(
        matches!(e, Error::LengthMismatch { what: "colors", .. }),
        "{e}"
    );
}

#[test]
fn reading_accepts_any_bufread() {
    let mesh = grid(4, true, 5);
    for (name, format, opts) in encodings() {
        let data = bytes(&mesh, format, &opts);
        // A BufReader with a tiny buffer forces refills at every boundary.
        let reader = std::io::BufReader::with_capacity(3, &data[..]);
        assert_identical(&read(reader, format).unwrap(), &mesh, name);
    }
}
