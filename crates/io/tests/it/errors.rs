//! Bad input gives the right error, quickly and without panicking.

use std::time::{Duration, Instant};

use whet_io::{read, Error, Format, WriteOptions};
use whet_mesh::{DVec3, Mesh};

use crate::common::{bytes, encodings, grid, Rng};

fn read_err(data: &[u8], format: Format) -> Error {
    match read(data, format) {
        Ok(m) => panic!(
            "{format}: expected an error, read {} vertices and {} triangles",
            m.positions.len(),
            m.triangles.len()
        ),
        Err(e) => {
            assert!(e.is_input_error(), "{format}: {e} should be an input error");
            e
        }
    }
}

#[test]
fn garbage_bytes_are_refused() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    for len in [0usize, 1, 7, 83, 84, 85, 200, 5000] {
        let mut data: Vec<u8> = (0..len).map(|_| rng.next() as u8).collect();
        if let Some(b) = data.first_mut() {
            // Not a digit, not whitespace, not a keyword: a control character.
            *b = 0x01;
        }
        for format in Format::ALL {
            if len == 0 && format == Format::Obj {
                // An empty OBJ is a valid empty mesh.
                assert_eq!(read(&data[..], format).unwrap(), Mesh::default());
                continue;
            }
            let e = read_err(&data, format);
            if format != Format::Stl {
                assert!(
                    matches!(e, Error::Parse { .. } | Error::Truncated { .. }),
                    "{format} {len}: {e}"
                );
            }
        }
    }
    // Text that is simply not the format.
    let text = b"hello world\nthis is not a mesh\n";
    assert!(matches!(
        read_err(text, Format::Off),
        Error::Parse { line: 1, .. }
    ));
    assert!(matches!(
        read_err(text, Format::Ply),
        Error::Parse { line: 1, .. }
    ));
    assert!(matches!(
        read_err(text, Format::Stl),
        Error::Truncated { .. } | Error::Parse { .. }
    ));
}

/// Start of the last line of a text file (everything before it is a strict prefix).
fn last_line_start(data: &[u8]) -> usize {
    let body = &data[..data.len() - 1];
    body.iter().rposition(|&b| b == b'\n').map_or(0, |i| i + 1)
}

#[test]
fn truncated_files_are_refused() {
    let mesh = grid(6, true, 42);
    for (name, format, opts) in encodings() {
        let data = bytes(&mesh, format, &opts);
        let binary = data.contains(&0);
        // Binary data: every strict prefix is an error. Text: every cut before the last line
        // (a cut inside the last line may leave a shorter valid number or name).
        let limit = if binary {
            data.len()
        } else {
            last_line_start(&data)
        };
        let mut cuts: Vec<usize> = (0..limit.min(300)).collect();
        cuts.extend((0..40).map(|k| limit * k / 40));
        cuts.extend([limit.saturating_sub(1), limit.saturating_sub(13)]);
        for cut in cuts.into_iter().filter(|&c| c < limit) {
            if format == Format::Obj {
                // A cut OBJ is a valid smaller OBJ or fails; it must not panic.
                let _ = read(&data[..cut], format);
                continue;
            }
            let e = read_err(&data[..cut], format);
            assert!(
                matches!(e, Error::Truncated { .. } | Error::Parse { .. }),
                "{name} cut at {cut}: {e}"
            );
        }
    }
}

#[test]
fn truncation_messages_count_what_was_read() {
    let mesh = grid(6, true, 42);
    let ply = bytes(&mesh, Format::Ply, &WriteOptions::DEFAULT);
    let header_len = ply.windows(11).position(|w| w == b"end_header\n").unwrap() + 11;
    let e = read_err(&ply[..header_len + 24 * 12 + 5], Format::Ply);
    assert_eq!(
        e.to_string(),
        "file is truncated: expected 36 vertices, file ended after 12"
    );
    let stl = bytes(&mesh, Format::Stl, &WriteOptions::DEFAULT);
    let e = read_err(&stl[..84 + 50 * 3 + 10], Format::Stl);
    assert_eq!(
        e.to_string(),
        "file is truncated: expected 50 triangles, file ended after 3"
    );
}

fn with_nan(format: Format, opts: &WriteOptions) -> Vec<u8> {
    // Write a mesh with a marker coordinate, then replace the marker by NaN in the bytes.
    let marker = 12345.678;
    let mesh = Mesh::new(
        vec![DVec3::ZERO, DVec3::new(1.0, marker, 0.0), DVec3::Y],
        vec![[0, 1, 2]],
    );
    let data = bytes(&mesh, format, opts);
    let text = marker.to_string();
    let replace = |data: &[u8], from: &[u8], to: &[u8]| -> Vec<u8> {
        let at = data
            .windows(from.len())
            .position(|w| w == from)
            .expect("marker present");
        [&data[..at], to, &data[at + from.len()..]].concat()
    };
    if data.windows(text.len()).any(|w| w == text.as_bytes()) {
        replace(&data, text.as_bytes(), b"NaN")
    } else if data.windows(8).any(|w| w == marker.to_le_bytes()) {
        replace(&data, &marker.to_le_bytes(), &f64::NAN.to_le_bytes())
    } else if data.windows(8).any(|w| w == marker.to_be_bytes()) {
        replace(&data, &marker.to_be_bytes(), &f64::NAN.to_be_bytes())
    } else {
        let m = (marker as f32).to_le_bytes();
        replace(&data, &m, &f32::NAN.to_le_bytes())
    }
}

#[test]
fn nan_coordinates_are_refused() {
    for (name, format, opts) in encodings() {
        let data = with_nan(format, &opts);
        let e = read_err(&data, format);
        assert!(matches!(e, Error::NonFinite { vertex: 1 }), "{name}: {e}");
    }
    for text in [
        "OFF\n1 0 0\ninf 0 0\n",
        "OFF\n1 0 0\n0 -infinity 0\n",
        "OFF\n1 0 0\n0 0 1e400\n",
    ] {
        assert!(matches!(
            read_err(text.as_bytes(), Format::Off),
            Error::NonFinite { vertex: 0 }
        ));
    }
}

#[test]
fn out_of_range_indices_are_refused() {
    let cases: [(&str, Format); 4] = [
        (
            "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 3\n",
            Format::Off,
        ),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n", Format::Obj),
        (
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n\
             0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n3 0 1 3\n",
            Format::Ply,
        ),
        (
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 -4\n",
            Format::Obj,
        ),
    ];
    for (text, format) in cases {
        let e = read_err(text.as_bytes(), format);
        assert!(
            matches!(
                e,
                Error::IndexOutOfRange {
                    face: 1,
                    vertex_count: 3,
                    ..
                }
            ),
            "{format}: {e}"
        );
    }
    // Binary PLY with an index past the end.
    let mesh = Mesh::new(vec![DVec3::ZERO, DVec3::X, DVec3::Y], vec![[0, 1, 2]]);
    let mut data = bytes(&mesh, Format::Ply, &WriteOptions::DEFAULT);
    let n = data.len();
    data[n - 4..].copy_from_slice(&3u32.to_le_bytes());
    let e = read_err(&data, Format::Ply);
    assert!(
        matches!(
            e,
            Error::IndexOutOfRange {
                face: 0,
                index: 3,
                vertex_count: 3
            }
        ),
        "{e}"
    );
}

#[test]
fn faces_with_fewer_than_three_vertices_are_parse_errors() {
    let cases: [(&str, Format); 3] = [
        ("OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", Format::Off),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n", Format::Obj),
        (
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n\
             property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n\
             0 0 0\n1 0 0\n0 1 0\n2 0 1\n",
            Format::Ply,
        ),
    ];
    for (text, format) in cases {
        let e = read_err(text.as_bytes(), format);
        assert!(matches!(e, Error::Parse { .. }), "{format}: {e}");
        assert!(e.to_string().contains("at least 3"), "{format}: {e}");
    }
}

#[test]
fn absurd_header_counts_fail_fast_without_allocating() {
    let start = Instant::now();
    let ply = "ply\nformat binary_little_endian 1.0\nelement vertex 4000000000\n\
               property float x\nproperty float y\nproperty float z\nend_header\n0123456789";
    let e = read_err(ply.as_bytes(), Format::Ply);
    assert!(matches!(e, Error::Truncated { .. }), "{e}");
    let ply = "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float x\n\
               property float y\nproperty float z\nelement face 4000000000\n\
               property list uchar int vertex_indices\nend_header\n0 0 0\n";
    assert!(matches!(
        read_err(ply.as_bytes(), Format::Ply),
        Error::Truncated { .. }
    ));
    let ply = "ply\nformat ascii 1.0\nelement vertex 1000000000000\nproperty float x\n\
               property float y\nproperty float z\nend_header\n";
    let e = read_err(ply.as_bytes(), Format::Ply);
    assert!(
        matches!(
            e,
            Error::TooLarge {
                count: 1_000_000_000_000,
                ..
            }
        ),
        "{e}"
    );
    let off = "OFF\n4000000000 4000000000 0\n0 0 0\n";
    assert!(matches!(
        read_err(off.as_bytes(), Format::Off),
        Error::Truncated { .. }
    ));
    let off = "OFF\n1000000000000 1 0\n";
    assert!(matches!(
        read_err(off.as_bytes(), Format::Off),
        Error::TooLarge { .. }
    ));
    let mut stl = vec![0u8; 80];
    stl.extend_from_slice(&u32::MAX.to_le_bytes());
    stl.extend_from_slice(&[0; 60]);
    assert!(matches!(
        read_err(&stl, Format::Stl),
        Error::Truncated { .. }
    ));
    // A face list claiming 4 billion indices.
    let ply: &[u8] = b"ply\nformat binary_little_endian 1.0\nelement vertex 0\nproperty float x\n\
               property float y\nproperty float z\nelement face 1\n\
               property list uint uint vertex_indices\nend_header\n\xff\xff\xff\xff";
    assert!(matches!(
        read_err(ply, Format::Ply),
        Error::Truncated { .. }
    ));
    assert!(
        start.elapsed() < Duration::from_secs(2),
        "took {:?}",
        start.elapsed()
    );
}

#[test]
fn unsupported_ply_layouts() {
    let cases = [
        "ply\nformat ascii 1.0\nelement face 0\nproperty list uchar int vertex_indices\n\
         end_header\n",
        "ply\nformat ascii 1.0\nelement vertex 0\nproperty float nx\nproperty float ny\n\
         end_header\n",
        "ply\nformat ascii 1.0\nelement vertex 0\nproperty list uchar float x\nproperty float y\n\
         property float z\nend_header\n",
        "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
         property float z\nelement face 0\nproperty list uchar float vertex_indices\nend_header\n",
        "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
         property float z\nelement face 0\nproperty int material\nend_header\n",
        "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\nproperty float y\n\
         property float z\nelement tristrips 1\nproperty list int int vertex_indices\nend_header\n",
    ];
    for text in cases {
        let e = read_err(text.as_bytes(), Format::Ply);
        assert!(matches!(e, Error::Unsupported { .. }), "{text}: {e}");
    }
}
